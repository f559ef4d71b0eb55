#include "weilgen/report/iso230_2_document.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <utility>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"
#include "weilgen/base/version.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

using nlohmann::json;

// The axis figures and per-target arrays of one evaluation (keys end in _um: the deviation
// column's unit, um for a linear axis).
json figures_json(const IsoFigures& f) {
  return {{"k_up", f.k_up},
          {"k_down", f.k_down},
          {"mean_up_um", json_numbers(f.mean_up)},
          {"mean_down_um", json_numbers(f.mean_down)},
          {"mean_bi_um", json_numbers(f.mean_bi)},
          {"s_up_um", json_numbers(f.s_up)},
          {"s_down_um", json_numbers(f.s_down)},
          {"B_i_um", json_numbers(f.B_i)},
          {"R_i_up_um", json_numbers(f.R_i_up)},
          {"R_i_down_um", json_numbers(f.R_i_down)},
          {"R_i_um", json_numbers(f.R_i)},
          {"B_um", json_number(f.B)},
          {"B_mean_um", json_number(f.B_mean)},
          {"R_up_um", json_number(f.R_up)},
          {"R_down_um", json_number(f.R_down)},
          {"R_um", json_number(f.R)},
          {"E_up_um", json_number(f.E_up)},
          {"E_down_um", json_number(f.E_down)},
          {"E_um", json_number(f.E)},
          {"M_um", json_number(f.M)},
          {"A_up_um", json_number(f.A_up)},
          {"A_down_um", json_number(f.A_down)},
          {"A_um", json_number(f.A)}};
}

json differences_json(const AdjacentDifferences& D, const std::vector<double>& pos) {
  json from = json::array(), to = json::array(), flagged = json::array(), pool = json::array();
  for (std::size_t q = 0; q < D.mean.size(); ++q) {
    from.push_back(pos[q]);
    to.push_back(pos[q + 1]);
    flagged.push_back(static_cast<bool>(D.flagged[q]));
    pool.push_back(D.pool[q]);
  }
  return {{"from_mm", from},
          {"to_mm", to},
          {"mean_um", json_numbers(D.mean)},
          {"s_um", json_numbers(D.s)},
          {"sem_um", json_numbers(D.sem)},
          {"F", json_numbers(D.F)},
          {"p_value", json_numbers(D.p_value)},
          {"pool", pool},
          {"flagged", flagged}};
}

// Table cells: fixed decimals (3 unless said), "-" when not computed.

std::string dir_label(int d) { return d > 0 ? "+1" : "-1"; }

// Lines of every cycle of one direction (only the first labelled), for a LinePlot.
void add_cycles(LinePlot& p, const std::vector<std::vector<double>>& x, const std::string& label) {
  const std::size_t n = x.empty() ? 0 : x[0].size();
  for (std::size_t j = 0; j < n; ++j) {
    std::vector<double> y;
    for (const auto& row : x) y.push_back(row[j]);
    p.lines.emplace_back(j == 0 ? label : std::string(), y);
  }
}

// The mean as a line and mean ± k s as a shaded band under it.
void add_band(LinePlot& p, const std::vector<double>& mean, const std::vector<double>& s, double k,
              const std::string& label, const std::string& s_name = "s") {
  LineBand band{label + " +-" + format_number(k) + s_name, {}, {}, p.lines.size()};
  for (std::size_t i = 0; i < mean.size(); ++i)
    band.lo.push_back(mean[i] - k * s[i]), band.hi.push_back(mean[i] + k * s[i]);
  p.bands.push_back(band);
  p.lines.emplace_back(label, mean);
}

// The +-T lines of a band tolerance.
void add_tolerance_rules(LinePlot& p, const std::vector<ToleranceCheck>& checks,
                         const std::string& unit) {
  for (const ToleranceCheck& c : checks)
    if (c.name == "band") {
      p.rules.push_back({"tolerance +-" + format_number(c.limit) + " " + unit, c.limit});
      p.rules.push_back({"", -c.limit});
    }
}

std::string range_text(const ValueRange& r, int decimals, const std::string& unit) {
  if (r.empty()) return "-";
  if (r.max - r.min < 0.5 * std::pow(10.0, -decimals))
    return format_fixed(r.mean, decimals) + " " + unit;
  return format_fixed(r.min, decimals) + " .. " + format_fixed(r.max, decimals) + " " + unit +
         " (mean " + format_fixed(r.mean, decimals) + ")";
}

std::string with_source(const std::string& text, const std::string& source) {
  return source.empty() ? text : text + " [" + source + "]";
}

json range_json(const ValueRange& r) {
  if (r.empty()) return json();
  return {{"min", json_number(r.min)}, {"mean", json_number(r.mean)}, {"max", json_number(r.max)}};
}

json uncertainty_json(const UncertaintyResult& U) {
  json figures = json::object();
  for (const FigureUncertainty& f : U.figures)
    figures[f.name] = {{"value_um", json_number(f.value)},
                       {"u_um", json_number(f.u)},
                       {"U_um", json_number(f.U)},
                       {"monte_carlo",
                        {{"u_um", json_number(f.mc_u)},
                         {"low_um", json_number(f.mc_low)},
                         {"high_um", json_number(f.mc_high)},
                         {"validated", f.validated}}}};
  json contributions = json::array();
  for (const UncertaintyContribution& c : U.contributions) {
    json sens = json::object(), part = json::object(), share = json::object();
    for (const FigureUncertainty& f : U.figures) {
      sens[f.name] = json_number(c.sensitivity.at(f.name));
      const double p = c.contribution_um.at(f.name);
      part[f.name] = json_number(p);
      share[f.name] = json_number(f.u > 0 ? 100 * p * p / (f.u * f.u) : NAN);
    }
    contributions.push_back(
        {{"name", c.name},
         {"input", c.input},
         {"distribution", c.kind == ContributionKind::TypeA ? "type A" : to_string(c.distribution)},
         {"kind", to_string(c.kind)},
         {"u", json_number(c.u)},
         {"unit", c.unit},
         {"sensitivity", sens},
         {"contribution_um", part},
         {"share_pct", share}});
  }
  return {{"method", "ISO 230-9 / GUM (JCGM 100:2008), Monte Carlo after GUM Supplement 1"},
          {"class", U.instrument_class},
          {"source", U.source},
          {"coverage_factor", U.coverage_factor},
          {"figures", figures},
          {"contributions", contributions},
          {"monte_carlo", {{"trials", U.trials}, {"seed", U.seed}, {"coverage", 0.95}}},
          {"notes", U.notes}};
}

std::string air_readings(const NormalisationResult& n) {
  std::vector<std::string> parts;
  if (!n.air_temperature_C.empty())
    parts.push_back(
        with_source(range_text(n.air_temperature_C, 2, "degC"), n.air_temperature_source));
  if (!n.air_pressure_Pa.empty())
    parts.push_back(with_source(range_text(n.air_pressure_Pa, 0, "Pa"), n.air_pressure_source));
  if (!n.air_humidity_pct.empty())
    parts.push_back(with_source(range_text(n.air_humidity_pct, 1, "%RH"), n.air_humidity_source));
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? ", " : "") + parts[i];
  return out;
}

}  // namespace

std::vector<std::string> iso230_2_normalisation_statement(const Iso230_2StudyResult& res) {
  const NormalisationResult& n = res.normalisation;
  const std::string datum = res.columns.axis + " = " + format_number(n.datum_mm) + " mm";
  std::vector<std::string> out;
  const std::string tm =
      n.material_temperature_C.empty()
          ? std::string("no material temperature recorded")
          : "material temperature " +
                with_source(range_text(n.material_temperature_C, 2, "degC"), n.material_source);
  if (n.material_applied) {
    out.push_back("Normalised to " + format_number(n.reference_temperature_C) +
                  " degC by weilgen (ISO 1; --normalise " + to_string(n.mode) +
                  "): " + n.material_decision + "; " + tm +
                  "; correction -alpha (T - 20 degC) L, L the travel from the datum " + datum +
                  ": " + range_text(n.material_correction_um, 3, "um") + ".");
  } else if (n.material_compensation == "instrument") {
    out.push_back("Normalised to 20 degC by the instrument, not by weilgen (--normalise " +
                  std::string(to_string(n.mode)) + "): " + n.material_decision + "; " + tm + ".");
  } else {
    out.push_back("Not normalised to 20 degC (--normalise " + std::string(to_string(n.mode)) +
                  "): " + n.material_decision + "; " + tm + ".");
  }
  const std::string air = air_readings(n);
  const std::string recorded = air.empty() ? std::string(".") : "; air as recorded: " + air + ".";
  if (n.air_applied) {
    out.push_back(
        "Air refraction corrected by weilgen with the modified Edlen equation of "
        "Birch & Downs (1993, corrected 1994) (" +
        n.air_decision + "), vacuum wavelength " + format_number(n.wavelength_nm) + " nm, air " +
        air + ": n - 1 = " + format_significant(n.air_refractivity.min, 6) + " .. " +
        format_significant(n.air_refractivity.max, 6) + "; readings counted with n0 = " +
        format_number(n.assumed_index) + "; correction L (n0/n - 1) from the datum " + datum +
        ": " + range_text(n.air_correction_um, 3, "um") + ".");
    return out;
  }
  switch (n.air) {
    case AirCompensation::Instrument:
      out.push_back("Air refraction compensated by the instrument: " + n.air_decision + recorded);
      break;
    case AirCompensation::None:
    case AirCompensation::Edlen:
      out.push_back(
          "Air refraction NOT compensated (" + n.air_decision +
          "): the deviations include the refractive index of the air (about 271 um per metre of "
          "travel at 20 degC, 101325 Pa, 50 %RH); --air-compensation edlen corrects them from "
          "the air's temperature, pressure and humidity" +
          recorded);
      break;
    case AirCompensation::Unstated:
      out.push_back(
          "Air refraction: " + n.air_decision +
          "; weilgen corrected nothing (--air-compensation instrument|edlen|none or the header "
          "key air_compensation states it)" +
          recorded);
      break;
  }
  return out;
}

std::vector<std::string> iso230_2_tolerance_statement(const Iso230_2StudyResult& res) {
  std::vector<std::string> out;
  if (res.tolerance.empty()) return out;
  const std::string u = res.columns.unit;
  std::vector<std::string> failed;
  bool with_u = false;
  for (const ToleranceCheck& c : res.tolerance) {
    std::ostringstream l;
    l << "  " << std::left << std::setw(8) << (c.name == "band" ? std::string("|x +- 2s|") : c.name)
      << std::right << std::setw(10) << format_fixed(c.value, 3) << " " << u;
    if (std::isfinite(c.U)) {
      with_u = true;
      l << " +- " << std::setw(6) << format_fixed(c.U, 3) << " (U)";
    }
    l << (c.pass ? " <= " : " >  ") << std::setw(8) << format_number(c.limit) << " " << u << "  "
      << (c.decision == Decision::Conforms         ? "pass"
          : c.decision == Decision::DoesNotConform ? "FAIL"
                                                   : "not proven");
    out.push_back(l.str());
    if (c.decision == Decision::DoesNotConform) failed.push_back(c.name);
  }
  out.push_back(with_u ? "  decided on the classical ISO 230-2 figures (k = 2) with their "
                         "expanded uncertainty U (ISO 14253-1)"
                       : "  decided on the classical ISO 230-2 figures (k = 2) without their "
                         "uncertainty (--uncertainty gives it)");
  switch (res.verdict) {
    case Decision::Conforms:
      out.push_back("  verdict: PASS");
      break;
    case Decision::DoesNotConform:
      out.push_back("  verdict: FAIL (" + join(failed) + " out of tolerance)");
      break;
    case Decision::NotProven:
      out.push_back("  verdict: NOT PROVEN (" + res.verdict_reason + ")");
      break;
  }
  return out;
}

const std::vector<std::string>& iso230_2_budget_figures() {
  static const std::vector<std::string> f = {"E", "M", "A", "B", "R"};
  return f;
}

std::vector<std::string> iso230_2_uncertainty_text(const Iso230_2StudyResult& res) {
  std::vector<std::string> out;
  if (!res.uncertainty) return out;
  const UncertaintyResult& U = *res.uncertainty;
  const std::string u = res.columns.unit;
  std::vector<std::string> shown = iso230_2_budget_figures();
  for (const ToleranceCheck& c : res.tolerance)
    if (std::find(shown.begin(), shown.end(), c.name) == shown.end()) shown.push_back(c.name);
  {
    std::ostringstream l;
    l << std::left << std::setw(10) << "  figure" << std::right << std::setw(10) << "value"
      << std::setw(10) << "u" << std::setw(10) << "U" << std::setw(16) << "Monte Carlo u"
      << "   95 % interval (" << U.trials << " trials)";
    out.push_back(l.str());
  }
  for (const std::string& name : shown) {
    const FigureUncertainty* f = U.figure(name);
    if (!f) continue;
    std::ostringstream l;
    l << "  " << std::left << std::setw(8) << name << std::right << std::setw(10)
      << format_fixed(f->value, 3) << std::setw(10) << format_fixed(f->u, 3) << std::setw(10)
      << format_fixed(f->U, 3) << std::setw(16) << format_fixed(f->mc_u, 3) << "   "
      << (std::isfinite(f->mc_low)
              ? format_fixed(f->mc_low, 3) + " .. " + format_fixed(f->mc_high, 3) + " " + u
              : std::string("-"))
      << (U.trials > 0 && !f->validated ? "  (*)" : "");
    out.push_back(l.str());
  }
  bool unvalidated = false;
  for (const std::string& name : shown)
    if (const FigureUncertainty* f = U.figure(name)) unvalidated |= U.trials > 0 && !f->validated;
  if (unvalidated)
    out.push_back(
        "  (*) the Monte Carlo u differs from the linearised u by more than 5 % (GUM Supplement "
        "1, 8): an extreme of the figure switches between targets within the uncertainty, and "
        "the Monte Carlo interval describes it better; the verdicts use U.");
  for (const std::string& name : iso230_2_budget_figures()) {
    const FigureUncertainty* f = U.figure(name);
    out.push_back("");
    out.push_back("  Budget of " + name + " = " + format_fixed(f->value, 3) + " " + u +
                  ": u = " + format_fixed(f->u, 3) + " " + u + ", U = " + format_fixed(f->U, 3) +
                  " " + u + " (k = " + format_number(U.coverage_factor) + ")");
    std::ostringstream h;
    h << "    " << std::left << std::setw(36) << "contribution" << std::setw(22) << "distribution"
      << std::right << std::setw(14) << "u(x)" << std::setw(12) << "c" << std::setw(10) << "|c| u"
      << std::setw(9) << "share";
    out.push_back(h.str());
    for (const UncertaintyContribution& c : U.contributions) {
      const double part = c.contribution_um.at(name);
      std::ostringstream l;
      l << "    " << std::left << std::setw(36) << c.name << std::setw(22)
        << (c.kind == ContributionKind::TypeA ? std::string("type A")
                                              : std::string(to_string(c.distribution)))
        << std::right << std::setw(14)
        << (std::isfinite(c.u) ? format_significant(c.u, 3) + " " + c.unit : std::string("-"))
        << std::setw(12)
        << (std::isfinite(c.sensitivity.at(name))
                ? format_significant(c.sensitivity.at(name), 3) +
                      (c.kind == ContributionKind::Scale ? " m" : "")
                : std::string("-"))
        << std::setw(10) << format_fixed(part, 3) << std::setw(8)
        << (f->u > 0 ? format_fixed(100 * part * part / (f->u * f->u), 1) : std::string("-"))
        << "%";
      out.push_back(l.str());
    }
  }
  for (const std::string& note : U.notes) out.push_back("  note: " + note);
  return out;
}

std::vector<std::string> iso230_2_conformance_statement(const Iso230_2StudyResult& res) {
  if (res.conformance.empty())
    return {
        "The run meets the test conditions of ISO 230-2:2014 that weilgen checks (targets, "
        "5 bidirectional cycles, air compensated, temperature corrected or stated)."};
  std::vector<std::string> out = {
      "NOT to ISO 230-2:2014: the figures are evaluated after the standard, but the run does not "
      "meet its test conditions:"};
  for (const ConformanceIssue& i : res.conformance)
    out.push_back("- " + i.check + ": " + i.message);
  return out;
}

namespace {

// The axis figures of each evaluation side by side: classical, with the Student-t factor,
// drift-eliminated and both (only the classical with --iso-only).
void text_axis_figures(std::ostream& o, const Iso230_2StudyResult& res) {
  const Iso230_2Result& cr = res.classical;
  const std::optional<DriftResult>& drift = res.drift;
  const std::string& u = res.columns.unit;
  const IsoFigures& F = cr.figures;
  struct Row {
    const char* name;
    const char* what;
    double IsoFigures::*field;
  };
  const Row rows[] = {{"B", "reversal value", &IsoFigures::B},
                      {"B mean", "mean reversal value", &IsoFigures::B_mean},
                      {"R up", "unidirectional repeatability +", &IsoFigures::R_up},
                      {"R down", "unidirectional repeatability -", &IsoFigures::R_down},
                      {"R", "bidirectional repeatability", &IsoFigures::R},
                      {"E up", "unidirectional systematic deviation +", &IsoFigures::E_up},
                      {"E down", "unidirectional systematic deviation -", &IsoFigures::E_down},
                      {"E", "bidirectional systematic deviation", &IsoFigures::E},
                      {"M", "range of mean bidirectional deviation", &IsoFigures::M},
                      {"A up", "unidirectional accuracy +", &IsoFigures::A_up},
                      {"A down", "unidirectional accuracy -", &IsoFigures::A_down},
                      {"A", "bidirectional accuracy", &IsoFigures::A}};
  std::vector<const IsoFigures*> sets = {&F, cr.student ? &*cr.student : nullptr,
                                         drift ? &drift->figures : nullptr,
                                         drift && drift->student ? &*drift->student : nullptr};
  std::vector<std::string> names = {"classical", "Student-t", "drift-elim.", "drift+t"};
  if (res.iso_only) sets.resize(1), names.resize(1);  // only what ISO 230-2 defines
  o << "\n" << std::left << std::setw(46) << "Axis figures (" + u + ")" << std::right;
  for (const std::string& name : names) o << std::setw(12) << name;
  o << "\n";
  for (const Row& r : rows) {
    o << "  " << std::left << std::setw(7) << r.name << std::setw(37) << r.what << std::right;
    for (const IsoFigures* s : sets)
      o << std::setw(12) << (s ? format_fixed(s->*(r.field), 3) : "-");
    o << "\n";
  }
  o << std::left << std::setw(46) << "  coverage factor k (up/down)" << std::right;
  for (const IsoFigures* s : sets)
    o << std::setw(12)
      << (s ? format_fixed(s->k_up, 2) + "/" + format_fixed(s->k_down, 2) : std::string("-"));
  o << "\n";
}

// The drift elimination's differences, chart, anomaly test and drift per cycle.
void text_drift_elimination(std::ostream& o, const Iso230_2StudyResult& res) {
  const IsoColumns& cols = res.columns;
  const std::optional<DriftResult>& drift = res.drift;
  const std::size_t m = res.runs.targets();
  const std::string& u = cols.unit;
  const auto& P = res.runs.positions_mm;
  if (drift) {
    const DriftResult& D = *drift;
    o << "\nDrift elimination (Stejskal et al. 2017): reference " << cols.axis << "="
      << format_number(P[D.reference_target]) << " mm, cycle " << D.reference_cycle << "\n";
    o << std::setw(20) << "between mm" << std::setw(10) << "diff up" << std::setw(9) << "s up"
      << std::setw(10) << "p up" << std::setw(10) << "diff dn" << std::setw(9) << "s dn"
      << std::setw(10) << "p dn"
      << "\n";
    for (std::size_t q = 0; q + 1 < m; ++q) {
      auto pv = [&](int d) {
        const auto& A = D.differences[d];
        std::ostringstream s;
        if (std::isfinite(A.p_value[q]))
          s << std::setprecision(2) << A.p_value[q] << (A.flagged[q] ? "*" : "");
        else
          s << "-";
        return s.str();
      };
      o << std::setw(20) << (format_number(P[q]) + ".." + format_number(P[q + 1])) << std::setw(10)
        << format_fixed(D.differences[kUp].mean[q], 3) << std::setw(9)
        << format_fixed(D.differences[kUp].s[q], 3) << std::setw(10) << pv(kUp) << std::setw(10)
        << format_fixed(D.differences[kDown].mean[q], 3) << std::setw(9)
        << format_fixed(D.differences[kDown].s[q], 3) << std::setw(10) << pv(kDown) << "\n";
    }
    o << "  s of differences / s of positions: up " << format_fixed(D.s_ratio[kUp], 3) << ", down "
      << format_fixed(D.s_ratio[kDown], 3) << " (sqrt 2 = 1.414 without drift)\n";
    o << "\n"
      << std::setw(12) << "target mm" << std::setw(11) << "chart up" << std::setw(9) << "s* up"
      << std::setw(11) << "chart dn" << std::setw(9) << "s* dn"
      << "\n";
    for (std::size_t i = 0; i < m; ++i)
      o << std::setw(12) << format_number(P[i]) << std::setw(11)
        << format_fixed(D.chart[kUp].value[i], 3) << std::setw(9)
        << format_fixed(D.chart[kUp].s[i], 3) << std::setw(11)
        << format_fixed(D.chart[kDown].value[i], 3) << std::setw(9)
        << format_fixed(D.chart[kDown].s[i], 3) << "\n";
    o << "\nAnomaly test (F test of each difference's variance against the same-parity others,\n"
         "Bonferroni over "
      << D.tests << " tests, alpha " << format_number(D.alpha) << "): ";
    if (D.anomalous_differences.empty()) {
      o << "no anomalous spread\n";
    } else {
      o << "\n";
      for (const auto& a : D.anomalous_differences)
        o << "  dir " << dir_label(a.direction) << ": " << format_number(P[a.from]) << ".."
          << format_number(P[a.to]) << " mm, s " << format_fixed(a.s, 3) << " " << u << ", F "
          << format_fixed(a.F, 2) << ", p " << std::setprecision(3) << a.p_value << "\n";
      for (const auto& a : D.anomalous_positions)
        o << "  anomalous position: " << cols.axis << "=" << format_number(P[a.target])
          << " mm (target " << a.target + 1 << "), dir " << dir_label(a.direction) << "\n";
    }
    const DriftPerCycle& C = D.per_cycle;
    o << "\nDrift per cycle (offset of the cycle's mean residual, relative to cycle "
      << D.reference_cycle << ", " << u << ")\n";
    o << std::setw(8) << "cycle" << (C.time_h.empty() ? "" : "   time h") << std::setw(10) << "up"
      << std::setw(10) << "down" << std::setw(10) << "mean"
      << "\n";
    for (std::size_t c = 0; c < C.cycles.size(); ++c) {
      o << std::setw(8) << C.cycles[c];
      if (!C.time_h.empty()) o << std::setw(9) << format_fixed(C.time_h[c], 3);
      o << std::setw(10) << format_fixed(C.offset_up[c], 3) << std::setw(10)
        << format_fixed(C.offset_down[c], 3) << std::setw(10) << format_fixed(C.offset[c], 3)
        << "\n";
    }
    o << "  drift rate: " << format_fixed(C.rate_per_cycle, 4) << " +- "
      << format_fixed(C.rate_per_cycle_se, 4) << " " << u << "/cycle";
    if (std::isfinite(C.rate_per_h))
      o << ", " << format_fixed(C.rate_per_h, 4) << " +- " << format_fixed(C.rate_per_h_se, 4)
        << " " << u << "/h";
    o << "\n";
  } else if (res.iso_only) {
    o << "\nDrift elimination and the Student-t set: off (--iso-only).\n";
  } else {
    o << "\nDrift elimination: needs at least 2 targets (skipped).\n";
  }
}

}  // namespace

std::string iso230_2_text(const std::string& data, const Iso230_2StudyResult& res) {
  const IsoColumns& cols = res.columns;
  const IsoRuns& runs = res.runs;
  const std::size_t m = runs.targets();
  const std::string u = cols.unit;
  const auto& P = runs.positions_mm;
  const IsoFigures& F = res.classical.figures;
  // ---- stdout ----
  std::ostringstream o;
  o << "weilgen iso230-2: " << data << ", axis " << cols.axis << " (deviation " << cols.deviation
    << "), " << m << " target" << (m == 1 ? "" : "s") << ", " << runs.cycles[kUp].size()
    << " cycles up, " << runs.cycles[kDown].size() << " cycles down\n\n";
  o << (res.iso_conforming() ? "Conformance\n" : "Conformance: NOT to ISO 230-2\n");
  for (const auto& line : iso230_2_conformance_statement(res)) o << "  " << line << "\n";
  o << "\n";
  o << "Normalisation and air (ISO 230-2:2014, ISO 1)\n";
  for (const auto& line : iso230_2_normalisation_statement(res)) o << "  " << line << "\n";
  o << "\n";
  o << "Per target (" << u << "; ISO 230-2, k = 2)\n";
  o << std::setw(12) << "target mm" << std::setw(10) << "mean up" << std::setw(10) << "mean dn"
    << std::setw(9) << "s up" << std::setw(9) << "s dn" << std::setw(9) << "B_i" << std::setw(9)
    << "R_i up" << std::setw(9) << "R_i dn" << std::setw(9) << "R_i" << std::setw(10) << "mean bi"
    << "\n";
  for (std::size_t i = 0; i < m; ++i)
    o << std::setw(12) << format_number(P[i]) << std::setw(10) << format_fixed(F.mean_up[i], 3)
      << std::setw(10) << format_fixed(F.mean_down[i], 3) << std::setw(9)
      << format_fixed(F.s_up[i], 3) << std::setw(9) << format_fixed(F.s_down[i], 3) << std::setw(9)
      << format_fixed(F.B_i[i], 3) << std::setw(9) << format_fixed(F.R_i_up[i], 3) << std::setw(9)
      << format_fixed(F.R_i_down[i], 3) << std::setw(9) << format_fixed(F.R_i[i], 3)
      << std::setw(10) << format_fixed(F.mean_bi[i], 3) << "\n";

  text_axis_figures(o, res);
  if (res.uncertainty) {
    o << "\nMeasurement uncertainty (" << u << "; ISO 230-9 and the GUM; class "
      << res.uncertainty->instrument_class << ", budget: " << res.uncertainty->source
      << "; Monte Carlo after GUM Supplement 1)\n";
    for (const auto& line : iso230_2_uncertainty_text(res)) o << line << "\n";
  }
  if (!res.tolerance.empty()) {
    o << "\nTolerances (" << u << ")\n";
    for (const auto& line : iso230_2_tolerance_statement(res)) o << line << "\n";
  }

  text_drift_elimination(o, res);

  return o.str();
}

nlohmann::json iso230_2_json(const std::string& data, const Iso230_2StudyResult& res,
                             const std::string& source_format) {
  const IsoColumns& cols = res.columns;
  const IsoRuns& runs = res.runs;
  const Iso230_2Result& cr = res.classical;
  const std::optional<DriftResult>& drift = res.drift;
  const std::size_t m = runs.targets();
  const std::string u = cols.unit;
  const auto& P = runs.positions_mm;
  const IsoFigures& F = cr.figures;
  // ---- JSON ----
  json j;
  {
    j = {{"file", data},
         {"axis", cols.axis},
         {"column", cols.deviation},
         {"deviation_unit", u},
         {"targets", m},
         {"cycles_up", runs.cycles[kUp]},
         {"cycles_down", runs.cycles[kDown]},
         {"positions_mm", P},
         {"coverage_factor", F.k_up}};
    j["source_format"] = source_format;
    json issues = json::array();
    for (const ConformanceIssue& i : res.conformance)
      issues.push_back({{"check", i.check}, {"message", i.message}});
    j["conformance"] = {{"iso230_2", res.iso_conforming()},
                        {"issues", issues},
                        {"statement", iso230_2_conformance_statement(res)}};
    j["iso_only"] = res.iso_only;
    j["uncertainty"] = res.uncertainty ? uncertainty_json(*res.uncertainty) : json();
    j["metadata"] = res.header_keys;
    const NormalisationResult& n = res.normalisation;
    j["normalisation"] = {
        {"reference_temperature_C", n.reference_temperature_C},
        {"datum_mm", json_number(n.datum_mm)},
        {"mode", to_string(n.mode)},
        {"warnings", n.warnings},
        {"material",
         {{"applied", n.material_applied},
          {"instrument_state",
           n.material_compensation.empty() ? json() : json(n.material_compensation)},
          {"decision", n.material_decision},
          {"expansion_source", n.expansion_origin.empty() ? json() : json(n.expansion_origin)},
          {"expansion_ppm_per_K", json_number(n.expansion_ppm_per_K)},
          {"temperature_source", n.material_source.empty() ? json() : json(n.material_source)},
          {"temperature_C", range_json(n.material_temperature_C)},
          {"correction_um", range_json(n.material_correction_um)}}},
        {"air",
         {{"compensation", to_string(n.air)},
          {"instrument_state", to_string(n.air_in_file)},
          {"applied", n.air_applied},
          {"decision", n.air_decision},
          {"equation", n.air_applied ? json("modified Edlen equation, Birch & Downs, Metrologia 30 "
                                            "(1993) 155 and 31 (1994) 315")
                                     : json()},
          {"wavelength_nm", json_number(n.wavelength_nm)},
          {"assumed_index", json_number(n.assumed_index)},
          {"temperature_C", range_json(n.air_temperature_C)},
          {"pressure_Pa", range_json(n.air_pressure_Pa)},
          {"humidity_pct", range_json(n.air_humidity_pct)},
          {"refractivity", range_json(n.air_refractivity)},
          {"correction_um", range_json(n.air_correction_um)}}},
        {"statement", iso230_2_normalisation_statement(res)}};
    j.update(figures_json(F));
    j["student"] = cr.student ? figures_json(*cr.student) : json();
    if (res.tolerance.empty()) {
      j["tolerance"] = json();
    } else {
      json checks = json::array();
      for (const ToleranceCheck& c : res.tolerance)
        checks.push_back({{"name", c.name},
                          {"value_um", json_number(c.value)},
                          {"limit_um", json_number(c.limit)},
                          {"U_um", json_number(c.U)},
                          {"decision", to_string(c.decision)},
                          {"pass", c.decision == Decision::Conforms}});
      j["tolerance"] = {{"checks", checks},
                        {"pass", res.verdict == Decision::Conforms},
                        {"verdict", to_string(res.verdict)},
                        {"reason", res.verdict_reason.empty() ? json() : json(res.verdict_reason)}};
    }
    if (drift) {
      const DriftResult& D = *drift;
      json de = figures_json(D.figures);
      de["reference_position_mm"] = P[D.reference_target];
      de["reference_cycle"] = D.reference_cycle;
      de["s_diff_up_um"] = json_numbers(D.chart[kUp].s_diff);
      de["s_diff_down_um"] = json_numbers(D.chart[kDown].s_diff);
      de["student"] = D.student ? figures_json(*D.student) : json();
      de["adjacent_differences"] = {{"up", differences_json(D.differences[kUp], P)},
                                    {"down", differences_json(D.differences[kDown], P)}};
      de["s_ratio"] = {{"up", json_number(D.s_ratio[kUp])},
                       {"down", json_number(D.s_ratio[kDown])}};
      j["drift_eliminated"] = de;
      const DriftPerCycle& C = D.per_cycle;
      j["drift_per_cycle"] = {{"cycles", C.cycles},
                              {"time_h", C.time_h.empty() ? json() : json_numbers(C.time_h)},
                              {"offset_up_um", json_numbers(C.offset_up)},
                              {"offset_down_um", json_numbers(C.offset_down)},
                              {"offset_um", json_numbers(C.offset)},
                              {"rate_um_per_cycle", json_number(C.rate_per_cycle)},
                              {"rate_se_um_per_cycle", json_number(C.rate_per_cycle_se)},
                              {"rate_um_per_h", json_number(C.rate_per_h)},
                              {"rate_se_um_per_h", json_number(C.rate_per_h_se)}};
      j["anomaly_test"] = {
          {"alpha", D.alpha},
          {"tests", D.tests},
          {"threshold_p", D.tests ? json(D.alpha / static_cast<double>(D.tests)) : json()}};
      json ad = json::array(), ap = json::array();
      for (const auto& a : D.anomalous_differences)
        ad.push_back({{"direction", a.direction},
                      {"from_mm", P[a.from]},
                      {"to_mm", P[a.to]},
                      {"s_um", json_number(a.s)},
                      {"F", json_number(a.F)},
                      {"p_value", json_number(a.p_value)}});
      for (const auto& a : D.anomalous_positions)
        ap.push_back(
            {{"direction", a.direction}, {"position_mm", P[a.target]}, {"target", a.target + 1}});
      j["anomalous_differences"] = ad;
      j["anomalous_positions"] = ap;
    } else {
      j["drift_eliminated"] = json();
      j["drift_per_cycle"] = json();
      j["anomalous_differences"] = json::array();
      j["anomalous_positions"] = json::array();
    }
  }

  return json_document("iso230-2", std::move(j));
}

std::string iso230_2_csv(const Iso230_2StudyResult& res) {
  const IsoFigures& F = res.classical.figures;
  const std::vector<double>& P = res.runs.positions_mm;
  const std::string u = "_" + res.columns.unit;
  const std::optional<DriftResult>& D = res.drift;
  std::ostringstream c;
  c << "target_mm";
  for (const char* name : {"mean_up", "mean_down", "s_up", "s_down", "B_i", "R_i_up", "R_i_down",
                           "R_i", "mean_bi", "lower_up", "upper_up", "lower_down", "upper_down"})
    c << "," << name << u;
  if (D)
    for (const char* name : {"chart_up", "s_star_up", "chart_down", "s_star_down"})
      c << "," << name << u;
  c << "\n";
  for (std::size_t i = 0; i < P.size(); ++i) {
    c << csv_number(P[i]);
    for (double v : {F.mean_up[i], F.mean_down[i], F.s_up[i], F.s_down[i], F.B_i[i], F.R_i_up[i],
                     F.R_i_down[i], F.R_i[i], F.mean_bi[i], F.mean_up[i] - F.k_up * F.s_up[i],
                     F.mean_up[i] + F.k_up * F.s_up[i], F.mean_down[i] - F.k_down * F.s_down[i],
                     F.mean_down[i] + F.k_down * F.s_down[i]})
      c << "," << csv_number(v);
    if (D)
      for (double v : {D->chart[kUp].value[i], D->chart[kUp].s[i], D->chart[kDown].value[i],
                       D->chart[kDown].s[i]})
        c << "," << csv_number(v);
    c << "\n";
  }
  return c.str();
}

std::vector<Panel> iso230_2_panels(const Iso230_2StudyResult& res) {
  const IsoColumns& cols = res.columns;
  const IsoRuns& runs = res.runs;
  const Iso230_2Result& cr = res.classical;
  const std::optional<DriftResult>& drift = res.drift;
  const std::size_t m = runs.targets();
  const std::string u = cols.unit;
  const auto& P = runs.positions_mm;
  const IsoFigures& F = cr.figures;
  std::vector<Panel> panels;
  {
    const std::string ylabel = "deviation " + cols.deviation + " (" + u + ")";
    const std::string xlabel = cols.axis + " (mm)";
    LinePlot c1{"ISO 230-2: every cycle", xlabel, ylabel, P, {}};
    add_cycles(c1, runs.x[kUp], "cycles up");
    add_cycles(c1, runs.x[kDown], "cycles down");
    panels.push_back(c1);
    LinePlot c2{"ISO 230-2: mean deviations and +-2s", xlabel, ylabel, P, {}};
    add_band(c2, F.mean_up, F.s_up, 2, "mean up");
    add_band(c2, F.mean_down, F.s_down, 2, "mean down");
    add_tolerance_rules(c2, res.tolerance, u);
    panels.push_back(c2);
    if (drift) {
      const DriftResult& D = *drift;
      const std::string ref = cols.axis + "=" + format_number(P[D.reference_target]) +
                              " mm, cycle " + std::to_string(D.reference_cycle);
      LinePlot c3{"drift eliminated: every cycle shifted to " + ref, xlabel, ylabel, P, {}};
      add_cycles(c3, D.chart[kUp].shifted, "cycles up");
      add_cycles(c3, D.chart[kDown].shifted, "cycles down");
      panels.push_back(c3);
      LinePlot c4{"drift eliminated: chart from " + ref + ", +-2s*", xlabel, ylabel, P, {}};
      add_band(c4, D.chart[kUp].value, D.chart[kUp].s, 2, "chart up", "s*");
      add_band(c4, D.chart[kDown].value, D.chart[kDown].s, 2, "chart down", "s*");
      add_tolerance_rules(c4, res.tolerance, u);
      panels.push_back(c4);
      BarChart c5{"s of adjacent differences (seed Fig. 10)", "s (" + u + ")", {}, {}};
      BarSeries su{"up", D.differences[kUp].s, {}, {}}, sd{"down", D.differences[kDown].s, {}, {}};
      for (std::size_t q = 0; q + 1 < m; ++q)
        c5.categories.push_back(format_number(P[q]) + ".." + format_number(P[q + 1]));
      c5.series = {su, sd};
      panels.push_back(c5);
      std::vector<double> cyc;
      for (long c : D.per_cycle.cycles) cyc.push_back(static_cast<double>(c));
      LinePlot c6{"drift per cycle (relative to cycle " + std::to_string(D.reference_cycle) + ")",
                  "cycle",
                  "offset (" + u + ")",
                  cyc,
                  {{"up", D.per_cycle.offset_up},
                   {"down", D.per_cycle.offset_down},
                   {"mean", D.per_cycle.offset}}};
      panels.push_back(c6);
    }
  }
  return panels;
}

}  // namespace weilgen
