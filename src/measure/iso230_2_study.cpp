#include "weilgen/measure/iso230_2_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "weilgen/base/format.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {

namespace {

// The figures a tolerance may limit, by name.
const std::vector<std::pair<std::string, double IsoFigures::*>>& figure_fields() {
  static const std::vector<std::pair<std::string, double IsoFigures::*>> f = {
      {"B", &IsoFigures::B},           {"B_mean", &IsoFigures::B_mean}, {"R_up", &IsoFigures::R_up},
      {"R_down", &IsoFigures::R_down}, {"R", &IsoFigures::R},           {"E_up", &IsoFigures::E_up},
      {"E_down", &IsoFigures::E_down}, {"E", &IsoFigures::E},           {"M", &IsoFigures::M},
      {"A_up", &IsoFigures::A_up},     {"A_down", &IsoFigures::A_down}, {"A", &IsoFigures::A}};
  return f;
}

double positive_number(const std::string& text, const std::string& item) {
  char* end = nullptr;
  const std::string t = trim(text);
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !std::isfinite(v) || !(v > 0))
    throw std::invalid_argument("--tolerance " + item + ": '" + text +
                                "' is not a number > 0 (in the deviation unit, um or urad)");
  return v;
}

}  // namespace

IsoTolerance parse_iso_tolerance(const std::string& text) {
  IsoTolerance t;
  if (trim(text).empty()) throw std::invalid_argument("--tolerance: empty");
  for (const std::string& raw : split(text, ',')) {
    const std::string item = trim(raw);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      if (t.band) throw std::invalid_argument("--tolerance " + text + ": two bands");
      t.band = positive_number(item, item);
      continue;
    }
    const std::string name = trim(item.substr(0, eq));
    const auto& f = figure_fields();
    if (std::none_of(f.begin(), f.end(), [&](const auto& p) { return p.first == name; })) {
      std::vector<std::string> names;
      for (const auto& p : f) names.push_back(p.first);
      throw std::invalid_argument("--tolerance " + item + ": unknown figure '" + name +
                                  "' (figures: " + join(names) + ")");
    }
    for (const auto& p : t.figures)
      if (p.first == name) throw std::invalid_argument("--tolerance: " + name + " given twice");
    t.figures.emplace_back(name, positive_number(item.substr(eq + 1), item));
  }
  return t;
}

std::vector<ToleranceCheck> check_iso_tolerance(const IsoTolerance& tol, const IsoFigures& F) {
  std::vector<ToleranceCheck> out;
  if (tol.band) {
    double worst = 0;
    for (std::size_t i = 0; i < F.mean_up.size(); ++i)
      for (double v :
           {F.mean_up[i] + F.k_up * F.s_up[i], F.mean_up[i] - F.k_up * F.s_up[i],
            F.mean_down[i] + F.k_down * F.s_down[i], F.mean_down[i] - F.k_down * F.s_down[i]})
        worst = std::max(worst, std::abs(v));
    out.push_back({"band", worst, *tol.band, worst <= *tol.band});
  }
  for (const auto& [name, limit] : tol.figures)
    for (const auto& [fname, field] : figure_fields())
      if (fname == name) {
        const double v = name == "B_mean" ? std::abs(F.*field) : F.*field;
        out.push_back({name, v, limit, v <= limit});
      }
  return out;
}

const char* to_string(Decision d) {
  switch (d) {
    case Decision::DoesNotConform:
      return "does not conform";
    case Decision::NotProven:
      return "not proven";
    case Decision::Conforms:
      break;
  }
  return "conforms";
}

std::vector<ConformanceIssue> iso230_2_conformance(const IsoRuns& runs, const IsoColumns& cols,
                                                   const NormalisationResult& n) {
  std::vector<ConformanceIssue> out;
  const std::size_t m = runs.targets();
  const bool linear = cols.unit == "um";
  // Clause 5.3: at least five targets, and five per metre of travel up to 2000 mm (one per
  // 250 mm beyond); a rotary axis at least five.
  const double travel = m ? runs.positions_mm.back() - runs.positions_mm.front() : 0;
  std::size_t needed = 5;
  std::string rule = "at least 5";
  if (linear && travel <= 2000) {
    needed =
        std::max<std::size_t>(5, static_cast<std::size_t>(std::ceil(5 * travel / 1000 - 1e-9)));
    rule = "at least 5, and 5 per metre of travel";
  } else if (linear) {
    needed = static_cast<std::size_t>(std::ceil(travel / 250 - 1e-9));
    rule = "one per 250 mm of travel beyond 2000 mm";
  }
  if (m < needed)
    out.push_back({"targets", std::to_string(m) + " target" + (m == 1 ? "" : "s") + " over " +
                                  format_number(travel) + (linear ? " mm" : " deg") +
                                  "; ISO 230-2 asks for " + std::to_string(needed) + " (" + rule +
                                  ")"});
  const std::size_t up = runs.cycles[kUp].size(), down = runs.cycles[kDown].size();
  if (up < 5 || down < 5)
    out.push_back({"cycles", std::to_string(up) + " cycles forward and " + std::to_string(down) +
                                 " reverse; ISO 230-2 asks for 5 in each direction"});
  if (up == 0 || down == 0)
    out.push_back({"bidirectional", "ISO 230-2 approaches every target from both directions"});
  if (linear && !n.air_applied && n.air != AirCompensation::Instrument)
    out.push_back({"air", std::string("the refractive index of the air is not compensated (") +
                              (n.air == AirCompensation::Unstated ? "the file does not say"
                                                                  : "stated as not compensated") +
                              "): the readings may be off by about 271 um per metre of travel"});
  if (linear && !n.material_applied && n.material_compensation != "instrument" &&
      n.material_temperature_C.empty())
    out.push_back({"temperature",
                   "no material temperature recorded and no normalisation to 20 degC: the "
                   "nominal differential expansion is neither corrected nor stated (ISO 230-2, "
                   "5.3)"});
  return out;
}

void decide_iso_tolerance(Iso230_2StudyResult& r) {
  // Without air compensation the readings carry a scale error of about 271 um/m: the figures
  // between targets (E, M, A, the band) prove nothing; R and B compare one target with itself.
  bool air = false;
  for (const ConformanceIssue& i : r.conformance) air |= i.check == "air";
  bool fails = false, unproven = false, air_open = false;
  std::vector<std::string> open;
  for (ToleranceCheck& c : r.tolerance) {
    if (std::isfinite(c.U))
      c.decision = c.value + c.U <= c.limit  ? Decision::Conforms
                   : c.value - c.U > c.limit ? Decision::DoesNotConform
                                             : Decision::NotProven;
    else
      c.decision = c.pass ? Decision::Conforms : Decision::DoesNotConform;
    const bool scaled =
        c.name == "band" || c.name[0] == 'E' || c.name[0] == 'M' || c.name[0] == 'A';
    if (air && scaled) {
      c.decision = Decision::NotProven;
      air_open = true;
      continue;
    }
    fails |= c.decision == Decision::DoesNotConform;
    if (c.decision == Decision::NotProven) {
      unproven = true;
      open.push_back(c.name);
    }
  }
  r.verdict = fails                  ? Decision::DoesNotConform
              : unproven || air_open ? Decision::NotProven
                                     : Decision::Conforms;
  std::vector<std::string> why;
  if (!open.empty())
    why.push_back(join(open) + ": the value +- U straddles the limit (ISO 14253-1)");
  if (air_open)
    why.push_back(
        "the refractive index of the air is not compensated: E, M, A and the band may be off by "
        "about 271 um per metre of travel");
  r.verdict_reason.clear();
  for (std::size_t k = 0; r.verdict == Decision::NotProven && k < why.size(); ++k)
    r.verdict_reason += (k ? "; " : "") + why[k];
}

void Iso230_2StudyOptions::validate() const {
  if (!(drift.alpha > 0 && drift.alpha < 1))
    throw std::invalid_argument("--alpha must be in (0, 1)");
  if (!(target_tolerance_mm > 0)) throw std::invalid_argument("--target-tolerance must be > 0");
  normalisation.validate();
  if (uncertainty) uncertainty->validate();
}

Iso230_2Study::Iso230_2Study(Iso230_2StudyOptions options) : options_(std::move(options)) {
  options_.validate();
}

Iso230_2StudyResult Iso230_2Study::run(const MeasurementTable& table) const {
  Iso230_2StudyResult r;
  r.header_keys = table.header_keys;
  r.columns = iso_columns(table, options_.axis, options_.column);
  std::vector<IsoObservation> obs = iso_observations(table, r.columns);
  r.normalisation = normalise_observations(
      table, obs, normalisation_with_header_keys(options_.normalisation, table), r.columns.unit);
  r.runs = group_iso_runs(obs, table.file, options_.target_tolerance_mm);
  r.iso_only = options_.iso_only;
  Iso230_2Options classical;
  classical.student = !options_.iso_only;
  r.classical = Iso230_2Evaluation(classical).run(r.runs);
  if (r.runs.targets() >= 2 && !options_.iso_only) {
    DriftOptions d = options_.drift;
    d.tolerance_mm = options_.target_tolerance_mm;
    r.drift = DriftElimination(d).run(r.runs);
  } else if (options_.drift.reference_position_mm || options_.drift.reference_cycle) {
    throw std::invalid_argument(
        options_.iso_only ? "--reference-position/--reference-cycle: --iso-only has no drift "
                            "elimination"
                          : "--reference-position/--reference-cycle need >= 2 targets");
  }
  if (options_.uncertainty)
    r.uncertainty = Iso230_2Uncertainty(*options_.uncertainty)
                        .run(r.runs, r.classical.figures, r.normalisation, r.columns.unit);
  r.tolerance = check_iso_tolerance(options_.tolerance, r.classical.figures);
  if (r.uncertainty)
    for (ToleranceCheck& c : r.tolerance)
      if (const FigureUncertainty* f = r.uncertainty->figure(c.name)) c.U = f->U;
  r.conformance = iso230_2_conformance(r.runs, r.columns, r.normalisation);
  decide_iso_tolerance(r);
  return r;
}

}  // namespace weilgen
