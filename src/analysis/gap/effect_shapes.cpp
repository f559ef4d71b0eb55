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

// ---- periodic and pdge_shape (position-dependent shapes along one axis, one output) --------

void add_periodic(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  const std::vector<AxisInfo> axes = varying_axes(d, 6);
  if (axes.empty()) return;
  Candidate c;
  c.name = "periodic";
  // hyper: [axis list index, output, period]
  for (std::size_t k = 0; k < axes.size(); ++k) {
    const auto& L = axes[k].levels;
    std::vector<double> gaps;
    for (std::size_t i = 1; i < L.size(); ++i) gaps.push_back(L[i] - L[i - 1]);
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<long>(gaps.size() / 2), gaps.end());
    const double step = gaps[gaps.size() / 2], span = L.back() - L.front();
    // At least 1.5 periods within the data: a single half-wave is a shape (pdge_shape), and a
    // longer "period" would fit steps and trends that are not periodic.
    const double lo = 2.5 * step, hi = span / 1.5;
    if (!(hi > lo)) continue;
    // Periods uniform in the number of cycles over the span, a quarter cycle apart (at least
    // 40): a wave fitted with a period a quarter cycle off over the span has lost its phase by
    // its far end, so a coarser grid can miss a short period on a long axis altogether.
    const double c_lo = span / hi, c_hi = span / lo;
    const int grid = std::max(40, static_cast<int>(std::ceil((c_hi - c_lo) / 0.25)) + 1);
    const double dcyc = (c_hi - c_lo) / (grid - 1);
    for (int o : outputs_of(d))
      for (int g = 0; g < grid; ++g) {
        const double cycles = c_lo + dcyc * g, period = span / cycles;
        c.variants.push_back({axes[k].name + ", " + output_name(static_cast<std::size_t>(o)),
                              {static_cast<double>(k), static_cast<double>(o), period},
                              false,
                              {{2, span / (cycles + dcyc), span / std::max(cycles - dcyc, 1.0)}}});
        c.variants.back().shape_axis = static_cast<int>(axes[k].index);
        c.variants.back().shape_output = o;
      }
  }
  if (c.variants.empty()) return;
  c.columns = [&d, axes](const Variant& v, const std::vector<double>&) {
    const double w = 2 * M_PI / v.hyper[2];
    return one_output(
        d, static_cast<int>(v.hyper[1]),
        {[w](double q) { return std::cos(w * q); }, [w](double q) { return std::sin(w * q); }},
        axes[static_cast<std::size_t>(v.hyper[0])].index);
  };
  c.describe = [axes](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const AxisInfo& a = axes[static_cast<std::size_t>(v.hyper[0])];
    const int o = static_cast<int>(v.hyper[1]);
    const double amp = std::hypot(coef[0], coef[1]);
    fit.params["period_mm"] = v.hyper[2];
    fit.params["amplitude"] = amp;
    fit.summary = "period " + num(v.hyper[2], 3) + " mm, " + num(amp, 2) + " " + unit_of(o) +
                  " in " + output_name(static_cast<std::size_t>(o)) + " along " + a.name;
    GapRegion r;
    r.by = a.name;
    r.output = output_name(static_cast<std::size_t>(o));
    r.from = a.levels.front();
    r.to = a.levels.back();
    fit.region = r;
  };
  out.push_back(std::move(c));
}

void add_pdge_shape(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  const std::vector<AxisInfo> axes = varying_axes(d, 6);
  if (axes.empty()) return;
  Candidate c;
  c.name = "pdge_shape";
  // hyper: [axis list index, output, kind (0 bump, 1 extra degrees), centre, width]
  for (std::size_t k = 0; k < axes.size(); ++k) {
    const auto& L = axes[k].levels;
    const double span = L.back() - L.front();
    for (int o : outputs_of(d)) {
      const std::string head = axes[k].name + ", " + output_name(static_cast<std::size_t>(o));
      c.variants.push_back(
          {head + ", degrees 4-5", {static_cast<double>(k), static_cast<double>(o), 1, 0, 0}});
      c.variants.back().shape_axis = static_cast<int>(axes[k].index);
      c.variants.back().shape_output = o;
      // Centres at a quarter of the sample spacing (at most 61): on a coarse grid the fit of a
      // bump between two sample positions differs by orders of magnitude from one centred on
      // either, so centres on the samples alone miss the truth's local minimum.
      const std::size_t nc = std::min<std::size_t>(61, 4 * (L.size() - 1) + 1);
      const double dc = span / static_cast<double>(nc - 1);
      for (std::size_t i = 0; i < nc; ++i) {
        const double centre = L.front() + dc * static_cast<double>(i);
        for (double f : {1.0 / 30, 1.0 / 15, 1.0 / 8}) {
          c.variants.push_back(
              {head + ", bump",
               {static_cast<double>(k), static_cast<double>(o), 0, centre, span * f},
               false,
               {{3, centre - dc, centre + dc}, {4, span * f / 2, span * f * 2}}});
          c.variants.back().shape_axis = static_cast<int>(axes[k].index);
          c.variants.back().shape_output = o;
        }
      }
    }
  }
  c.columns = [&d, axes](const Variant& v, const std::vector<double>&) {
    const AxisInfo& a = axes[static_cast<std::size_t>(v.hyper[0])];
    const int o = static_cast<int>(v.hyper[1]);
    if (v.hyper[2] == 1) {
      const double lo = a.levels.front(), hi = a.levels.back();
      auto u = [lo, hi](double q) { return (2 * q - lo - hi) / (hi - lo); };
      return one_output(d, o,
                        {[u](double q) { return std::pow(u(q), 4); },
                         [u](double q) { return std::pow(u(q), 5); }},
                        a.index);
    }
    const double c0 = v.hyper[3], w = v.hyper[4];
    return one_output(
        d, o, {[c0, w](double q) { return std::exp(-0.5 * (q - c0) * (q - c0) / (w * w)); }},
        a.index);
  };
  c.describe = [axes](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const AxisInfo& a = axes[static_cast<std::size_t>(v.hyper[0])];
    const int o = static_cast<int>(v.hyper[1]);
    GapRegion r;
    r.by = a.name;
    r.output = output_name(static_cast<std::size_t>(o));
    if (v.hyper[2] == 1) {
      fit.summary = "more shape along " + a.name + " in " +
                    output_name(static_cast<std::size_t>(o)) + ": u^4 " + num(coef[0], 2) +
                    ", u^5 " + num(coef[1], 2) + " " + unit_of(o);
      r.from = a.levels.front();
      r.to = a.levels.back();
    } else {
      fit.params["centre"] = v.hyper[3];
      fit.params["width"] = v.hyper[4];
      fit.params["amplitude"] = coef[0];
      fit.summary = "bump " + num(coef[0], 2) + " " + unit_of(o) + " in " +
                    output_name(static_cast<std::size_t>(o)) + " at " + a.name + " = " +
                    num(v.hyper[3], 4) + " (width " + num(v.hyper[4], 3) + ")";
      r.from = v.hyper[3] - 2 * v.hyper[4];
      r.to = v.hyper[3] + 2 * v.hyper[4];
      // A bump is resolved when at least 3 sample positions carry a tenth of its height or
      // more (|q - c| < 2.15 w); over one or two it is a step or a single position's offset.
      const auto covered = std::count_if(a.levels.begin(), a.levels.end(), [&](double q) {
        return std::abs(q - v.hyper[3]) < 2.15 * v.hyper[4];
      });
      fit.params["positions_covered"] = static_cast<double>(covered);
      if (covered < 3) {
        fit.distinguishable = false;
        fit.indistinct_reason = "the bump covers " + std::to_string(covered) + " sample position" +
                                (covered == 1 ? "" : "s") + " along " + a.name +
                                ": narrower than the sampling, it cannot be told from a step";
      }
    }
    fit.region = r;
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
