#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>

#include "effects.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/machine/iso_names.hpp"

namespace weilgen::gap_detail {

// ---- reversal ------------------------------------------------------------------------------

void add_reversal(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  if (d.dir.empty()) return;
  const std::vector<int> outs = outputs_of(d);
  Candidate c;
  c.name = "reversal";
  std::vector<std::string> axes;
  for (const auto& [axis, v] : d.dir) {
    axes.push_back(axis);
    c.variants.push_back({axis, {static_cast<double>(axes.size() - 1)}});
  }
  c.columns = [&d, outs, axes](const Variant& v, const std::vector<double>&) {
    const std::vector<double>& dir = d.dir.at(axes[static_cast<std::size_t>(v.hyper[0])]);
    return per_output(d, outs, [&](std::size_t r) { return dir[r] / 2; });  // ±B/2
  };
  c.describe = [outs, axes](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const std::string& axis = axes[static_cast<std::size_t>(v.hyper[0])];
    std::size_t big = 0;
    for (std::size_t k = 1; k < outs.size(); ++k)
      if (std::abs(coef[static_cast<Index>(k)]) > std::abs(coef[static_cast<Index>(big)])) big = k;
    fit.summary = "reversal " + num(std::abs(coef[static_cast<Index>(big)]), 2) + " " +
                  unit_of(outs[big]) + " on " + axis + " (" +
                  per_output_text(outs, coef, 1, "", fit, "reversal") + ")";
    fit.params["axis_" + axis] = 1;
    GapRegion r;
    r.by = "dir_" + axis;
    r.output = output_name(static_cast<std::size_t>(outs[big]));
    r.from = -1;
    r.to = 1;
    fit.region = r;
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
