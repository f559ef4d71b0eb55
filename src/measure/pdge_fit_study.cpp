#include "weilgen/measure/pdge_fit_study.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>

#include "weilgen/base/range.hpp"
#include "weilgen/measure/line6d.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

namespace {

// --travel a:b (mm), a < b.
std::pair<double, double> parse_travel(const std::string& travel) {
  const auto colon = travel.find(':');
  if (colon == std::string::npos)
    throw std::invalid_argument("--travel: \"" + travel + "\": expected a:b in mm");
  const double a = parse_number_in(travel.substr(0, colon), NumberRange{}, "--travel");
  const double b = parse_number_in(travel.substr(colon + 1), NumberRange{}, "--travel");
  if (!(a < b))
    throw std::invalid_argument("--travel: \"" + travel + "\": the start must be below the end");
  return {a, b};
}

std::vector<std::string> split_list(const std::vector<std::string>& items) {
  std::vector<std::string> out;
  for (const std::string& item : items) {
    std::size_t start = 0;
    while (start <= item.size()) {
      std::size_t comma = item.find(',', start);
      if (comma == std::string::npos) comma = item.size();
      std::string s = item.substr(start, comma - start);
      s.erase(0, s.find_first_not_of(" \t"));
      s.erase(s.find_last_not_of(" \t") + 1);
      if (!s.empty()) out.push_back(s);
      start = comma + 1;
    }
  }
  return out;
}

// --basis: "all" or comma-separated specs; --order/--period fill what a spec leaves open.
std::vector<BasisSpec> parse_bases(const std::vector<std::string>& flags, const std::string& order,
                                   const std::string& period) {
  std::vector<std::string> items = split_list(flags);
  if (items.empty()) items = {"all"};
  std::vector<std::string> expanded;
  for (const std::string& s : items) {
    if (s == "all") {
      for (const char* k : {"poly", "fourier", "legendre", "chebyshev"}) expanded.push_back(k);
    } else {
      expanded.push_back(s);
    }
  }
  int default_order = -1;
  if (order != "auto") {
    char* end = nullptr;
    const long v = std::strtol(order.c_str(), &end, 10);
    if (order.empty() || *end != '\0' || v < 0 || v > 200)
      throw std::invalid_argument("--order: \"" + order + "\": expected a whole number or auto");
    default_order = static_cast<int>(v);
  }
  bool period_search = false;
  double period_mm = NAN;
  if (period == "auto") {
    period_search = true;
  } else if (period != "travel") {
    std::string p = period;
    if (p.size() > 2 && p.compare(p.size() - 2, 2, "mm") == 0) p.resize(p.size() - 2);
    try {
      period_mm = parse_number_in(p, NumberRange::positive(), "--period");
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument("--period: \"" + period +
                                  "\": expected a length > 0 in mm, auto or travel");
    }
  }
  std::vector<BasisSpec> specs;
  for (const std::string& s : expanded) {
    BasisSpec b;
    try {
      b = parse_basis(s, true);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("--basis: ") + e.what());
    }
    const bool order_given = s.find(':') != std::string::npos;
    if (!order_given) b.order = default_order;
    if (b.kind == BasisKind::Fourier && !b.period_search && std::isnan(b.period_mm)) {
      b.period_search = period_search;
      b.period_mm = period_mm;
    }
    for (const BasisSpec& other : specs)
      if (other.str() == b.str())
        throw std::invalid_argument("--basis: " + b.str() + " given twice");
    specs.push_back(b);
  }
  return specs;
}

}  // namespace

void PdgeFitStudyOptions::validate() const {
  if (cv != "blocks" && cv != "cycles")
    throw std::invalid_argument("--cv must be blocks or cycles, not '" + cv + "'");
  if (rule != "1se" && rule != "min")
    throw std::invalid_argument("--rule must be 1se or min, not '" + rule + "'");
  if (angular != "mean" && angular != "none")
    throw std::invalid_argument("--angular-reference must be mean or none, not '" + angular + "'");
  if (min_order < 0 || max_order < min_order)
    throw std::invalid_argument("--min-order/--max-order: need 0 <= min <= max");
  if (folds < 2) throw std::invalid_argument("--folds must be >= 2");
  if (!travel.empty()) parse_travel(travel);
}

PdgeFitStudy::PdgeFitStudy(PdgeFitStudyOptions options) : options_(std::move(options)) {
  options_.validate();
  parse_bases(options_.bases, options_.order, options_.period);  // bad --basis: before any file
}

PdgeFitStudyResult PdgeFitStudy::run(const std::string& path) const {
  const PdgeFitStudyOptions& o = options_;
  PdgeFitStudyResult r;
  r.file = path;
  r.specs = parse_bases(o.bases, o.order, o.period);
  // ---- read the profiles ----
  std::vector<PdgeProfile>& profiles = r.profiles;
  std::string& format = r.format;
  std::string& pos_name = r.axis;
  std::size_t& rows = r.rows;
  {
    // Header keys first (unknown columns allowed), to know the variant.
    ReadOptions probe;
    probe.allow_unknown = true;
    const MeasurementTable head = read_measurements(path, probe);
    if (is_line6d(head)) {
      format = "line6d";
      const MeasurementTable table = read_measurements(path, line6d_read_options());
      r.warnings = table.warnings;
      Line6dOptions lo;
      lo.remove_straightness_line = !o.keep_line;
      lo.angular = o.angular == "mean" ? AngularReference::Mean : AngularReference::None;
      const Line6dData d = line6d_from_table(table, lo);
      pos_name = d.axis;
      rows = d.position.size();
      for (const Line6dProfile& p : d.profiles) {
        PdgeProfile q;
        q.name = p.error;
        q.column = p.source;
        q.unit = p.unit;
        const PdgeProfileSource src{
            p.error, profile_kind_name(p.kind), p.unit,           p.source, p.removed,
            p.sign,  p.reference.intercept,     p.reference.slope};
        r.line6d_conversions.push_back(src);
        q.source = src;
        for (std::size_t i = 0; i < p.values.size(); ++i) {
          if (std::isnan(p.values[i])) continue;
          q.x.push_back(d.position[i]);
          q.y.push_back(p.values[i]);
          if (!d.cycle.empty()) q.cycle.push_back(d.cycle[i]);
        }
        profiles.push_back(std::move(q));
      }
      r.line6d_spelling = d.spelling;
    } else {
      const MeasurementTable table = read_measurements(path);
      r.warnings = table.warnings;
      rows = table.rows();
      pos_name = o.axis.empty() ? head.header_key("axis") : o.axis;
      if (pos_name.empty()) {
        std::vector<std::string> varying;
        for (const std::string& c : table.columns_with(ColumnRole::Coordinate)) {
          const auto& v = table.column(c);
          if (std::any_of(v.begin(), v.end(), [&](double a) { return a != v.front(); }))
            varying.push_back(c);
        }
        if (varying.size() != 1)
          throw std::invalid_argument("give the position column with --axis (" +
                                      std::to_string(varying.size()) +
                                      " coordinate columns vary in " + path + ")");
        pos_name = varying.front();
      }
      const std::vector<double>& pos = table.column(pos_name);
      std::vector<int> cyc;
      if (table.has("cycle"))
        for (double c : table.column("cycle")) cyc.push_back(static_cast<int>(c));
      for (const std::string& c : table.columns_with(ColumnRole::Deviation)) {
        PdgeProfile q;
        q.name = c;
        q.column = c;
        q.unit = table.info_of(c).unit;
        const auto& v = table.column(c);
        for (std::size_t i = 0; i < v.size(); ++i) {
          if (std::isnan(v[i]) || std::isnan(pos[i])) continue;
          q.x.push_back(pos[i]);
          q.y.push_back(v[i]);
          if (!cyc.empty()) q.cycle.push_back(cyc[i]);
        }
        if (!q.x.empty()) profiles.push_back(std::move(q));
      }
    }
  }
  // --column selection.
  const std::vector<std::string> wanted = split_list(o.columns);
  if (!wanted.empty()) {
    std::vector<PdgeProfile> chosen;
    for (const std::string& w : wanted) {
      auto it = std::find_if(profiles.begin(), profiles.end(), [&](const PdgeProfile& p) {
        return p.name == w || p.column == w || p.name + "_" + p.unit == w;
      });
      if (it == profiles.end()) {
        std::string known;
        for (const PdgeProfile& p : profiles) known += (known.empty() ? "" : ", ") + p.name;
        throw std::invalid_argument("--column: \"" + w + "\" is not a profile of " + path +
                                    " (profiles: " + (known.empty() ? "none" : known) + ")");
      }
      chosen.push_back(*it);
    }
    profiles = std::move(chosen);
  }
  if (profiles.empty())
    throw std::invalid_argument(path + ": no profile to fit (no deviation or 6D column)");

  // Travel: --travel, else the smallest to largest position of every profile.
  double& a = r.travel_a;
  double& b = r.travel_b;
  a = INFINITY, b = -INFINITY;
  if (!o.travel.empty()) {
    std::tie(a, b) = parse_travel(o.travel);
  } else {
    for (const PdgeProfile& p : profiles)
      for (double v : p.x) a = std::min(a, v), b = std::max(b, v);
  }
  Basis::make(BasisKind::Polynomial, 0, a, b);  // zero-length travel: a clear message

  PdgeFitOptions& fo = r.fit_options;
  fo.min_order = o.min_order;
  fo.max_order = o.max_order;
  fo.rule = o.rule == "1se" ? OrderRule::OneStandardError : OrderRule::Minimum;
  fo.cv.scheme = o.cv == "blocks" ? CvScheme::Blocks : CvScheme::Cycles;
  fo.cv.folds = o.folds;
  const PdgeFit fitter(fo);

  // ---- fit ----
  // A basis the data cannot support is reported and the others still fitted; exit status 1.
  auto& results = r.results;
  auto& failures = r.failures;
  results.resize(profiles.size());
  failures.resize(profiles.size());
  for (std::size_t i = 0; i < profiles.size(); ++i) {
    const PdgeProfile& p = profiles[i];
    for (const BasisSpec& s : r.specs) {
      try {
        results[i].push_back(fitter.run(p.x, p.y, p.cycle, s, a, b));
        failures[i].emplace_back();
      } catch (const std::invalid_argument& e) {
        results[i].emplace_back();
        results[i].back().spec = s;
        failures[i].push_back(e.what());
        ++r.failed;
      }
    }
  }

  return r;
}

}  // namespace weilgen
