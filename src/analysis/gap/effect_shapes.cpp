// periodic and pdge_shape: a shape of one motion error of one axis along that axis (a pitch
// error of a ball screw, a bump in a guideway), sent through the kinematics: the columns are the
// error's sensitivity at each observation's pose times the shape of the axis position. On a
// 3-axis machine a straightness shape moves one output; on a turning table or a tilting head the
// same error reaches the outputs rotated, and an angular error through its lever arm.
#include <algorithm>
#include <cmath>
#include <memory>

#include "effects.hpp"
#include "weilgen/base/constants.hpp"

namespace weilgen::gap_detail {

namespace {

// Per observation: the error's sensitivity times f(axis position), one column per f.
MatrixXd shaped(const GapData& d, const AxisError& ae,
                const std::vector<std::function<double(double)>>& f) {
  const auto& obs = d.points.observations;
  MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(f.size()));
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double w = (*ae.unit)[static_cast<Index>(i)];
    if (w == 0) continue;
    const double q = d.points.poses[obs[i].row][ae.axis.index];
    for (std::size_t k = 0; k < f.size(); ++k)
      E(static_cast<Index>(i), static_cast<Index>(k)) = w * f[k](q);
  }
  return E;
}

std::string axis_unit(const GapData& d, const AxisError& ae) {
  return ae.axis.index < d.axis_units.size() ? d.axis_units[ae.axis.index] : "mm";
}

// "E_YX of X" (with the errors the data cannot tell from it).
std::string error_of(const AxisError& ae) {
  std::string s = ae.name + " of " + ae.axis.name;
  for (const std::string& o : ae.same_as) s += " (or " + o + ")";
  return s;
}

void mark_shape(Variant& v, const AxisError& ae) {
  v.shape_axis = static_cast<int>(ae.axis.index);
  v.shape_output = ae.output;
  v.shape_weight = ae.unit;
  v.shape_key = ae.name;
}

GapRegion shape_region(const AxisError& ae, double from, double to) {
  GapRegion r;
  r.by = ae.axis.name;
  r.output = observation_name(static_cast<std::size_t>(ae.output));
  r.from = from;
  r.to = to;
  return r;
}

void describe_error(const AxisError& ae, EffectFit& fit) {
  fit.params["error_" + ae.name] = 1;
  fit.params["axis_" + ae.axis.name] = 1;
}

}  // namespace

void add_periodic(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  const auto errors = shaped_errors(ctx);
  if (errors->empty()) return;
  Candidate c;
  c.name = "periodic";
  // hyper: [error list index, period (axis unit)]
  for (std::size_t k = 0; k < errors->size(); ++k) {
    const auto& L = (*errors)[k].axis.levels;
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
    for (int g = 0; g < grid; ++g) {
      const double cycles = c_lo + dcyc * g, period = span / cycles;
      c.variants.push_back({error_of((*errors)[k]),
                            {static_cast<double>(k), period},
                            false,
                            {{1, span / (cycles + dcyc), span / std::max(cycles - dcyc, 1.0)}}});
      mark_shape(c.variants.back(), (*errors)[k]);
    }
  }
  if (c.variants.empty()) return;
  c.columns = [&d, errors](const Variant& v, const std::vector<double>&) {
    const double w = 2 * kPi / v.hyper[1];
    return shaped(
        d, (*errors)[static_cast<std::size_t>(v.hyper[0])],
        {[w](double q) { return std::cos(w * q); }, [w](double q) { return std::sin(w * q); }});
  };
  c.describe = [&d, errors](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const AxisError& ae = (*errors)[static_cast<std::size_t>(v.hyper[0])];
    const std::string au = axis_unit(d, ae), eu = ae.rotation ? "urad" : "um";
    const double amp = std::hypot(coef[0], coef[1]);
    fit.params["period_" + au] = v.hyper[1];
    fit.params["amplitude_" + eu] = amp;
    describe_error(ae, fit);
    fit.summary = "periodic " + error_of(ae) + ": period " + format_short(v.hyper[1], 3) + " " +
                  au + ", " + format_short(amp, 2) + (ae.rotation ? " µrad" : " µm");
    fit.region = shape_region(ae, ae.axis.levels.front(), ae.axis.levels.back());
  };
  out.push_back(std::move(c));
}

void add_pdge_shape(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  const auto errors = shaped_errors(ctx);
  if (errors->empty()) return;
  Candidate c;
  c.name = "pdge_shape";
  // hyper: [error list index, kind (0 bump, 1 extra degrees), centre, width]
  for (std::size_t k = 0; k < errors->size(); ++k) {
    const AxisError& ae = (*errors)[k];
    const auto& L = ae.axis.levels;
    const double span = L.back() - L.front();
    const std::string head = error_of(ae);
    c.variants.push_back({head + ", degrees 4-5", {static_cast<double>(k), 1, 0, 0}});
    mark_shape(c.variants.back(), ae);
    // Centres at a quarter of the sample spacing (at most 61): on a coarse grid the fit of a
    // bump between two sample positions differs by orders of magnitude from one centred on
    // either, so centres on the samples alone miss the truth's local minimum.
    const std::size_t nc = std::min<std::size_t>(61, 4 * (L.size() - 1) + 1);
    const double dc = span / static_cast<double>(nc - 1);
    for (std::size_t i = 0; i < nc; ++i) {
      const double centre = L.front() + dc * static_cast<double>(i);
      for (double f : {1.0 / 30, 1.0 / 15, 1.0 / 8}) {
        c.variants.push_back({head + ", bump",
                              {static_cast<double>(k), 0, centre, span * f},
                              false,
                              {{2, centre - dc, centre + dc}, {3, span * f / 2, span * f * 2}}});
        mark_shape(c.variants.back(), ae);
      }
    }
  }
  c.columns = [&d, errors](const Variant& v, const std::vector<double>&) {
    const AxisError& ae = (*errors)[static_cast<std::size_t>(v.hyper[0])];
    if (v.hyper[1] == 1) {
      const double lo = ae.axis.levels.front(), hi = ae.axis.levels.back();
      auto u = [lo, hi](double q) { return (2 * q - lo - hi) / (hi - lo); };
      return shaped(d, ae,
                    {[u](double q) { return std::pow(u(q), 4); },
                     [u](double q) { return std::pow(u(q), 5); }});
    }
    const double c0 = v.hyper[2], w = v.hyper[3];
    return shaped(d, ae,
                  {[c0, w](double q) { return std::exp(-0.5 * (q - c0) * (q - c0) / (w * w)); }});
  };
  c.describe = [&d, errors](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const AxisError& ae = (*errors)[static_cast<std::size_t>(v.hyper[0])];
    const std::string au = axis_unit(d, ae), eu = ae.rotation ? "urad" : "um";
    const char* eus = ae.rotation ? " µrad" : " µm";
    describe_error(ae, fit);
    if (v.hyper[1] == 1) {
      fit.summary = "more shape of " + error_of(ae) + ": u^4 " + format_short(coef[0], 2) +
                    ", u^5 " + format_short(coef[1], 2) + eus;
      fit.region = shape_region(ae, ae.axis.levels.front(), ae.axis.levels.back());
      return;
    }
    const double centre = v.hyper[2], width = v.hyper[3];
    fit.params["centre_" + au] = centre;
    fit.params["width_" + au] = width;
    fit.params["amplitude_" + eu] = coef[0];
    fit.summary = "bump of " + error_of(ae) + ": " + format_short(coef[0], 2) + eus + " at " +
                  ae.axis.name + " = " + format_short(centre, 4) + " " + au + " (width " +
                  format_short(width, 3) + " " + au + ")";
    fit.region = shape_region(ae, centre - 2 * width, centre + 2 * width);
    // A bump is resolved when at least 3 sample positions carry a tenth of its height or
    // more (|q - c| < 2.15 w); over one or two it is a step or a single position's offset.
    const auto covered = std::count_if(ae.axis.levels.begin(), ae.axis.levels.end(), [&](double q) {
      return std::abs(q - centre) < 2.15 * width;
    });
    fit.params["positions_covered"] = static_cast<double>(covered);
    if (covered < 3) {
      fit.distinguishable = false;
      fit.indistinct_reason = "the bump covers " + std::to_string(covered) + " sample position" +
                              (covered == 1 ? "" : "s") + " along " + ae.axis.name +
                              ": narrower than the sampling, it cannot be told from a step";
    }
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
