#include "weilgen/analysis/gap_effects.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "weilgen/base/text.hpp"
#include "weilgen/machine/iso_names.hpp"

namespace weilgen::gap_detail {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Index = Eigen::Index;
const char* unit_of(int o) { return observation_unit(static_cast<std::size_t>(o)); }

std::string num(double v, int digits = 3) {
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

// The deviation outputs (0..5) the observations see: their own, and for ballbar dr the
// in-plane directions.
std::vector<int> outputs_of(const GapData& d) {
  std::set<int> o;
  for (const auto& ob : d.points.observations)
    for (int k = 0; k < 6; ++k)
      if (observation_weight(ob, k) != 0) o.insert(k);
  return {o.begin(), o.end()};
}

// Per observation: f(row) in output o (as much of it as the observation sees, for dr its radial
// component), zero elsewhere; one column per output.
template <typename F>
MatrixXd per_output(const GapData& d, const std::vector<int>& outs, F f) {
  const auto& obs = d.points.observations;
  MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(outs.size()));
  for (std::size_t i = 0; i < obs.size(); ++i)
    for (std::size_t k = 0; k < outs.size(); ++k) {
      const double w = observation_weight(obs[i], outs[k]);
      if (w != 0) E(static_cast<Index>(i), static_cast<Index>(k)) = w * f(obs[i].row);
    }
  return E;
}

// "dx +2.1 µm/h, dy -0.4 µm/h" from per-output coefficients.
std::string per_output_text(const std::vector<int>& outs, const VectorXd& c, double scale,
                            const std::string& unit_suffix, EffectFit& fit,
                            const std::string& key) {
  std::string s;
  for (std::size_t k = 0; k < outs.size(); ++k) {
    const double v = c[static_cast<Index>(k)] * scale;
    s += (s.empty() ? "" : ", ") + std::string(output_name(static_cast<std::size_t>(outs[k]))) +
         " " + (v >= 0 ? "+" : "") + num(v, 2) + " " + unit_of(outs[k]) + unit_suffix;
    fit.params[key + "_" + output_name(static_cast<std::size_t>(outs[k]))] = v;
  }
  return s;
}

std::vector<double> axis_values(const GapData& d, std::size_t a) {
  std::vector<double> v;
  for (const auto& p : d.points.poses)
    if (!p.empty() && std::isfinite(p[a])) v.push_back(p[a]);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// ---- thermal_drift -----------------------------------------------------------------------

void add_thermal(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  const std::vector<int> outs = outputs_of(d);
  double t0 = INFINITY, t1 = -INFINITY;
  for (const auto& o : d.points.observations)
    if (std::isfinite(d.time_s[o.row]))
      t0 = std::min(t0, d.time_s[o.row]), t1 = std::max(t1, d.time_s[o.row]);
  const bool time = t1 > t0;
  if (!time && d.temperature.empty()) return;
  Candidate c;
  c.name = "thermal_drift";
  // hyper: [kind, tau_s or sensor index]; kind 0 = linear in time, 1 = lag in time,
  // 2 = temperature (offset), 3 = temperature × coordinate along the output (scale).
  if (time) {
    c.variants.push_back({"linear in time", {0, 0}});
    for (double f : {0.03, 0.1, 0.3, 1.0})
      c.variants.push_back({"heat-up lag",
                            {1, (t1 - t0) * f},
                            false,
                            {{1, (t1 - t0) * f / 3.2, (t1 - t0) * f * 3.2}}});
  }
  std::vector<std::string> sensors;
  for (const auto& [name, v] : d.temperature) sensors.push_back(name);
  // Each sensor, as read and through a first-order lag (the structure heats up behind the
  // sensor): hyper[2] = tau (s, 0 = none). Offset and scale (ΔT × the coordinate along the
  // output) together.
  // hyper[3]: the output the sensor acts on, or -1 for all measured outputs together (a
  // structure's sensors differ per direction: the greedy search may take one per output).
  std::vector<double> targets = {-1};
  if (outs.size() > 1)
    for (int o : outs) targets.push_back(o);
  for (double target : targets)
    for (std::size_t j = 0; j < sensors.size(); ++j) {
      const std::string head =
          "temperature " + sensors[j] +
          (target < 0 ? "" : std::string(" on ") + output_name(static_cast<std::size_t>(target)));
      c.variants.push_back({head, {2, static_cast<double>(j), 0, target}});
      if (time)
        for (double f : {0.03, 0.1, 0.3})
          c.variants.push_back({head + " lagged",
                                {2, static_cast<double>(j), (t1 - t0) * f, target},
                                false,
                                {{2, (t1 - t0) * f / 3.2, (t1 - t0) * f * 3.2}}});
    }
  auto mean_of = [&d](const std::vector<double>& v) {
    double sum = 0;
    std::size_t n = 0;
    for (const auto& o : d.points.observations) sum += v[o.row], ++n;
    return n ? sum / static_cast<double>(n) : 0.0;
  };
  // First-order lag of a per-row signal in time order.
  auto lagged = [&d](const std::vector<double>& T, double tau) {
    if (!(tau > 0)) return T;
    std::vector<std::size_t> rows;
    for (std::size_t r = 0; r < T.size(); ++r)
      if (std::isfinite(T[r]) && std::isfinite(d.time_s[r])) rows.push_back(r);
    std::stable_sort(rows.begin(), rows.end(),
                     [&](std::size_t a, std::size_t b) { return d.time_s[a] < d.time_s[b]; });
    std::vector<double> f = T;
    for (std::size_t k = 1; k < rows.size(); ++k) {
      const double dt = d.time_s[rows[k]] - d.time_s[rows[k - 1]];
      f[rows[k]] = f[rows[k - 1]] + (1 - std::exp(-dt / tau)) * (T[rows[k]] - f[rows[k - 1]]);
    }
    return f;
  };
  c.columns = [&d, outs, t0, sensors, mean_of, lagged](const Variant& v,
                                                       const std::vector<double>&) {
    const int kind = static_cast<int>(v.hyper[0]);
    if (kind == 0)
      return per_output(d, outs, [&](std::size_t r) { return (d.time_s[r] - t0) / 3600.0; });
    if (kind == 1) {
      const double tau = v.hyper[1];
      return per_output(d, outs,
                        [&](std::size_t r) { return 1 - std::exp(-(d.time_s[r] - t0) / tau); });
    }
    const std::vector<int> outs_v =
        v.hyper[3] < 0 ? outs : std::vector<int>{static_cast<int>(v.hyper[3])};
    const std::vector<double> T =
        lagged(d.temperature.at(sensors[static_cast<std::size_t>(v.hyper[1])]), v.hyper[2]);
    const double Tm = mean_of(T);
    const MatrixXd offset = per_output(d, outs_v, [&](std::size_t r) { return T[r] - Tm; });
    // Scale: ΔT times the coordinate along the output's direction (dx with X ...), in m.
    const auto& obs = d.points.observations;
    MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(outs_v.size()));
    for (std::size_t i = 0; i < obs.size(); ++i)
      for (std::size_t k = 0; k < outs_v.size(); ++k) {
        const double w = observation_weight(obs[i], outs_v[k]);
        if (w == 0 || outs_v[k] > 2) continue;
        const std::string axis(1, static_cast<char>('X' + outs_v[k]));
        const auto it = std::find(d.axes.begin(), d.axes.end(), axis);
        if (it == d.axes.end()) continue;
        const double q = d.points.poses[obs[i].row][static_cast<std::size_t>(it - d.axes.begin())];
        E(static_cast<Index>(i), static_cast<Index>(k)) = w * (T[obs[i].row] - Tm) * q / 1000.0;
      }
    std::vector<Index> keep;  // scale columns that vary (a fixed coordinate adds nothing)
    for (Index k = 0; k < E.cols(); ++k)
      if ((E.col(k) - offset.col(k) * (E.col(k).dot(offset.col(k)) /
                                       std::max(1e-300, offset.col(k).squaredNorm())))
              .norm() > 1e-9 * std::max(1.0, E.col(k).norm()))
        keep.push_back(k);
    MatrixXd all(E.rows(), offset.cols() + static_cast<Index>(keep.size()));
    all.leftCols(offset.cols()) = offset;
    for (std::size_t k = 0; k < keep.size(); ++k)
      all.col(offset.cols() + static_cast<Index>(k)) = E.col(keep[k]);
    return all;
  };
  c.describe = [outs, sensors](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const int kind = static_cast<int>(v.hyper[0]);
    if (kind == 0) {
      fit.summary = "drift " + per_output_text(outs, coef, 1, "/h", fit, "rate_per_h");
    } else if (kind == 1) {
      fit.params["tau_h"] = v.hyper[1] / 3600;
      fit.summary = "heat-up drift (tau " + num(v.hyper[1] / 3600, 2) +
                    " h): " + per_output_text(outs, coef, 1, "", fit, "amplitude");
    } else {
      const std::string& s = sensors[static_cast<std::size_t>(v.hyper[1])];
      fit.params["sensor_" + s] = 1;
      fit.params["lag_h"] = v.hyper[2] / 3600;
      const std::vector<int> outs_v =
          v.hyper[3] < 0 ? outs : std::vector<int>{static_cast<int>(v.hyper[3])};
      fit.summary = "thermal, " + s +
                    (v.hyper[2] > 0 ? " (lag " + num(v.hyper[2] / 3600, 2) + " h)" : "") + ": " +
                    per_output_text(outs_v, coef.head(static_cast<Index>(outs_v.size())), 1, "/K",
                                    fit, "per_K");
    }
  };
  out.push_back(std::move(c));
}

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
  };
  out.push_back(std::move(c));
}

// ---- periodic and pdge_shape (position-dependent shapes along one axis, one output) --------

struct AxisInfo {
  std::size_t index;
  std::string name;
  std::vector<double> levels;
};

std::vector<AxisInfo> varying_axes(const GapData& d, std::size_t min_levels) {
  std::vector<AxisInfo> v;
  for (std::size_t a = 0; a < d.axes.size(); ++a) {
    AxisInfo ai{a, d.axes[a], axis_values(d, a)};
    if (ai.levels.size() >= min_levels) v.push_back(ai);
  }
  return v;
}

MatrixXd one_output(const GapData& d, int output,
                    const std::vector<std::function<double(double)>>& f, std::size_t axis) {
  const auto& obs = d.points.observations;
  MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), static_cast<Index>(f.size()));
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const double w = observation_weight(obs[i], output);
    if (w == 0) continue;
    const double q = d.points.poses[obs[i].row][axis];
    for (std::size_t k = 0; k < f.size(); ++k)
      E(static_cast<Index>(i), static_cast<Index>(k)) = w * f[k](q);
  }
  return E;
}

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

// ---- Model-based effects: higher_order, missing_error, tool_offset ------------------------

// Exact-chain deviation (µm, µrad) at an observation's pose for given errors (base units).
std::array<double, 6> exact(const NumericChain& chain, const std::vector<double>& pose,
                            const std::vector<double>& errors) {
  std::array<double, 6> v = chain.deviation(pose, errors);
  for (std::size_t o = 0; o < 6; ++o) v[o] *= kMeasuredScale[o];
  return v;
}

void add_higher_order(const EffectContext& ctx, std::vector<Candidate>& out) {
  Candidate c;
  c.name = "higher_order";
  c.variants.push_back({"products of errors (exact kinematics)", {}, true});
  const GapData& d = *ctx.data;
  c.columns = [&d, ctx](const Variant&, const std::vector<double>& theta) {
    const auto& obs = d.points.observations;
    MatrixXd E(static_cast<Index>(obs.size()), 1);
    ModelData md(*ctx.model);
    std::vector<double> err(ctx.model->num_errors());
    std::size_t row = SIZE_MAX;
    std::array<double, 6> nonlinear{};
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (obs[i].row != row) {
        row = obs[i].row;
        const std::vector<double>& q = d.points.poses[row];
        ctx.param->errors_at(q.data(), theta.data(), err.data());
        const std::array<double, 6> full = exact(*ctx.chain, q, err);
        const std::array<double, 6> lin =
            predict_deviation(*ctx.model, md, *ctx.param, theta, q.data());
        for (std::size_t o = 0; o < 6; ++o) nonlinear[o] = full[o] - lin[o];
      }
      E(static_cast<Index>(i), 0) = observe(obs[i], nonlinear);
    }
    return E;
  };
  c.describe = [](const Variant&, const VectorXd& coef, EffectFit& fit) {
    fit.params["scale"] = coef[0];
    fit.summary = "second- and higher-order products of the identified errors (scale " +
                  num(coef[0], 3) +
                  " of the exact kinematics' nonlinear part; regenerate at "
                  "algebra order 2)";
  };
  out.push_back(std::move(c));
}

void add_missing_error(const EffectContext& ctx, std::vector<Candidate>& out) {
  const Description& desc = ctx.model->description();
  const GapData& d = *ctx.data;
  struct Missing {
    std::string name, coordinate;
    bool pdge;
    double lo, hi;
    MatrixXd unit;  // per observation: ∂output/∂error (µm or µrad per declared unit)
  };
  auto missing = std::make_shared<std::vector<Missing>>();
  const std::vector<int> axes = desc.axes();
  for (std::size_t b = 0; b < desc.bodies.size(); ++b) {
    const Joint& j = desc.bodies[b].joint;
    if (j.type == JointType::Fixed || j.link || !iso_not_applicable(j).empty()) continue;
    std::vector<std::string> names = iso_motion_errors(j);
    for (const char* k : {"X", "Y", "Z", "A", "B", "C"})  // squareness and location errors
      names.push_back(std::string("E_") + k + "0" + j.coordinate);
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    for (const std::string& n : names) {
      if (desc.error_index(n) >= 0) continue;
      const IsoMatch m = match_iso_name(j, n);
      if (m.status != IsoMatch::Status::Fits) continue;
      Description aug = desc;
      ErrorDef e;
      e.name = e.iso = n;
      e.effect = m.error.effect;
      e.direction = m.error.direction;
      e.group = m.error.group;
      e.placement = m.error.placement;
      e.dependence = m.error.dependence;
      e.unit = m.error.unit;
      e.to_base = e.effect == ErrorEffect::Rotation ? 1e-6 : 1e-3;  // µrad, µm
      e.body = static_cast<int>(b);
      aug.errors.push_back(e);
      aug.bodies[b].errors.push_back(static_cast<int>(aug.errors.size() - 1));
      NumericChain chain(aug);
      chain.set_parameters(ctx.model->parameters());
      const auto& obs = d.points.observations;
      Missing mi{n,     j.coordinate, e.dependence == Dependence::PDGE,
                 j.min, j.max,        MatrixXd(static_cast<Index>(obs.size()), 1)};
      std::vector<double> err(aug.errors.size(), 0.0);
      std::size_t row = SIZE_MAX;
      std::array<double, 6> g{};
      for (std::size_t i = 0; i < obs.size(); ++i) {
        if (obs[i].row != row) {
          row = obs[i].row;
          err.back() = e.to_base;  // 1 µm or µrad: central differences, third order ~1e-12
          const auto p = exact(chain, d.points.poses[row], err);
          err.back() = -e.to_base;
          const auto m2 = exact(chain, d.points.poses[row], err);
          for (std::size_t o = 0; o < 6; ++o) g[o] = (p[o] - m2[o]) / 2;
        }
        mi.unit(static_cast<Index>(i), 0) = observe(obs[i], g);
      }
      if (mi.unit.norm() > 0) missing->push_back(std::move(mi));
    }
  }
  if (missing->empty()) return;
  Candidate c;
  c.name = "missing_error";
  for (std::size_t k = 0; k < missing->size(); ++k)
    c.variants.push_back({(*missing)[k].name, {static_cast<double>(k)}});
  // The coordinate of each observation for a PDGE's basis (poly:3 on the joint's travel).
  c.columns = [&d, missing, axes, &desc](const Variant& v, const std::vector<double>&) {
    const Missing& mi = (*missing)[static_cast<std::size_t>(v.hyper[0])];
    if (!mi.pdge) return MatrixXd(mi.unit);
    std::size_t a = 0;
    for (std::size_t i = 0; i < axes.size(); ++i)
      if (desc.bodies[static_cast<std::size_t>(axes[i])].joint.coordinate == mi.coordinate) a = i;
    const auto& obs = d.points.observations;
    MatrixXd E(static_cast<Index>(obs.size()), 4);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const double u = (2 * d.points.poses[obs[i].row][a] - mi.lo - mi.hi) / (mi.hi - mi.lo);
      double p = 1;
      for (Index t = 0; t < 4; ++t, p *= u)
        E(static_cast<Index>(i), t) = mi.unit(static_cast<Index>(i), 0) * p;
    }
    return E;
  };
  c.describe = [missing](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const Missing& mi = (*missing)[static_cast<std::size_t>(v.hyper[0])];
    const bool rot =
        mi.name.size() > 2 && (mi.name[2] == 'A' || mi.name[2] == 'B' || mi.name[2] == 'C');
    const char* unit = rot ? "µrad" : "µm";
    if (!mi.pdge) {
      fit.params[mi.name] = coef[0];
      fit.summary = mi.name + " = " + num(coef[0], 3) + " " + unit + " (not in the machine file)";
    } else {
      double peak = 0;
      for (double u = -1; u <= 1.0001; u += 0.05)
        peak = std::max(peak, std::abs(coef[0] + u * (coef[1] + u * (coef[2] + u * coef[3]))));
      fit.params[mi.name + "_peak"] = peak;
      fit.summary = mi.name + "(" + mi.coordinate + ") up to " + num(peak, 3) + " " + unit +
                    " over the travel (poly:3; not in the machine file)";
    }
  };
  out.push_back(std::move(c));
}

void add_tool_offset(const EffectContext& ctx, std::vector<Candidate>& out) {
  const Description& desc = ctx.model->description();
  int tool = -1;
  for (std::size_t p = 0; p < desc.parameters.size(); ++p)
    if (lower(desc.parameters[p].name).find("tool") != std::string::npos)
      tool = static_cast<int>(p);
  if (tool < 0) return;
  Candidate c;
  c.name = "tool_offset";
  const std::string pname = desc.parameters[static_cast<std::size_t>(tool)].name;
  c.variants.push_back({pname, {static_cast<double>(tool)}, true});
  c.variants.back().theta_iterations = 1;
  const GapData& d = *ctx.data;
  const double base = ctx.model->parameters()[static_cast<std::size_t>(tool)];
  c.columns = [&d, ctx, tool, base](const Variant&, const std::vector<double>& theta) {
    // ∂deviation/∂tool length at the identified errors (µm per mm), by central differences of
    // the exact chain over ±10 mm.
    std::vector<double> params = ctx.model->parameters();
    NumericChain plus(ctx.model->description()), minus(ctx.model->description());
    params[static_cast<std::size_t>(tool)] = base + 10;
    plus.set_parameters(params);
    params[static_cast<std::size_t>(tool)] = base - 10;
    minus.set_parameters(params);
    const auto& obs = d.points.observations;
    MatrixXd E(static_cast<Index>(obs.size()), 1);
    std::vector<double> err(ctx.model->num_errors());
    std::size_t row = SIZE_MAX;
    std::array<double, 6> g{};
    for (std::size_t i = 0; i < obs.size(); ++i) {
      if (obs[i].row != row) {
        row = obs[i].row;
        const std::vector<double>& q = d.points.poses[row];
        ctx.param->errors_at(q.data(), theta.data(), err.data());
        const auto p = exact(plus, q, err), m = exact(minus, q, err);
        for (std::size_t o = 0; o < 6; ++o) g[o] = (p[o] - m[o]) / 20;
      }
      E(static_cast<Index>(i), 0) = observe(obs[i], g);
    }
    return E;
  };
  c.describe = [pname, base](const Variant&, const VectorXd& coef, EffectFit& fit) {
    fit.params["offset_mm"] = coef[0];
    fit.params[pname + "_mm"] = base + coef[0];
    fit.summary = "tool offset " + num(coef[0], 3) + " mm (" + pname + " " + num(base, 4) + " -> " +
                  num(base + coef[0], 4) + " mm)";
  };
  out.push_back(std::move(c));
}

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
      fit.summary = "ballbar length " + num(coef[0], 3) + " µm" +
                    (r > 0 ? " (" + num(coef[0] / r * 1000, 3) + " µm/m of the radius)" : "");
      return;
    }
    fit.params["scale_ppm"] = coef[0];
    fit.params["quadratic_um_per_m2"] = coef[1];
    fit.summary = "measuring set-up: scale " + num(coef[0], 3) + " µm/m (ppm) in " + v.label +
                  ", quadratic " + num(coef[1], 3) + " µm/m²";
  };
  out.push_back(std::move(c));
}

}  // namespace

std::vector<Candidate> effect_candidates(const EffectContext& ctx,
                                         const std::vector<std::string>& names) {
  std::vector<Candidate> out;
  for (const std::string& n : names) {
    if (n == "thermal_drift")
      add_thermal(ctx, out);
    else if (n == "reversal")
      add_reversal(ctx, out);
    else if (n == "periodic")
      add_periodic(ctx, out);
    else if (n == "pdge_shape")
      add_pdge_shape(ctx, out);
    else if (n == "higher_order")
      add_higher_order(ctx, out);
    else if (n == "missing_error")
      add_missing_error(ctx, out);
    else if (n == "tool_offset")
      add_tool_offset(ctx, out);
    else if (n == "setup")
      add_setup(ctx, out);
    else
      throw std::invalid_argument("--effects: unknown effect '" + n +
                                  "' (the library: " + join(gap_effect_names()) + ")");
  }
  return out;
}

}  // namespace weilgen::gap_detail
