#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "internal.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

using namespace gap_detail;

std::string HoldoutScheme::str() const {
  switch (kind) {
    case Kind::Cycle:
      return "cycle:" + std::to_string(folds);
    case Kind::Time:
      return "time:" + std::to_string(folds);
    case Kind::Space:
      return "space:" + axis + ":" + std::to_string(folds);
    case Kind::Forward:
      return "forward:" + format_short(fraction);
  }
  return "";
}

std::optional<HoldoutScheme> parse_holdout(const std::string& text) {
  const std::vector<std::string> parts = [&] {
    std::vector<std::string> v;
    std::size_t s = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
      if (i == text.size() || text[i] == ':') v.push_back(text.substr(s, i - s)), s = i + 1;
    return v;
  }();
  const std::string what = "--holdout \"" + text + "\"";
  auto whole = [&](const std::string& s) {
    char* end = nullptr;
    const long k = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end || k < 2 || k > 100)
      throw std::invalid_argument(what + ": the number of folds must be a whole number 2..100");
    return static_cast<int>(k);
  };
  HoldoutScheme h;
  const std::string& k = parts[0];
  if (k == "auto" && parts.size() == 1) return std::nullopt;
  if (k == "cycle" || k == "time") {
    h.kind = k == "cycle" ? HoldoutScheme::Kind::Cycle : HoldoutScheme::Kind::Time;
    if (parts.size() > 2) throw std::invalid_argument(what + ": expected " + k + "[:FOLDS]");
    if (parts.size() == 2) h.folds = whole(parts[1]);
    return h;
  }
  if (k == "space") {
    h.kind = HoldoutScheme::Kind::Space;
    if (parts.size() > 3) throw std::invalid_argument(what + ": expected space[:AXIS][:FOLDS]");
    for (std::size_t i = 1; i < parts.size(); ++i) {
      if (!parts[i].empty() && std::isdigit(static_cast<unsigned char>(parts[i][0])))
        h.folds = whole(parts[i]);
      else
        h.axis = parts[i];
    }
    return h;
  }
  if (k == "forward") {
    h.kind = HoldoutScheme::Kind::Forward;
    if (parts.size() > 2) throw std::invalid_argument(what + ": expected forward[:FRACTION]");
    if (parts.size() == 2) {
      char* end = nullptr;
      h.fraction = std::strtod(parts[1].c_str(), &end);
      if (parts[1].empty() || *end || !(h.fraction > 0.1 && h.fraction < 0.95))
        throw std::invalid_argument(what + ": the training fraction must be in (0.1, 0.95)");
    }
    return h;
  }
  throw std::invalid_argument(what + ": unknown scheme '" + k +
                              "' (expected cycle[:K], time[:K], space[:AXIS][:K], "
                              "forward[:FRACTION] or auto)");
}

HoldoutScheme default_holdout(const GapData& d) {
  HoldoutScheme h;
  if (distinct(d.cycle) >= 3) {
    h.kind = HoldoutScheme::Kind::Cycle;
  } else if (distinct(d.time_s) >= 10) {
    h.kind = HoldoutScheme::Kind::Time;
  } else {
    h.kind = HoldoutScheme::Kind::Space;
  }
  return h;
}

std::vector<Split> make_splits(const GapData& d, const HoldoutScheme& s, std::size_t min_train) {
  const auto& obs = d.points.observations;
  const std::size_t m = obs.size();
  std::vector<int> fold(m, -1);
  int k = s.folds;
  const std::string file = d.points.file;
  auto fail = [&](const std::string& msg) {
    throw InputError(SourceLoc{file, 0, 0}, "--holdout " + s.str() + ": " + msg);
  };
  if (s.kind == HoldoutScheme::Kind::Cycle) {
    std::vector<double> ids;
    for (const auto& o : obs) {
      if (!std::isfinite(d.cycle[o.row])) fail("needs a cycle column with a value in every row");
      ids.push_back(d.cycle[o.row]);
    }
    std::vector<double> u = ids;
    std::sort(u.begin(), u.end());
    u.erase(std::unique(u.begin(), u.end()), u.end());
    if (u.size() < 2) fail("needs at least 2 cycles (has " + std::to_string(u.size()) + ")");
    k = std::min<int>(k, static_cast<int>(u.size()));
    for (std::size_t i = 0; i < m; ++i)
      fold[i] = static_cast<int>(std::lower_bound(u.begin(), u.end(), ids[i]) - u.begin()) % k;
  } else if (s.kind == HoldoutScheme::Kind::Time || s.kind == HoldoutScheme::Kind::Forward) {
    std::vector<std::size_t> order(m);
    std::iota(order.begin(), order.end(), 0);
    for (const auto& o : obs)
      if (!std::isfinite(d.time_s[o.row])) fail("needs a t_s column with a value in every row");
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return d.time_s[obs[a].row] < d.time_s[obs[b].row];
    });
    if (s.kind == HoldoutScheme::Kind::Forward) {
      k = 1;
      const auto cut = static_cast<std::size_t>(s.fraction * static_cast<double>(m));
      for (std::size_t i = 0; i < m; ++i) fold[order[i]] = i < cut ? -1 : 0;
    } else {
      for (std::size_t i = 0; i < m; ++i)
        fold[order[i]] = static_cast<int>(i * static_cast<std::size_t>(k) / m);
    }
  } else {
    std::string axis = s.axis;
    std::size_t a = 0, best = 0;
    for (std::size_t i = 0; i < d.axes.size(); ++i) {
      std::vector<double> v;
      for (const auto& p : d.points.poses)
        if (!p.empty()) v.push_back(p[i]);
      const std::size_t n = distinct(v);
      if (axis.empty() ? n > best : d.axes[i] == axis) a = i, best = n;
    }
    if (!axis.empty() && d.axes[a] != axis)
      fail("'" + axis + "' is not a coordinate (" + join(d.axes) + ")");
    std::vector<double> u;
    for (const auto& o : obs) u.push_back(d.points.poses[o.row][a]);
    std::vector<double> levels = u;
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    if (levels.size() < 2) fail("the data do not vary along " + d.axes[a]);
    k = std::min<int>(k, static_cast<int>(levels.size()));
    for (std::size_t i = 0; i < m; ++i) {
      const auto l = static_cast<std::size_t>(std::lower_bound(levels.begin(), levels.end(), u[i]) -
                                              levels.begin());
      fold[i] = static_cast<int>(l * static_cast<std::size_t>(k) / levels.size());
    }
  }
  std::vector<Split> splits(static_cast<std::size_t>(k));
  for (std::size_t i = 0; i < m; ++i)
    for (int f = 0; f < k; ++f) (fold[i] == f ? splits[f].test : splits[f].train).push_back(i);
  for (std::size_t f = 0; f < splits.size(); ++f) {
    if (splits[f].test.size() < 3)
      fail("held-out part " + std::to_string(f + 1) + " has " +
           std::to_string(splits[f].test.size()) + " observations (at least 3)");
    if (splits[f].train.size() < min_train)
      fail("too few observations: a training part has " + std::to_string(splits[f].train.size()) +
           ", the model needs at least " + std::to_string(min_train));
  }
  return splits;
}

std::string holdout_reason(const HoldoutScheme& scheme, bool given) {
  if (given) return "given";
  if (scheme.kind == HoldoutScheme::Kind::Cycle) return "default: the data have cycles";
  if (scheme.kind == HoldoutScheme::Kind::Time)
    return "default: no cycle column with >= 3 cycles; blocks of t_s";
  return "default: no cycles, no time; blocks along the most-varied axis";
}

}  // namespace weilgen
