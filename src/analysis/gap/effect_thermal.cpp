// thermal_drift as a growth of the machine with time or temperature, sent through the
// kinematics (docs/gap.md, "Effect library"): the spindle side grows in the tool's frame (it
// turns with a tilting head), the structure before the rotary axes in the machine's (a turning
// table shows it rotated), and each linear axis' positioning scale grows with it (the axis'
// position times the signal, through the axis Jacobian). The signal is linear in time, a heat-up
// lag 1 - e^{-t/tau}, or a temperature sensor as read or through a first-order lag.
#include <algorithm>
#include <cmath>
#include <memory>

#include "effects.hpp"
#include "weilgen/machine/iso_names.hpp"

namespace weilgen::gap_detail {

namespace {

constexpr double kLagRatio = 1.5;

struct ThermalContext {
  const GapData* d = nullptr;
  double t0 = 0, t1 = 0;
  std::vector<std::string> sensors;
  std::vector<Frame> frames;
  std::vector<std::vector<Eigen::Matrix3d>> rotation;  // per frame, per row
  std::vector<Eigen::MatrixXd> jacobian;               // per row (axis Jacobians)
  std::vector<std::size_t> linear;                     // GapData::axes indices of linear axes
  std::vector<int> linear_dir;                         // each one's machine direction 0..2
  bool angles = false;                                 // angular outputs measured
};

// hyper: [kind, tau_s, sensor, frame, target]; kind 0 = linear in time, 1 = heat-up lag,
// 2 = sensor (lagged by tau_s, 0 = as read); target -1 = every direction, 0..2 = one direction
// of the frame with the scale of the linear axis along it.
std::vector<double> signal_of(const ThermalContext& tc, const Variant& v) {
  const GapData& d = *tc.d;
  const int kind = static_cast<int>(v.hyper[0]);
  std::vector<double> s(d.time_s.size(), 0.0);
  if (kind == 0) {
    for (std::size_t r = 0; r < s.size(); ++r) s[r] = (d.time_s[r] - tc.t0) / 3600.0;
  } else if (kind == 1) {
    for (std::size_t r = 0; r < s.size(); ++r)
      s[r] = 1 - std::exp(-(d.time_s[r] - tc.t0) / v.hyper[1]);
  } else {
    s = first_order_lag(d, d.temperature.at(tc.sensors[static_cast<std::size_t>(v.hyper[2])]),
                        v.hyper[1]);
    double mean = 0;
    for (const auto& o : d.points.observations) mean += s[o.row];
    mean /= static_cast<double>(std::max<std::size_t>(1, d.points.observations.size()));
    for (double& x : s) x -= mean;
  }
  for (double& x : s)
    if (!std::isfinite(x)) x = 0;
  return s;
}

struct Columns {
  MatrixXd E;
  std::vector<std::string> labels;  // "drift_x", "tilt_a", "scale_X"
};

// The variant's columns, each kept only when it adds to the ones before (a fixed coordinate's
// scale is the offset again; a frame direction no output sees is zero).
Columns thermal_columns(const ThermalContext& tc, const Variant& v) {
  const GapData& d = *tc.d;
  const auto& obs = d.points.observations;
  const std::vector<double> s = signal_of(tc, v);
  const auto& R = tc.rotation[static_cast<std::size_t>(v.hyper[3])];
  const int target = static_cast<int>(v.hyper[4]);
  std::vector<VectorXd> cols;
  std::vector<std::string> labels;
  const auto n = static_cast<Index>(obs.size());
  for (int k = 0; k < 3; ++k) {
    if (target >= 0 && k != target) continue;
    for (int part = 0; part < (tc.angles ? 2 : 1); ++part) {
      VectorXd c(n);
      for (std::size_t i = 0; i < obs.size(); ++i) {
        double v6[6] = {0, 0, 0, 0, 0, 0};
        for (int o = 0; o < 3; ++o) v6[3 * part + o] = R[obs[i].row](o, k) * 1e-3 * s[obs[i].row];
        if (part == 1)
          for (int o = 3; o < 6; ++o) v6[o] *= 1e-3;  // µrad: 1e-6 rad
        c[static_cast<Index>(i)] = measured(obs[i], v6);
      }
      cols.push_back(c);
      labels.push_back(std::string(part ? "tilt_" : "drift_") + "xyz"[k]);
    }
  }
  for (std::size_t a = 0; a < tc.linear.size(); ++a) {
    if (target >= 0 && tc.linear_dir[a] != target) continue;
    VectorXd c(n);
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const Eigen::MatrixXd& J = tc.jacobian[obs[i].row];
      if (J.size() == 0) {
        c[static_cast<Index>(i)] = 0;
        continue;
      }
      const double q_m = d.points.poses[obs[i].row][tc.linear[a]] / 1000;
      double v6[6];
      for (int o = 0; o < 6; ++o)
        v6[o] = J(o, static_cast<Index>(tc.linear[a])) * q_m * s[obs[i].row] * 1e-3;
      c[static_cast<Index>(i)] = measured(obs[i], v6);
    }
    cols.push_back(c);
    labels.push_back("scale_" + d.axes[tc.linear[a]]);
  }
  // Keep a column when it adds to the kept ones (Gram-Schmidt, relative 1e-9).
  Columns out;
  std::vector<VectorXd> basis;
  std::vector<std::size_t> keep;
  for (std::size_t k = 0; k < cols.size(); ++k) {
    VectorXd r = cols[k];
    for (const VectorXd& b : basis) r -= b * b.dot(r);
    if (!(r.norm() > 1e-9 * std::max(1e-300, cols[k].norm()))) continue;
    basis.push_back(r / r.norm());
    keep.push_back(k);
  }
  out.E.resize(n, static_cast<Index>(keep.size()));
  for (std::size_t k = 0; k < keep.size(); ++k) {
    out.E.col(static_cast<Index>(k)) = cols[keep[k]];
    out.labels.push_back(labels[keep[k]]);
  }
  return out;
}

// A fitted thermal variant in words and parameters: its kind (time, heat-up, sensor), frame,
// drift and scale per axis, and the region it explains.
void describe_thermal(const ThermalContext& tc, const Variant& v, const VectorXd& coef,
                      EffectFit& fit) {
  const GapData& data = *tc.d;
  const int kind = static_cast<int>(v.hyper[0]);
  const Frame frame = tc.frames[static_cast<std::size_t>(v.hyper[3])];
  const Columns cols = thermal_columns(tc, v);
  const std::string per = kind == 0 ? "_per_h" : kind == 1 ? "" : "_per_K";
  const std::string per_text = kind == 0 ? "/h" : kind == 1 ? "" : "/K";
  std::string drift, scale;
  for (std::size_t k = 0; k < cols.labels.size() && static_cast<Index>(k) < coef.size(); ++k) {
    const std::string& l = cols.labels[k];
    const double x = coef[static_cast<Index>(k)];
    const std::string sx = (x >= 0 ? "+" : "") + format_short(x, 2);
    if (l.rfind("scale_", 0) == 0) {
      fit.params[l + "_um_per_m" + per] = x;
      scale += (scale.empty() ? "" : ", ") + std::string("scale of ") + l.substr(6) + " " + sx +
               " µm/m" + per_text;
    } else {
      const bool tilt = l[0] == 't';
      fit.params[l + (tilt ? "_urad" : "_um") + per] = x;
      drift += (drift.empty() ? "" : ", ") + std::string(tilt ? "tilt " : "") + l.back() + " " +
               sx + (tilt ? " µrad" : " µm") + per_text;
    }
  }
  fit.params[frame == Frame::Tool ? "frame_tool" : "frame_machine"] = 1;
  std::string what;
  if (kind == 0) {
    what = "drift in time";
  } else if (kind == 1) {
    fit.params["tau_h"] = v.hyper[1] / 3600;
    what = "heat-up (tau " + format_short(v.hyper[1] / 3600, 2) + " h)";
  } else {
    const std::string& s = tc.sensors[static_cast<std::size_t>(v.hyper[2])];
    fit.params["sensor_" + s] = 1;
    fit.params["lag_h"] = v.hyper[1] / 3600;
    what = s + (v.hyper[1] > 0 ? " (lag " + format_short(v.hyper[1] / 3600, 2) + " h)" : "");
  }
  fit.summary = "thermal, " + what +
                (frame == Frame::Tool ? ", tool side: " : ", machine frame: ") +
                (drift.empty() ? "" : drift) + (drift.empty() || scale.empty() ? "" : "; ") + scale;
  // Where: along the signal's own coordinate, in the output the fitted growth moves most.
  const auto& obs = data.points.observations;
  const VectorXd moved = cols.E * coef.head(cols.E.cols());
  std::array<double, kObservationKinds> ss{};
  for (std::size_t i = 0; i < obs.size(); ++i)
    ss[static_cast<std::size_t>(obs[i].output)] +=
        moved[static_cast<Index>(i)] * moved[static_cast<Index>(i)];
  GapRegion r;
  r.output = observation_name(
      static_cast<std::size_t>(std::max_element(ss.begin(), ss.end()) - ss.begin()));
  if (kind < 2) {
    r.by = "t_s";
    r.unit = "s";
    r.from = tc.t0;
    r.to = tc.t1;
  } else {
    r.by = tc.sensors[static_cast<std::size_t>(v.hyper[2])];
    r.unit = "°C";
    const std::vector<double>& T = data.temperature.at(r.by);
    r.from = INFINITY;
    r.to = -INFINITY;
    for (const auto& o : obs)
      if (std::isfinite(T[o.row]))
        r.from = std::min(r.from, T[o.row]), r.to = std::max(r.to, T[o.row]);
  }
  fit.region = r;
}

}  // namespace

void add_thermal(const EffectContext& ctx, std::vector<Candidate>& out) {
  const GapData& d = *ctx.data;
  if (!ctx.chain) return;
  auto tc = std::make_shared<ThermalContext>();
  tc->d = &d;
  double t0 = INFINITY, t1 = -INFINITY;
  for (const auto& o : d.points.observations)
    if (std::isfinite(d.time_s[o.row]))
      t0 = std::min(t0, d.time_s[o.row]), t1 = std::max(t1, d.time_s[o.row]);
  const bool time = t1 > t0;
  tc->t0 = t0;
  tc->t1 = t1;
  for (const auto& [name, v] : d.temperature) tc->sensors.push_back(name);
  if (!time && tc->sensors.empty()) return;
  // The tool's frame always; the machine's where it differs (a tilting head, a turning table).
  tc->frames.push_back(Frame::Tool);
  tc->rotation.push_back(frame_rotations(ctx, Frame::Tool));
  {
    std::vector<Eigen::Matrix3d> m = frame_rotations(ctx, Frame::Machine);
    bool differs = false;
    for (std::size_t r = 0; r < m.size() && !differs; ++r)
      differs = (m[r] - tc->rotation[0][r]).norm() > 1e-9;
    if (differs) {
      tc->frames.push_back(Frame::Machine);
      tc->rotation.push_back(std::move(m));
    }
  }
  const Description& desc = ctx.model->description();
  const std::vector<int> bodies = desc.axes();
  for (std::size_t a = 0; a < d.axes.size() && a < bodies.size(); ++a) {
    const Joint& j = desc.bodies[static_cast<std::size_t>(bodies[a])].joint;
    if (j.type != JointType::Prismatic || axis_values(d, a).size() < 2) continue;
    tc->linear.push_back(a);
    tc->linear_dir.push_back(principal_axis(j.axis));
  }
  if (!tc->linear.empty()) tc->jacobian = axis_jacobians(ctx);
  const std::vector<int> outs = outputs_of(d);
  for (int o : outs) tc->angles = tc->angles || o >= 3;

  Candidate c;
  c.name = "thermal_drift";
  // Lags are scanned over the whole range on a fine log grid (ratio 1.5) before the best is
  // refined between its neighbours: with cycle folds the training error over the lag has
  // several minima, and a coarse grid refined by golden section can settle in the wrong one.
  std::vector<double> lags;  // fractions of the run
  for (double f = 0.01; f <= 2.0 * kLagRatio; f *= kLagRatio) lags.push_back(f);
  // One direction at a time as well as all together: a structure's sensors differ per
  // direction, and the greedy search may take one per direction.
  std::vector<double> targets = {-1};
  int dirs = 0;
  for (int o : outs) dirs += o < 3;
  if (dirs > 1)
    for (int k = 0; k < 3; ++k) targets.push_back(k);
  for (std::size_t f = 0; f < tc->frames.size(); ++f) {
    const std::string in = tc->frames[f] == Frame::Tool ? "" : " (machine frame)";
    const auto fr = static_cast<double>(f);
    if (time) {
      c.variants.push_back({"linear in time" + in, {0, 0, -1, fr, -1}});
      for (double x : lags)
        c.variants.push_back({"heat-up lag" + in,
                              {1, (t1 - t0) * x, -1, fr, -1},
                              false,
                              {{1, (t1 - t0) * x / kLagRatio, (t1 - t0) * x * kLagRatio}}});
    }
    for (double target : targets)
      for (std::size_t j = 0; j < tc->sensors.size(); ++j) {
        const std::string head = "temperature " + tc->sensors[j] +
                                 (target < 0 ? "" : std::string(" along ") + "xyz"[int(target)]) +
                                 in;
        const auto sj = static_cast<double>(j);
        c.variants.push_back({head, {2, 0, sj, fr, target}});
        if (time)
          for (double x : lags)
            if (x <= 0.5)
              c.variants.push_back({head + " lagged",
                                    {2, (t1 - t0) * x, sj, fr, target},
                                    false,
                                    {{1, (t1 - t0) * x / kLagRatio, (t1 - t0) * x * kLagRatio}}});
      }
  }
  c.columns = [tc](const Variant& v, const std::vector<double>&) {
    return thermal_columns(*tc, v).E;
  };
  c.describe = [tc](const Variant& v, const VectorXd& coef, EffectFit& fit) {
    describe_thermal(*tc, v, coef, fit);
  };
  out.push_back(std::move(c));
}

}  // namespace weilgen::gap_detail
