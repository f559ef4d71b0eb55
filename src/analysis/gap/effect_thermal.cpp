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
  // Lags are scanned over the whole range on a fine log grid (ratio 1.5) before the best is
  // refined between its neighbours: with cycle folds the training error over the lag has
  // several minima, and a coarse grid refined by golden section can settle in the wrong one.
  const double ratio = 1.5;
  std::vector<double> lags;  // fractions of the run
  for (double f = 0.01; f <= 2.0 * ratio; f *= ratio) lags.push_back(f);
  if (time) {
    c.variants.push_back({"linear in time", {0, 0}});
    for (double f : lags)
      c.variants.push_back({"heat-up lag",
                            {1, (t1 - t0) * f},
                            false,
                            {{1, (t1 - t0) * f / ratio, (t1 - t0) * f * ratio}}});
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
        for (double f : lags)
          if (f <= 0.5)
            c.variants.push_back({head + " lagged",
                                  {2, static_cast<double>(j), (t1 - t0) * f, target},
                                  false,
                                  {{2, (t1 - t0) * f / ratio, (t1 - t0) * f * ratio}}});
    }
  auto mean_of = [&d](const std::vector<double>& v) {
    double sum = 0;
    std::size_t n = 0;
    for (const auto& o : d.points.observations) sum += v[o.row], ++n;
    return n ? sum / static_cast<double>(n) : 0.0;
  };
  auto lagged = [&d](const std::vector<double>& T, double tau) {
    return first_order_lag(d, T, tau);
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

}  // namespace weilgen::gap_detail

namespace weilgen::gap_detail {

// ---- thermal_drift in the machine frame ----------------------------------------------------
// The spindle, column and headstock grow in the machine's frame; a table that turns (A, C)
// shows that growth to the workpiece rotated by its own orientation. Offered when the
// workpiece frame turns over the data: a drift vector fixed in the machine frame (3 parameters)
// following time (linear or a heat-up lag) or a sensor (as read or lagged), seen through
// R_workpiece(q)^T.
void add_thermal_machine_frame(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  if (!ctx.chain) return;
  auto rt = std::make_shared<std::vector<Eigen::Matrix3d>>(d.points.poses.size(),
                                                           Eigen::Matrix3d::Identity());
  bool turns = false;
  std::vector<char> needed(d.points.poses.size(), 0);
  for (const auto& o : d.points.observations) needed[o.row] = 1;
  const Eigen::Matrix3d* first = nullptr;
  for (std::size_t r = 0; r < rt->size(); ++r) {
    if (!needed[r] || d.points.poses[r].size() != d.axes.size()) continue;
    (*rt)[r] = ctx.chain->workpiece_in_base(d.points.poses[r]).block<3, 3>(0, 0).transpose();
    if (!first) first = &(*rt)[r];
    turns = turns || ((*rt)[r] - *first).norm() > 1e-9;
  }
  if (!turns) return;
  double t0 = INFINITY, t1 = -INFINITY;
  for (const auto& o : d.points.observations)
    if (std::isfinite(d.time_s[o.row]))
      t0 = std::min(t0, d.time_s[o.row]), t1 = std::max(t1, d.time_s[o.row]);
  const bool time = t1 > t0;
  std::vector<std::string> sensors;
  for (const auto& [name, v] : d.temperature) sensors.push_back(name);
  if (!time && sensors.empty()) return;
  Candidate c;
  c.name = "thermal_drift";
  // hyper: [kind, tau_s, sensor]; kind 0 = linear in time, 1 = heat-up lag, 2 = sensor (lag
  // tau_s, 0 = as read).
  const double ratio = 1.5;
  if (time) {
    c.variants.push_back({"linear in time (machine frame)", {0, 0, -1}});
    for (double f = 0.01; f <= 2.0 * ratio; f *= ratio)
      c.variants.push_back({"heat-up lag (machine frame)",
                            {1, (t1 - t0) * f, -1},
                            false,
                            {{1, (t1 - t0) * f / ratio, (t1 - t0) * f * ratio}}});
  }
  for (std::size_t j = 0; j < sensors.size(); ++j) {
    c.variants.push_back(
        {"temperature " + sensors[j] + " (machine frame)", {2, 0, static_cast<double>(j)}});
    if (time)
      for (double f = 0.01; f <= 0.5; f *= ratio)
        c.variants.push_back({"temperature " + sensors[j] + " lagged (machine frame)",
                              {2, (t1 - t0) * f, static_cast<double>(j)},
                              false,
                              {{1, (t1 - t0) * f / ratio, (t1 - t0) * f * ratio}}});
  }
  c.columns = [&d, rt, t0, sensors](const Variant& v, const std::vector<double>&) {
    const int kind = static_cast<int>(v.hyper[0]);
    std::vector<double> signal(d.time_s.size(), 0.0);
    if (kind == 0) {
      for (std::size_t r = 0; r < signal.size(); ++r) signal[r] = (d.time_s[r] - t0) / 3600.0;
    } else if (kind == 1) {
      for (std::size_t r = 0; r < signal.size(); ++r)
        signal[r] = 1 - std::exp(-(d.time_s[r] - t0) / v.hyper[1]);
    } else {
      signal = first_order_lag(d, d.temperature.at(sensors[static_cast<std::size_t>(v.hyper[2])]),
                               v.hyper[1]);
      double mean = 0;
      for (const auto& o : d.points.observations) mean += signal[o.row];
      mean /= static_cast<double>(std::max<std::size_t>(1, d.points.observations.size()));
      for (double& s : signal) s -= mean;
    }
    const auto& obs = d.points.observations;
    MatrixXd E = MatrixXd::Zero(static_cast<Index>(obs.size()), 3);
    for (std::size_t i = 0; i < obs.size(); ++i)
      for (int o = 0; o < 3; ++o) {
        const double w = observation_weight(obs[i], o);
        if (w == 0) continue;
        for (int k = 0; k < 3; ++k)  // µm of drift along machine axis k
          E(static_cast<Index>(i), k) += w * (*rt)[obs[i].row](o, k) * signal[obs[i].row];
      }
    return E;
  };
  c.describe = [sensors](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    const int kind = static_cast<int>(v.hyper[0]);
    std::string what = kind == 0 ? "drift per h" : kind == 1 ? "heat-up drift" : "per K";
    if (kind == 1) fit.params["tau_h"] = v.hyper[1] / 3600;
    if (kind == 2) {
      fit.params["sensor_" + sensors[static_cast<std::size_t>(v.hyper[2])]] = 1;
      fit.params["lag_h"] = v.hyper[1] / 3600;
    }
    std::string s;
    for (int k = 0; k < 3 && k < coef.size(); ++k) {
      const std::string axis(1, static_cast<char>('x' + k));
      fit.params["machine_" + axis + "_um"] = coef[k];
      s += (k ? ", " : "") + axis + " " + num(coef[k], 2) + " µm";
    }
    fit.summary = "thermal in the machine frame (" + v.label + "), " + what + ": " + s;
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
