#include "weilgen/report/ballbar_document.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

using nlohmann::json;

// The largest G (LSQ centre) of the runs: what a cause's share is of.
double largest_g(const BallbarStudy& st) {
  double g = 0;
  for (const BallbarRun& r : st.diagnosis.runs) g = std::max(g, r.evaluation.circular_deviation_um);
  return g;
}

std::string size_text(const BallbarCause& c) {
  std::string s = format_fixed(c.size, c.unit == "um" ? 2 : 1) + " +- " +
                  format_fixed(c.se, c.unit == "um" ? 2 : 1) + " " + c.unit;
  if (std::isfinite(c.detail))
    s += ", " + c.detail_name + " " + format_fixed(c.detail, c.detail_unit == "ms" ? 3 : 1) + " " +
         c.detail_unit;
  return s;
}

}  // namespace

std::string ballbar_run_label(int feed, int cycle) {
  return std::string(feed > 0 ? "ccw" : "cw") + (cycle != 0 ? " " + std::to_string(cycle) : "");
}

std::string ballbar_text(const BallbarStudy& st) {
  const BallbarCircle& c = st.circle;
  const BallbarDiagnosisResult& d = st.diagnosis;
  std::ostringstream o;
  o << "weilgen ballbar: " << st.file << ", plane " << c.plane << ", radius "
    << format_number(c.radius_mm) << " mm";
  if (std::isfinite(st.feedrate_mm_min))
    o << ", feedrate " << format_number(st.feedrate_mm_min) << " mm/min";
  o << ", " << d.runs.size() << " run" << (d.runs.size() == 1 ? "" : "s");
  if (!st.machine.empty()) o << ", machine " << st.machine;
  o << "\n\n";
  // ISO 230-4, one column per run.
  o << std::left << std::setw(40) << "ISO 230-4 (um)" << std::right;
  for (const BallbarRun& r : d.runs) o << std::setw(12) << ballbar_run_label(r.feed, r.cycle);
  o << "\n";
  struct Row {
    const char* name;
    std::function<double(const BallbarEvaluation&)> get;
  };
  const Row rows[] = {
      {"circular deviation G (LSQ centre)", [](const auto& e) { return e.circular_deviation_um; }},
      {"circular deviation G (minimum zone)",
       [](const auto& e) { return e.mz_circular_deviation_um; }},
      {"radial deviation F max", [](const auto& e) { return e.radial_deviation_max_um; }},
      {"radial deviation F min", [](const auto& e) { return e.radial_deviation_min_um; }},
      {"radius deviation", [](const auto& e) { return e.radius_deviation_um; }},
      {"centre offset first", [](const auto& e) { return e.centre_offset_um[0]; }},
      {"centre offset second", [](const auto& e) { return e.centre_offset_um[1]; }}};
  for (const Row& row : rows) {
    std::string name = row.name;
    if (name == "centre offset first") name = "centre offset " + c.first;
    if (name == "centre offset second") name = "centre offset " + c.second;
    o << "  " << std::left << std::setw(38) << name << std::right;
    for (const BallbarRun& r : d.runs) o << std::setw(12) << format_fixed(row.get(r.evaluation), 3);
    o << "\n";
  }
  o << "  " << std::left << std::setw(38) << "points / coverage (deg)" << std::right;
  for (const BallbarRun& r : d.runs)
    o << std::setw(12)
      << (std::to_string(r.evaluation.points) + "/" + format_fixed(r.evaluation.coverage_deg, 0));
  o << "\n";
  if (std::isfinite(d.hysteresis_um))
    o << "  circular hysteresis H (first ccw against first cw run): "
      << format_fixed(d.hysteresis_um, 3) << " um\n";
  else
    o << "  circular hysteresis H: needs a ccw and a cw run\n";

  o << "\nDiagnosis (least squares on every run, each run's centre and radius free; residual "
    << format_fixed(d.residual_rms_um, 3)
    << " um rms; significance: partial F test, family-wise alpha " << format_number(d.alpha)
    << ")\n";
  const double g = largest_g(st);
  std::size_t rank = 0;
  for (const BallbarCause& k : d.causes)
    if (k.significant) {
      if (rank == 0)
        o << std::setw(6) << "rank"
          << "  " << std::left << std::setw(26) << "cause" << std::setw(34) << "size" << std::right
          << std::setw(14) << "contribution" << std::setw(8) << "share" << std::setw(10) << "p"
          << "\n";
      o << std::setw(6) << ++rank << "  " << std::left << std::setw(26) << k.name << std::setw(34)
        << size_text(k) << std::right << std::setw(11) << format_fixed(k.contribution_um, 3)
        << " um" << std::setw(7) << (g > 0 ? format_fixed(100 * k.contribution_um / g, 0) : "-")
        << "%" << std::setw(10) << p_text(k.p_value) << "\n";
      for (const BallbarCauseTerm& t : st.terms)
        if (t.cause == k.id && t.per_unit != 0)
          o << "          " << st.machine << ": as " << t.term << " alone, " << t.term << " = "
            << format_significant(k.size / t.per_unit, 4) << " " << t.unit << "\n";
    }
  if (rank == 0)
    o << "  clean: no cause stands out of the noise (" << format_fixed(d.residual_rms_um, 3)
      << " um rms)\n";
  std::vector<std::string> quiet, inseparable;
  for (const BallbarCause& k : d.causes) {
    if (!k.separable) {
      inseparable.push_back(k.name + " (" + k.note + ")");
    } else if (!k.significant) {
      quiet.push_back(k.name + " " + size_text(k) + " (p " + p_text(k.p_value) + ")");
    }
  }
  if (!quiet.empty()) {
    o << "  not significant:\n";
    for (const std::string& q : quiet) o << "    " << q << "\n";
  }
  if (!inseparable.empty()) {
    o << "  not separable on these runs:\n";
    for (const std::string& q : inseparable) o << "    " << q << "\n";
  }
  return o.str();
}

nlohmann::json ballbar_json(const BallbarStudy& st) {
  const BallbarCircle& c = st.circle;
  const BallbarDiagnosisResult& d = st.diagnosis;
  json runs = json::array();
  for (const BallbarRun& r : d.runs) {
    const BallbarEvaluation& e = r.evaluation;
    json harmonics = json::array();
    for (const BallbarHarmonic& h : e.harmonics)
      harmonics.push_back({{"order", h.order},
                           {"amplitude_um", json_number(h.amplitude_um)},
                           {"phase_deg", json_number(h.phase_deg)}});
    runs.push_back(
        {{"feed", r.feed > 0 ? "ccw" : "cw"},
         {"cycle", r.cycle},
         {"label", ballbar_run_label(r.feed, r.cycle)},
         {"points", e.points},
         {"coverage_deg", json_number(e.coverage_deg)},
         {"G_um", json_number(e.circular_deviation_um)},
         {"G_minimum_zone_um", json_number(e.mz_circular_deviation_um)},
         {"F_max_um", json_number(e.radial_deviation_max_um)},
         {"F_min_um", json_number(e.radial_deviation_min_um)},
         {"radius_deviation_um", json_number(e.radius_deviation_um)},
         {"centre_offset_um", json_numbers({e.centre_offset_um[0], e.centre_offset_um[1]})},
         {"minimum_zone_centre_um",
          json_numbers({e.mz_centre_offset_um[0], e.mz_centre_offset_um[1]})},
         {"minimum_zone_radius_deviation_um", json_number(e.mz_radius_deviation_um)},
         {"harmonics", harmonics}});
  }
  const double g = largest_g(st);
  json causes = json::array();
  for (const BallbarCause& k : d.causes) {
    json terms = json::array();
    for (const BallbarCauseTerm& t : st.terms)
      if (t.cause == k.id)
        terms.push_back({{"term", t.term},
                         {"unit", t.unit},
                         {"per_unit", json_number(t.per_unit)},
                         {"alone", json_number(t.per_unit != 0 ? k.size / t.per_unit : NAN)}});
    causes.push_back({{"id", k.id},
                      {"name", k.name},
                      {"axis", k.axis.empty() ? json() : json(k.axis)},
                      {"size", json_number(k.size)},
                      {"se", json_number(k.se)},
                      {"unit", k.unit},
                      {"detail", k.detail_name.empty() ? json()
                                                       : json{{"name", k.detail_name},
                                                              {"value", json_number(k.detail)},
                                                              {"unit", k.detail_unit}}},
                      {"contribution_um", json_number(k.contribution_um)},
                      {"share_pct", json_number(g > 0 ? 100 * k.contribution_um / g : NAN)},
                      {"p_value", json_number(k.p_value)},
                      {"threshold_p", json_number(k.threshold_p)},
                      {"significant", k.significant},
                      {"separable", k.separable},
                      {"note", k.note.empty() ? json() : json(k.note)},
                      {"terms", terms}});
  }
  json centre = json();
  if (st.centre_given) {
    centre = json::object();
    for (const auto& [name, v] : c.centre) centre[name] = v;
  }
  json body = {{"file", st.file},
               {"plane", c.plane},
               {"first", c.first},
               {"second", c.second},
               {"radius_mm", c.radius_mm},
               {"centre", centre},
               {"feedrate_mm_min", json_number(st.feedrate_mm_min)},
               {"machine", st.machine.empty() ? json() : json(st.machine)},
               {"metadata", st.header_keys},
               {"runs", runs},
               {"hysteresis_um", json_number(d.hysteresis_um)},
               {"diagnosis",
                {{"alpha", d.alpha},
                 {"residual_rms_um", json_number(d.residual_rms_um)},
                 {"points", d.points},
                 {"parameters", d.parameters},
                 {"clean", d.clean()},
                 {"causes", causes}}}};
  return json_document("ballbar", std::move(body));
}

}  // namespace weilgen
