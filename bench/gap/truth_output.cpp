// The generator's files: the measurement CSV (docs/data-format.md) and truth.json with each
// effect's held-out signal binned where it lies.
#include <algorithm>
#include <cmath>
#include <set>

#include "truth.hpp"

namespace weilgen::gapbench {

// The held-out signal of one effect in one measured column binned along a coordinate (an axis,
// or time when axis < 0): one bin per distinct position when there are at most 25, else 20
// equal bins. Each bin gives its data range, size and RMS; bins with at least half the largest
// RMS are "hot".
nlohmann::json Synthesiser::signal_bins(const Effect& e, int axis, std::size_t column) const {
  std::vector<std::pair<double, double>> v;  // coordinate, residual
  for (std::size_t o = 0; o < obs_row_.size(); ++o) {
    if (static_cast<std::size_t>(obs_col_[o]) != column) continue;
    const Row& row = rows_[static_cast<std::size_t>(obs_row_[o])];
    v.emplace_back(axis < 0 ? row.t_s : row.axes[static_cast<std::size_t>(axis)],
                   e.residual[static_cast<Eigen::Index>(o)]);
  }
  std::sort(v.begin(), v.end());
  std::vector<double> distinct;
  for (const auto& p : v)
    if (distinct.empty() || p.first > distinct.back() + 1e-9) distinct.push_back(p.first);
  const bool per_value = distinct.size() <= 25;
  const double lo = v.front().first, hi = v.back().first;
  struct Bin {
    double from = INFINITY, to = -INFINITY, ss = 0;
    std::size_t n = 0;
  };
  std::vector<Bin> bins(per_value ? distinct.size() : 20);
  std::size_t d = 0;
  for (const auto& [x, r] : v) {
    std::size_t b = 0;
    if (per_value) {
      while (x > distinct[d] + 1e-9) ++d;
      b = d;
    } else {
      b = std::min<std::size_t>(19, static_cast<std::size_t>(20 * (x - lo) / (hi - lo)));
    }
    bins[b].from = std::min(bins[b].from, x);
    bins[b].to = std::max(bins[b].to, x);
    bins[b].ss += r * r;
    ++bins[b].n;
  }
  double peak = 0;
  for (const Bin& b : bins)
    if (b.n) peak = std::max(peak, std::sqrt(b.ss / static_cast<double>(b.n)));
  nlohmann::json out = nlohmann::json::array();
  for (const Bin& b : bins) {
    if (!b.n) continue;
    const double r = std::sqrt(b.ss / static_cast<double>(b.n));
    out.push_back(
        {{"from", b.from}, {"to", b.to}, {"n", b.n}, {"rms_um", r}, {"hot", r >= 0.5 * peak}});
  }
  return out;
}

std::string Synthesiser::expected_of(const Effect& e) const {
  if (!e.identifiable) return "none";
  return e.kind == EffectKind::Step ? "unexplained" : e.name;
}

std::size_t Synthesiser::dominant_column(const Effect& e) const {
  const auto& v = e.identifiable ? e.unabsorbed_by_column : e.raw_by_column;
  return static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

// ---------------------------------------------------------------------------------------------
// Output

std::vector<std::string> Synthesiser::comment_lines() const {
  std::vector<std::string> head_lines;
  head_lines.push_back(
      "# Synthetic measurement written by weilgen_gap_synth (bench/gap/README.md)");
  head_lines.push_back("# machine: " + model_desc_.name);
  head_lines.push_back("# layout: " + spec_.layout);
  const bool ballbar = column_dim_[0] < 0;
  if (layout_.line()) {
    head_lines.push_back("# instrument: synthetic laser interferometer");
    head_lines.push_back("# axis: " + axes_[static_cast<std::size_t>(line_axis_)].name);
  } else if (ballbar) {
    head_lines.push_back("# instrument: synthetic ballbar");
    head_lines.push_back("# plane: " + axes_[static_cast<std::size_t>(plane_a_)].name +
                         axes_[static_cast<std::size_t>(plane_b_)].name);
    std::string centre;
    for (std::size_t k = 0; k < axes_.size(); ++k)
      centre += (k ? ", " : "") + axes_[k].name + "=" + fmt("%.10g", centre_[k]);
    head_lines.push_back("# centre: " + centre);
    head_lines.push_back("# radius: " + fmt("%.10g", radius_mm_) + " mm");
    head_lines.push_back("# feed: ccw");
  } else if (layout_.rtest()) {
    head_lines.push_back("# instrument: synthetic R-test (sphere centre relative to the tool)");
  } else {
    head_lines.push_back("# instrument: synthetic laser tracker");
  }
  return head_lines;
}

std::string Synthesiser::csv(bool with_effect, bool with_noise, bool with_gross) const {
  std::vector<double> v = measured(with_effect);
  if (with_noise) {
    for (std::size_t i = 0; i < v.size(); ++i) v[i] += noise_um_[i];
    if (with_gross)
      for (const GrossReading& g : gross_) v[g.observation] += g.size_um;
  }
  const std::vector<std::string> head_lines = comment_lines();
  const bool ballbar = column_dim_[0] < 0;
  std::vector<std::string> head;
  for (const AxisInfo& a : axes_) head.push_back(a.name);
  head.push_back("t_s");
  if (layout_.line()) {
    head.push_back("dir");
  } else if (ballbar) {
    head.push_back("dir");
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_a_)].name);
    head.push_back("dir_" + axes_[static_cast<std::size_t>(plane_b_)].name);
  } else {
    for (const AxisInfo& a : axes_) head.push_back("dir_" + a.name);
  }
  head.push_back("cycle");
  head.push_back("T_spindle");
  if (ballbar) head.push_back("angle_deg");
  for (const std::string& c : columns_) head.push_back(c);
  std::string s;
  for (const std::string& l : head_lines) s += l + "\n";
  for (std::size_t i = 0; i < head.size(); ++i) s += (i ? "," : "") + head[i];
  s += "\n";
  const std::size_t nc = columns_.size();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Row& row = rows_[r];
    std::string line;
    for (double a : row.axes) line += fmt("%.10g", a) + ",";
    line += fmt("%.2f", row.t_s) + ",";
    if (layout_.line()) {
      line += std::to_string(row.feed_dir) + ",";
    } else if (ballbar) {
      line += std::to_string(row.feed_dir) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_a_)]) + "," +
              std::to_string(row.dir[static_cast<std::size_t>(plane_b_)]) + ",";
    } else {
      for (int d : row.dir) line += std::to_string(d) + ",";
    }
    line += std::to_string(row.cycle) + ",";
    line += fmt("%.4f", temperature(row.t_s) + temp_noise_[r]);
    if (ballbar) line += "," + fmt("%.10g", row.angle_deg);
    for (std::size_t c = 0; c < nc; ++c) line += "," + fmt("%.6f", v[r * nc + c]);
    s += line + "\n";
  }
  return s;
}

nlohmann::json Synthesiser::truth() const {
  using nlohmann::json;
  json j;
  j["generator"] = "weilgen_gap_synth";
  j["format"] = 2;
  j["scenario"] = {{"machine", truth_desc_.name},
                   {"model_machine", model_machine_},
                   {"effect", spec_.effect},
                   {"factor", spec_.factor},
                   {"noise_sigma_um", spec_.noise_um},
                   {"layout", spec_.layout},
                   {"seed", spec_.seed},
                   {"truth_degree", spec_.truth_degree},
                   {"fit_degree", spec_.fit_degree},
                   {"rotary_harmonics", spec_.rotary_harmonics},
                   {"outliers", spec_.outliers},
                   {"heteroscedastic", spec_.heteroscedastic}};
  // The verdict expected: every identifiable library effect named; a step makes it unexplained.
  std::vector<std::string> expected;
  bool step = false;
  for (const Effect& f : effects_) {
    const std::string e = expected_of(f);
    if (e == "unexplained") step = true;
    if (e != "none" && e != "unexplained") expected.push_back(e);
  }
  std::string verdict = step ? "unexplained" : expected.empty() ? "none" : expected[0];
  if (!step)
    for (std::size_t k = 1; k < expected.size(); ++k) verdict += "+" + expected[k];
  j["expected_verdict"] = verdict;
  j["expected_effects"] = step ? json::array() : json(expected);
  j["noise_sigma_um"] = spec_.noise_um;
  j["noise_rms_um"] = noise_rms_um_;
  j["noise_sigma_range_um"] = {*std::min_element(sigma_.begin(), sigma_.end()),
                               *std::max_element(sigma_.begin(), sigma_.end())};
  j["rows"] = rows_.size();
  j["observations"] = obs_row_.size();
  j["duration_s"] = t_total_s_;
  j["measured_columns"] = columns_;
  j["model_regressors"] = {{"columns", regressors_.cols()},
                           {"rank", span_.basis.cols()},
                           {"smallest_kept_singular_value", span_.smallest_kept},
                           {"largest_dropped_singular_value", span_.largest_dropped}};
  if (!spheres_.empty()) j["rtest_spheres_mm"] = spheres_;
  json effs = json::array();
  for (const Effect& f : effects_) effs.push_back(effect_json(f));
  j["effects"] = effs;
  // The first effect as `effect` (format 1 readers), or an empty one.
  if (!effects_.empty()) {
    j["effect"] = effs[0];
    j["localise"] = effs[0]["localise"];
  } else {
    j["effect"] = {{"name", "none"},
                   {"observable", true},
                   {"identifiable", true},
                   {"heldout_signal_rms_um", 0},
                   {"raw_signal_rms_um", 0},
                   {"visible_fraction", 0},
                   {"snr", 0}};
    j["localise"] = {{"kind", "none"}, {"by", json::array()}};
  }
  json gross = json::array();
  for (const GrossReading& g : gross_) {
    const std::size_t row = static_cast<std::size_t>(obs_row_[g.observation]);
    gross.push_back({{"observation", g.observation},
                     {"line", comment_lines().size() + 1 + row + 1},
                     {"output", columns_[static_cast<std::size_t>(obs_col_[g.observation])]},
                     {"size_um", g.size_um}});
  }
  j["gross_readings"] = gross;

  json errs = json::array();
  for (std::size_t i = 0; i < truth_desc_.errors.size(); ++i) {
    const ErrorDef& e = truth_desc_.errors[i];
    const TruthError& t = errors_[i];
    double scale = 1;
    for (const Effect& f : effects_) {
      if (f.kind == EffectKind::HigherOrder) scale = f.amplitude;
      if (f.kind == EffectKind::MissingError && static_cast<int>(i) == f.error) scale = f.amplitude;
    }
    json c = json::array();
    for (double v : t.coeff) c.push_back(v * scale);
    json je = {{"name", e.name}, {"unit", e.unit}, {"to_base", e.to_base}};
    if (t.axis >= 0) {
      const AxisInfo& a = axes_[static_cast<std::size_t>(t.axis)];
      je["dependence"] = "PDGE";
      je["axis"] = a.name;
      je["travel"] = {a.min, a.max};
      if (t.harmonics > 0)
        je["fourier"] = c;  // 1, cos θ, sin θ, cos 2θ … with θ = 2π q / 360 (q in deg)
      else
        je["legendre"] = c;
    } else {
      je["dependence"] = "PIGE";
      je["value"] = c[0];
    }
    errs.push_back(je);
  }
  j["truth_errors"] = errs;
  json tp = json::object();
  for (std::size_t i = 0; i < truth_desc_.parameters.size(); ++i) {
    double v = truth_params_[i];
    for (const Effect& f : effects_)
      if (f.kind == EffectKind::ToolOffset && truth_desc_.parameters[i].name == "tool_length")
        v += f.amplitude;
    tp[truth_desc_.parameters[i].name] = v;
  }
  j["truth_parameters"] = tp;
  return j;
}

}  // namespace weilgen::gapbench
