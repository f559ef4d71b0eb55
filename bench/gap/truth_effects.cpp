// The effects the truth generator withholds (bench/gap/README.md, "Effects"): one row each in
// effect_table() with its placement on the layout (axis, error, direction, shape: the draws from
// the effect's own stream) and its truth.json parameters and localisation. How an effect acts on
// the measured values is in Synthesiser::errors_at (an error's shape), Synthesiser::evaluate
// (the chain, the tool point, the instrument) and scale_effects (its amplitude).
#include <algorithm>
#include <cmath>
#include <set>

#include "truth.hpp"

namespace weilgen::gapbench {

// What every placement may use: the layout's axes and measured directions.
struct Synthesiser::Placement {
  std::vector<int> linear;  // linear axes with a travel
  std::vector<int> moving;  // the axes an axis-bound effect may sit on: those the layout moves
  std::set<int> measured_dims;
};

// The names a description uses.
struct Synthesiser::Labels {
  std::string output;     // the dominant measured column: dx, dy, dz or dr
  std::string axis;       // the effect's axis, or empty
  std::string error;      // the effect's error, or empty
  bool rotation = false;  // the error is a rotation (µrad) rather than a translation (µm)
  std::string axis_unit;  // deg on a rotary axis, else mm
};

const std::vector<Synthesiser::EffectDef>& Synthesiser::effect_table() {
  // The diagnosis library's effects in confusion-matrix order, then "step" (outside it).
  static const std::vector<EffectDef> table = {
      {EffectKind::ThermalDrift, "thermal_drift", true, true, 1, &Synthesiser::place_thermal,
       &Synthesiser::describe_thermal},
      {EffectKind::Reversal, "reversal", true, true, 1, &Synthesiser::place_reversal,
       &Synthesiser::describe_reversal},
      {EffectKind::Periodic, "periodic", true, true, 1, &Synthesiser::place_shape,
       &Synthesiser::describe_periodic},
      {EffectKind::PdgeShape, "pdge_shape", true, true, 1, &Synthesiser::place_shape,
       &Synthesiser::describe_pdge_shape},
      // Second-order terms of about a micrometre.
      {EffectKind::HigherOrder, "higher_order", true, false, 100, nullptr,
       &Synthesiser::describe_higher_order},
      {EffectKind::MissingError, "missing_error", true, false, 1, nullptr,
       &Synthesiser::describe_missing_error},
      {EffectKind::ToolOffset, "tool_offset", true, false, 100, &Synthesiser::place_tool_offset,
       &Synthesiser::describe_tool_offset},
      {EffectKind::Setup, "setup", true, false, 10, nullptr, &Synthesiser::describe_setup},
      {EffectKind::Step, "step", false, false, 1, &Synthesiser::place_step,
       &Synthesiser::describe_step},
  };
  return table;
}

const Synthesiser::EffectDef& Synthesiser::effect_def(EffectKind kind) {
  for (const EffectDef& d : effect_table())
    if (d.kind == kind) return d;
  throw fail("no effect of that kind");
}

const Synthesiser::EffectDef* Synthesiser::find_effect(const std::string& name) {
  for (const EffectDef& d : effect_table())
    if (name == d.name) return &d;
  return nullptr;
}

const std::vector<std::string>& library_effects() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> names;
    for (const auto& d : Synthesiser::effect_table())
      if (d.library) names.push_back(d.name);
    return names;
  }();
  return v;
}

const std::vector<std::string>& all_effects() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> a = library_effects();
    for (const auto& d : Synthesiser::effect_table())
      if (!d.library) a.push_back(d.name);
    a.push_back("none");
    return a;
  }();
  return v;
}

// ---------------------------------------------------------------------------------------------
// Placement

namespace {

int pick_of(Rng& rng, const std::vector<int>& v) {
  return v[static_cast<std::size_t>(rng.index(static_cast<int>(v.size())))];
}

// The principal direction (x, y, z) of an error.
int direction_of(const Description& desc, int err) {
  const Vec3& d = desc.errors[static_cast<std::size_t>(err)].direction;
  return static_cast<int>(
      std::max_element(d.begin(), d.end(),
                       [](double x, double y) { return std::abs(x) < std::abs(y); }) -
      d.begin());
}

}  // namespace

void Synthesiser::build_effect(Effect& e, Rng& rng) {
  Placement at;
  at.linear = linear_axes();
  at.moving = at.linear;
  if (layout_.line()) at.moving = {line_axis_};
  if (layout_.ballbar()) at.moving = {plane_a_, plane_b_};
  if (layout_.rtest()) {
    at.moving.clear();
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (distinct_positions(static_cast<int>(k)) > 1) at.moving.push_back(static_cast<int>(k));
  }
  if (column_dim_[0] < 0) {
    at.measured_dims = {axes_[plane_a_].dim, axes_[plane_b_].dim};
  } else {
    for (int d : column_dim_) at.measured_dims.insert(d);
  }
  const EffectDef& def = effect_def(e.kind);
  if (def.place) (this->*def.place)(e, rng, at);
  if (e.error >= 0 && e.kind != EffectKind::MissingError)
    e.dim = direction_of(truth_desc_, e.error);
}

// A translation error of `axis` (line: its positioning error; a linear axis: along a measured
// direction; a rotary axis: radial or axial, which the R-test sees in every direction).
int Synthesiser::pick_error(int axis, Rng& rng, const Placement& at) const {
  if (layout_.line()) return positioning_error(axis);
  std::vector<int> cand;
  for (int i : translation_errors(axis))
    if (!axes_[axis].linear || at.measured_dims.count(direction_of(truth_desc_, i)))
      cand.push_back(i);
  if (cand.empty()) throw fail("axis " + axes_[axis].name + " has no measured translation error");
  return pick_of(rng, cand);
}

void Synthesiser::place_reversal(Effect& e, Rng& rng, const Placement& at) const {
  // On an R-test, a rotary axis or a linear one with equal odds.
  std::vector<int> cand = at.moving;
  if (layout_.rtest()) {
    std::vector<int> rot, lin;
    for (int k : at.moving) (axes_[k].linear ? lin : rot).push_back(k);
    cand = (rng.uniform() < 0.5 && !rot.empty()) || lin.empty() ? rot : lin;
  }
  e.axis = pick_of(rng, cand);
  e.error = positioning_error(e.axis);
}

void Synthesiser::place_shape(Effect& e, Rng& rng, const Placement& at) const {
  // A shape needs enough positions along its axis to be told from other shapes: on 7
  // positions a cubic PDGE leaves 3 shape degrees of freedom, which a period (amplitude,
  // phase, period) or a bump (height, centre, width) uses up, so no data could tell either
  // from a step there (docs/gap.md, "Verdict"). At least 9 positions; on an R-test the
  // turning axis (the linear axes follow the spheres, not a grid).
  std::vector<int> cand;
  for (int k : at.moving)
    if (distinct_positions(k) >= 9 && (!layout_.rtest() || !axes_[k].linear)) cand.push_back(k);
  if (cand.empty()) throw fail(e.name + ": no axis with 9 positions in layout " + spec_.layout);
  e.axis = pick_of(rng, cand);
  e.error = pick_error(e.axis, rng, at);
  const double step = axis_step(e.axis);
  const auto [lo, hi] = data_range(e.axis);
  if (e.kind == EffectKind::Periodic) {
    e.period = 4 * step;  // 4 samples per period: resolved by every layout
    e.phase = rng.uniform(0, 2 * kPi);
  } else {
    e.width = std::max(step, (hi - lo) / 25);
    e.centre = rng.uniform(lo + 0.3 * (hi - lo), hi - 0.3 * (hi - lo));
  }
}

void Synthesiser::place_thermal(Effect& e, Rng& rng, const Placement& at) const {
  // The tool point grows in the tool's frame (the spindle) or in the machine's (the column,
  // the ram), and every linear axis' positioning scale grows from its reference point.
  e.machine_frame = rng.uniform() < 0.5;
  e.offset.assign(3, 0.0);
  for (double& v : e.offset) v = rng.normal();
  e.scale.assign(axes_.size(), 0.0);
  for (int k : at.linear) e.scale[static_cast<std::size_t>(k)] = rng.normal();
}

void Synthesiser::place_step(Effect& e, Rng& rng, const Placement& at) const {
  e.step_in_time = rng.uniform() < 0.5;
  e.dim =
      *std::next(at.measured_dims.begin(), rng.index(static_cast<int>(at.measured_dims.size())));
  if (e.step_in_time) {
    e.step_at = std::round(rng.uniform(0.35, 0.65) * t_total_s_);
  } else {
    e.axis = pick_of(rng, at.moving);
    const auto [lo, hi] = data_range(e.axis);
    e.step_at = std::round(rng.uniform(lo + 0.35 * (hi - lo), lo + 0.65 * (hi - lo)));
  }
}

void Synthesiser::place_tool_offset(Effect&, Rng&, const Placement&) const {
  bool found = false;
  for (const Parameter& p : truth_desc_.parameters) found = found || p.name == "tool_length";
  if (!found) throw fail("tool_offset needs a parameter 'tool_length' in the machine");
}

// ---------------------------------------------------------------------------------------------
// Description (truth.json)

std::string Synthesiser::output_name(std::size_t column) const {
  return column_dim_[column] >= 0 ? std::string(kDimNames[column_dim_[column]]) : std::string("dr");
}

nlohmann::json Synthesiser::effect_json(const Effect& f) const {
  using nlohmann::json;
  json eff;
  eff["name"] = f.name;
  eff["observable"] = f.observable;
  eff["identifiable"] = f.identifiable;
  eff["expected"] = expected_of(f);
  eff["heldout_signal_rms_um"] = f.unabsorbed_rms;
  eff["raw_signal_rms_um"] = f.raw_rms;
  eff["visible_fraction"] = f.raw_rms > 0 ? f.unabsorbed_rms / f.raw_rms : 0.0;
  eff["snr"] = spec_.noise_um > 0 ? f.unabsorbed_rms / spec_.noise_um : 0.0;
  json by_out = json::object(), raw_out = json::object();
  for (std::size_t c = 0; c < f.unabsorbed_by_column.size(); ++c) {
    by_out[output_name(c)] = f.unabsorbed_by_column[c];
    raw_out[output_name(c)] = f.raw_by_column[c];
  }
  eff["heldout_signal_rms_by_output_um"] = by_out;
  eff["raw_signal_rms_by_output_um"] = raw_out;
  const std::size_t dominant = dominant_column(f);
  Labels names;
  names.output = output_name(dominant);
  names.axis = f.axis >= 0 ? axes_[static_cast<std::size_t>(f.axis)].name : std::string();
  names.error =
      f.error >= 0 ? truth_desc_.errors[static_cast<std::size_t>(f.error)].name : std::string();
  names.rotation = f.error >= 0 && truth_desc_.errors[static_cast<std::size_t>(f.error)].effect ==
                                       ErrorEffect::Rotation;
  names.axis_unit = f.axis >= 0 && !axes_[static_cast<std::size_t>(f.axis)].linear ? "deg" : "mm";
  json params = json::object();
  json loc = {{"kind", "output"}, {"by", json::array()}, {"output", names.output}};
  (this->*effect_def(f.kind).describe)(f, names, params, loc);
  eff["params"] = params;
  // Where the held-out signal is, along the primary coordinate: what a localisation is judged by.
  if (loc["kind"] == "interval" || loc["kind"] == "whole") {
    const std::string by = loc["by"][0].get<std::string>();
    int axis = -1;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      if (axes_[k].name == by) axis = static_cast<int>(k);
    loc["bins"] = signal_bins(f, axis, dominant);
  }
  eff["localise"] = loc;
  return eff;
}

void Synthesiser::describe_reversal(const Effect& f, const Labels& n, nlohmann::json& params,
                                    nlohmann::json& loc) const {
  params = {{"axis", n.axis},
            {"error", n.error},
            {n.rotation ? "backlash_urad" : "backlash_um", f.amplitude},
            {"model", "error += -backlash/2 * dir (approach direction of the axis)"}};
  loc = {{"kind", "direction"}, {"by", {"dir_" + n.axis, "dir"}}, {"output", n.output}};
}

void Synthesiser::describe_periodic(const Effect& f, const Labels& n, nlohmann::json& params,
                                    nlohmann::json& loc) const {
  params = {{"axis", n.axis},
            {"error", n.error},
            {"period_" + n.axis_unit, f.period},
            {n.rotation ? "amplitude_urad" : "amplitude_um", f.amplitude},
            {"phase_rad", f.phase}};
  const auto [lo, hi] = data_range(f.axis);
  loc = {{"kind", "whole"}, {"by", {n.axis}}, {"output", n.output}, {"from", lo}, {"to", hi}};
}

void Synthesiser::describe_pdge_shape(const Effect& f, const Labels& n, nlohmann::json& params,
                                      nlohmann::json& loc) const {
  params = {{"axis", n.axis},
            {"error", n.error},
            {"centre_" + n.axis_unit, f.centre},
            {"width_" + n.axis_unit, f.width},
            {n.rotation ? "amplitude_urad" : "amplitude_um", f.amplitude},
            {"shape", "a exp(-(q-c)^2/(2 w^2))"}};
  const auto [lo, hi] = data_range(f.axis);
  loc = {{"kind", "interval"},
         {"by", {n.axis}},
         {"output", n.output},
         {"from", std::max(lo, f.centre - 2 * f.width)},
         {"to", std::min(hi, f.centre + 2 * f.width)},
         {"at", f.centre}};
}

void Synthesiser::describe_thermal(const Effect& f, const Labels& n, nlohmann::json& params,
                                   nlohmann::json& loc) const {
  using nlohmann::json;
  const double dmax = *std::max_element(drift_table_.begin(), drift_table_.end());
  json scale = json::object();
  for (std::size_t a = 0; a < axes_.size(); ++a)
    if (axes_[a].linear && axes_[a].max > axes_[a].min)
      scale[axes_[a].name] =
          1000 * f.amplitude * f.scale[a] / (dmax * (axes_[a].max - axes_[a].min) / 2);
  json offset = json::object();
  for (int d = 0; d < 3; ++d)
    offset[std::string(1, "xyz"[d])] = f.amplitude * f.offset[static_cast<std::size_t>(d)] / dmax;
  params = {{"temperature", "T_spindle"},
            {"frame", f.machine_frame ? "machine" : "tool"},
            {"model",
             "the tool point moves by D(t) offset (in the frame), each linear axis by D(t) "
             "scale (q - home); D: first-order lag of T_spindle - 22 degC"},
            {"tau_lag_s", t_total_s_ / 12},
            {"drift_max_K", dmax},
            {"offset_um_per_K", offset},
            {"scale_um_per_m_per_K", scale}};
  // Where the lagged rise is at least half its peak.
  double from = t_total_s_, to = 0, at = 0, best = -1;
  for (std::size_t i = 0; i < drift_table_.size(); ++i) {
    const double t = t_total_s_ * i / (drift_table_.size() - 1);
    if (drift_table_[i] >= 0.5 * dmax) {
      from = std::min(from, t);
      to = std::max(to, t);
    }
    if (drift_table_[i] > best) {
      best = drift_table_[i];
      at = t;
    }
  }
  loc = {{"kind", "interval"}, {"by", {"t_s", "T_spindle", "cycle"}},
         {"output", n.output}, {"from", from},
         {"to", to},           {"at", at}};
}

void Synthesiser::describe_step(const Effect& f, const Labels& n, nlohmann::json& params,
                                nlohmann::json& loc) const {
  using nlohmann::json;
  const std::string coord = f.step_in_time ? "t_s" : n.axis;
  double hi = t_total_s_;
  if (!f.step_in_time) hi = data_range(f.axis).second;
  params = {{"kind", f.step_in_time ? "time" : "position"},
            {"coordinate", coord},
            {"at", f.step_at},
            {"output", kDimNames[f.dim]},
            {"step_um", f.amplitude}};
  json by = json::array({coord});
  if (f.step_in_time) by.push_back("cycle");
  loc = {{"kind", "interval"}, {"by", by}, {"output", n.output},
         {"from", f.step_at},  {"to", hi}, {"at", f.step_at}};
}

void Synthesiser::describe_higher_order(const Effect& f, const Labels&, nlohmann::json& params,
                                        nlohmann::json&) const {
  params = {{"error_scale", f.amplitude},
            {"model_order", model_desc_.algebra.order},
            {"how",
             "every truth error multiplied by error_scale; the exact chain minus its "
             "first-order part is the effect"}};
}

void Synthesiser::describe_missing_error(const Effect& f, const Labels&, nlohmann::json& params,
                                         nlohmann::json&) const {
  params = {{"error", spec_.missing_error},
            {"unit", truth_desc_.errors[static_cast<std::size_t>(f.error)].unit},
            {"scale_of_drawn", f.amplitude},
            {"model_machine", model_machine_}};
}

void Synthesiser::describe_tool_offset(const Effect& f, const Labels&, nlohmann::json& params,
                                       nlohmann::json&) const {
  double model_len = 0;
  for (std::size_t i = 0; i < model_desc_.parameters.size(); ++i)
    if (model_desc_.parameters[i].name == "tool_length") model_len = model_params_[i];
  params = {{"tool_length_model_mm", model_len},
            {"tool_length_truth_mm", model_len + f.amplitude},
            {"offset_mm", f.amplitude}};
}

void Synthesiser::describe_setup(const Effect& f, const Labels&, nlohmann::json& params,
                                 nlohmann::json&) const {
  params = {{"scale_ppm", -f.amplitude},
            {"cosine_angle_mrad", 1e3 * std::acos(1 - f.amplitude * 1e-6)},
            {"model", "reading = (1 - k) x displacement from the instrument zero (first pose)"}};
}

}  // namespace weilgen::gapbench
