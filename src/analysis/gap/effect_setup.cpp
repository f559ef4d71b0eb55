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

// ---- setup ---------------------------------------------------------------------------------

void add_setup(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  Candidate c;
  c.name = "setup";
  // Instrument misalignment along the measured direction: dx read with a scale (cosine or
  // wavelength) error proportional to the travel along X, per run when runs were re-set-up.
  for (int o : outputs_of(d)) {
    if (o > 2) continue;
    const std::string axis(1, static_cast<char>('X' + o));
    const auto it = std::find(d.axes.begin(), d.axes.end(), axis);
    if (it == d.axes.end() ||
        axis_values(d, static_cast<std::size_t>(it - d.axes.begin())).size() < 3)
      continue;
    c.variants.push_back({std::string(output_name(static_cast<std::size_t>(o))) + " along " + axis,
                          {static_cast<double>(o), static_cast<double>(it - d.axes.begin())}});
  }
  // A ballbar's length calibration: a constant dr (µm).
  if (d.points.count[kRadialOutput]) c.variants.push_back({"ballbar length", {-1, 0}});
  if (c.variants.empty()) return;
  c.columns = [&d](const Variant& v, const std::vector<double>&) {
    if (v.hyper[0] < 0) return per_output(d, {kRadialOutput}, [](std::size_t) { return 1.0; });
    const std::size_t a = static_cast<std::size_t>(v.hyper[1]);
    return one_output(d, static_cast<int>(v.hyper[0]),
                      {[](double q) { return q / 1000.0; }, [](double q) { return q * q / 1e6; }},
                      a);
  };
  c.describe = [&d](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    if (v.hyper[0] < 0) {
      fit.params["length_um"] = coef[0];
      const double r = d.circle ? d.circle->radius_mm : 0;
      if (r > 0) fit.params["scale_ppm"] = coef[0] / r * 1000;
      fit.summary =
          "ballbar length " + format_short(coef[0], 3) + " µm" +
          (r > 0 ? " (" + format_short(coef[0] / r * 1000, 3) + " µm/m of the radius)" : "");
      return;
    }
    fit.params["scale_ppm"] = coef[0];
    fit.params["quadratic_um_per_m2"] = coef[1];
    fit.summary = "measuring set-up: scale " + format_short(coef[0], 3) + " µm/m (ppm) in " +
                  v.label + ", quadratic " + format_short(coef[1], 3) + " µm/m²";
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
