#include "weilgen/measure/iso230_2_study.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

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

void Iso230_2StudyOptions::validate() const {
  if (!(drift.alpha > 0 && drift.alpha < 1))
    throw std::invalid_argument("--alpha must be in (0, 1)");
  if (!(target_tolerance_mm > 0)) throw std::invalid_argument("--target-tolerance must be > 0");
  normalisation.validate();
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
  r.classical = Iso230_2Evaluation().run(r.runs);
  if (r.runs.targets() >= 2) {
    DriftOptions d = options_.drift;
    d.tolerance_mm = options_.target_tolerance_mm;
    r.drift = DriftElimination(d).run(r.runs);
  } else if (options_.drift.reference_position_mm || options_.drift.reference_cycle) {
    throw std::invalid_argument("--reference-position/--reference-cycle need >= 2 targets");
  }
  r.tolerance = check_iso_tolerance(options_.tolerance, r.classical.figures);
  return r;
}

}  // namespace weilgen
