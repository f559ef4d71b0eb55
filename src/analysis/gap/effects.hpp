// The candidate unmodelled effects of the gap diagnosis (docs/gap.md, "Effect library"): each is
// a set of variants (hyper-parameters such as a period, a lag, an axis), and a variant gives
// extra design columns for every observation. Internal to the gap diagnosis and its tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "internal.hpp"
#include "weilgen/base/format.hpp"
#include "weilgen/model/numeric_chain.hpp"
#include "weilgen/uq/dense.hpp"

namespace weilgen::gap_detail {

struct AxisError;

// What an effect's columns need to know: the data, the model and its parameterisation, the
// observation-to-row map, and a numeric chain for the linearised effects.
struct EffectContext {
  const GapData* data = nullptr;
  const Model* model = nullptr;
  const ErrorParameterisation* param = nullptr;
  std::shared_ptr<const NumericChain> chain;  // exact kinematics (higher_order, tool_offset)
  // The axes' motion errors with their sensitivities (axis_errors(ctx, 6)), shared by the shape
  // effects; computed on first use.
  mutable std::shared_ptr<const std::vector<AxisError>> shaped_errors;
  // axis_jacobians(ctx), shared by the reversal and thermal effects; computed on first use.
  mutable std::shared_ptr<const std::vector<Eigen::MatrixXd>> jacobians;
  unsigned threads = 1;  // for the loops over poses and candidate errors (GapOptions::threads)
};

struct Variant {
  struct Refine;
  Variant() = default;
  Variant(std::string l, std::vector<double> h, bool theta = false, std::vector<Refine> r = {})
      : label(std::move(l)), hyper(std::move(h)), needs_theta(theta), refine(std::move(r)) {}
  std::string label;          // "temperature T_1 lagged", "X, dy"
  std::vector<double> hyper;  // effect-specific numbers
  bool needs_theta = false;   // columns depend on the identified parameters
  // Continuous hyper-parameters refined around the grid value: (index, lo, hi) bounds.
  std::vector<Refine> refine;
  // A shape along one coordinate (periodic, pdge_shape): GapData::axes index and the output
  // 0..5 it moves most; -1 for other effects. The diagnosis checks that the data can tell the
  // shape from any other along that coordinate. `shape_weight`: per observation, how much of
  // the shaped error it sees (the error's sensitivity); null: the observation's weight in
  // shape_output. `shape_key` names the shaped quantity (an error), shape_output when empty.
  int shape_axis = -1, shape_output = -1;
  std::shared_ptr<const Eigen::VectorXd> shape_weight;
  std::string shape_key;
  // needs_theta: refit θ jointly with the columns this many times before they are taken (the
  // columns at the first-order θ are biased when that θ has absorbed part of the effect).
  int theta_iterations = 0;
};

struct Variant::Refine {
  std::size_t index;
  double lo, hi;
};

struct Candidate {
  std::string name;
  std::vector<Variant> variants;
  // Columns (observations × q) of a variant; `theta` is the baseline parameters of the split
  // (only read when the variant needs_theta).
  std::function<Eigen::MatrixXd(const Variant&, const std::vector<double>& theta)> columns;
  // A regularised model of many inputs (the multi-sensor thermal model) instead of `columns`:
  // its columns are fitted on a training part, from those rows (observation indices) and the
  // baseline's residual there, and predict every observation. Held-out observations never
  // inform their own columns, so the candidate is tested on its held-out improvement.
  std::function<Eigen::MatrixXd(const Variant&, const std::vector<std::size_t>& train,
                                const Eigen::VectorXd& train_residual)>
      fitted_columns;
  // A nonlinear refit instead of θ_iterations (higher_order): from a split's linear θ (all of
  // A's columns), the θ (first np entries) fitted to the training rows `train` of y through the
  // exact kinematics; the columns are taken there. Fitted per split like fitted_columns, so the
  // held-out improvement is what is tested (it has more effective parameters than columns).
  std::function<std::vector<double>(const std::vector<std::size_t>& train,
                                    const Eigen::VectorXd& theta, const Eigen::MatrixXd& A,
                                    const Eigen::VectorXd& y)>
      refit;
  // Fills summary/params/region of `fit` from the full-data coefficients c of the columns.
  std::function<void(const Variant&, const Eigen::VectorXd& c, EffectFit& fit)> describe;
  // The columns are terms of one shape (a missing PDGE): describe gets only the part of c the
  // data determine (determined_part; fit.terms and fit.terms_absorbed say how much is left out).
  bool determined_part = false;
};

// The library's candidates that apply to the data (e.g. reversal needs a direction column);
// the library is the table in effects.cpp.
std::vector<Candidate> effect_candidates(const EffectContext& ctx,
                                         const std::vector<std::string>& names);
// Whether the greedy search may accept the effect again (a second sensor or lag).
bool effect_repeatable(const std::string& name);

// One family of the library each (effect_*.cpp): appends its candidate, if the data allow it.
void add_thermal(const EffectContext& ctx, std::vector<Candidate>& out);
void add_thermal_sensors(const EffectContext& ctx, std::vector<Candidate>& out);
void add_reversal(const EffectContext& ctx, std::vector<Candidate>& out);
void add_periodic(const EffectContext& ctx, std::vector<Candidate>& out);
void add_pdge_shape(const EffectContext& ctx, std::vector<Candidate>& out);
void add_higher_order(const EffectContext& ctx, std::vector<Candidate>& out);
void add_missing_error(const EffectContext& ctx, std::vector<Candidate>& out);
void add_tool_offset(const EffectContext& ctx, std::vector<Candidate>& out);
void add_setup(const EffectContext& ctx, std::vector<Candidate>& out);

// ---- Helpers of the effect files --------------------------------------------------------

inline const char* unit_of(int o) { return observation_unit(static_cast<std::size_t>(o)); }

// The deviation outputs (0..5) the observations see: their own, and for ballbar dr the
// in-plane directions.
inline std::vector<int> outputs_of(const GapData& d) {
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
inline std::string per_output_text(const std::vector<int>& outs, const VectorXd& c, double scale,
                                   const std::string& unit_suffix, EffectFit& fit,
                                   const std::string& key) {
  std::string s;
  for (std::size_t k = 0; k < outs.size(); ++k) {
    const double v = c[static_cast<Index>(k)] * scale;
    s += (s.empty() ? "" : ", ") + std::string(output_name(static_cast<std::size_t>(outs[k]))) +
         " " + (v >= 0 ? "+" : "") + format_short(v, 2) + " " + unit_of(outs[k]) + unit_suffix;
    fit.params[key + "_" + output_name(static_cast<std::size_t>(outs[k]))] = v;
  }
  return s;
}

inline std::vector<double> axis_values(const GapData& d, std::size_t a) {
  std::vector<double> v;
  for (const auto& p : d.points.poses)
    if (!p.empty() && std::isfinite(p[a])) v.push_back(p[a]);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

// Axes with at least `min_levels` distinct positions, and the columns f_k(position) of one output.
struct AxisInfo {
  std::size_t index;
  std::string name;
  std::vector<double> levels;
};

inline std::vector<AxisInfo> varying_axes(const GapData& d, std::size_t min_levels) {
  std::vector<AxisInfo> v;
  for (std::size_t a = 0; a < d.axes.size(); ++a) {
    AxisInfo ai{a, d.axes[a], axis_values(d, a)};
    if (ai.levels.size() >= min_levels) v.push_back(ai);
  }
  return v;
}

inline MatrixXd one_output(const GapData& d, int output,
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

// First-order lag (time constant tau_s, s) of a per-row signal, in time order; the signal as it
// is for tau_s <= 0. Rows without a time or a value keep theirs.
inline std::vector<double> first_order_lag(const GapData& d, const std::vector<double>& T,
                                           double tau_s) {
  if (!(tau_s > 0)) return T;
  std::vector<std::size_t> rows;
  for (std::size_t r = 0; r < T.size(); ++r)
    if (std::isfinite(T[r]) && std::isfinite(d.time_s[r])) rows.push_back(r);
  std::stable_sort(rows.begin(), rows.end(),
                   [&](std::size_t a, std::size_t b) { return d.time_s[a] < d.time_s[b]; });
  std::vector<double> f = T;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    const double dt = d.time_s[rows[k]] - d.time_s[rows[k - 1]];
    f[rows[k]] = f[rows[k - 1]] + (1 - std::exp(-dt / tau_s)) * (T[rows[k]] - f[rows[k - 1]]);
  }
  return f;
}

// The nominal Jacobian of the outputs with respect to every axis at each table row, from the
// exact chain by central differences: [row] -> 6 x axes, in mm (or rad) per unit of the axis
// (mm, deg). An effect of an axis (its backlash, its scale) reaches the outputs through it, the
// rotation of a turning table included.
std::vector<Eigen::MatrixXd> axis_jacobians(const EffectContext& ctx);

// A 6-vector deviation (mm, rad) as an observation sees it (µm, µrad; a dr its radial part).
double measured(const PointObservation& ob, const double* v6);

// The frames a thermal growth is fixed in: the tool's (the spindle grows along its own axis and
// turns with a head) or the machine base's (a column or ram; a turning table shows its growth
// rotated). Per table row, the frame's orientation in the workpiece frame, whose outputs the
// data measure (identity where nothing turns).
enum class Frame { Tool, Machine };
std::vector<Eigen::Matrix3d> frame_rotations(const EffectContext& ctx, Frame frame);

// One motion error of one axis that the machine file has (ISO 230-1: E_XX, E_YX ... E_CC) and
// how much of it every observation sees: the periodic and bump shapes are shapes of one such
// error along its axis, sent through the kinematics (the model's coefficients at the pose).
struct AxisError {
  AxisInfo axis;                         // the axis and its distinct positions
  int error = -1;                        // Description::errors index
  std::string name;                      // E_XX
  bool rotation = false;                 // the error in µrad (else µm)
  std::vector<std::string> same_as;      // errors of this axis whose columns are proportional
  int output = 0;                        // the observation kind it moves most
  std::shared_ptr<const VectorXd> unit;  // per observation: µm (µrad) per µm (µrad) of error
};
// The errors of every axis with at least `min_levels` positions that reach the observations,
// positioning first, then straightness, then angular; errors with the same column (up to a
// factor) as one before are folded into its `same_as`.
std::vector<AxisError> axis_errors(const EffectContext& ctx, std::size_t min_levels);
// axis_errors(ctx, 6), computed once per context.
std::shared_ptr<const std::vector<AxisError>> shaped_errors(const EffectContext& ctx);

}  // namespace weilgen::gap_detail
