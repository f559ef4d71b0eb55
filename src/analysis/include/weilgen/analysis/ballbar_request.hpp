// `weilgen ballbar` as written (docs/ballbar.md, "weilgen ballbar"): a ballbar trace evaluated
// on its own — its circle from the header keys and flags, the ISO 230-4 figures of every run and
// the diagnosis of the usual causes (weilgen/measure/ballbar_diagnosis.hpp) — and, with a
// machine, through its model: the circle checked against the machine's travel and kinematics,
// and the model's error terms that would make each geometric cause named beside it. Every front
// end (the CLI, the Python module) runs these steps and gets the documents of
// report/ballbar_document.hpp.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/study.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/ballbar_diagnosis.hpp"

namespace weilgen {

struct BallbarRequest : MeasurementRequest {
  std::string trace;     // the trace file (docs/data-format.md, "Ballbar traces")
  std::string feedrate;  // --feedrate ("1000 mm/min"); else the header key feedrate
  double alpha = BallbarDiagnosisOptions{}.alpha;                              // --alpha
  double min_contribution_um = BallbarDiagnosisOptions{}.min_contribution_um;  // --min-contribution
  std::vector<std::string> pdge = {"poly:2"};  // with a machine: the basis of the error terms
  bool with_machine() const { return !model.machine.empty() || opened != nullptr; }
  // The flags alone, before any file is read (std::invalid_argument naming the flag).
  void validate() const;
  // The outputs before any work: the plot an .svg, the report an .html, none of them an input
  // (the trace, the machine file) or another output (std::invalid_argument naming the flag).
  void check_outputs(const std::string& json, const std::string& plot,
                     const std::string& report) const;
};

// A model term whose ballbar signature on the circle is one geometric cause: the cause's size
// (in its unit) per unit of the term (its error's unit), so that the term alone would be
// size / per_unit.
struct BallbarCauseTerm {
  std::string cause;  // a BallbarCause id: squareness, scale_mismatch, straightness_X ...
  std::string term;   // "E_C0Y", "E_XX[u]" ...
  std::string unit;   // the term's unit
  double per_unit = 0;
};

struct BallbarStudy {
  std::string file;
  std::map<std::string, std::string> header_keys;  // machine, date, operator ... of the file
  BallbarCircle circle;
  bool centre_given = true;  // false: no centre key or flag (no machine: the centre is not needed)
  double feedrate_mm_min = std::numeric_limits<double>::quiet_NaN();
  std::vector<BallbarTrace> traces;
  BallbarDiagnosisResult diagnosis;
  std::string machine;                  // the machine's name; "" without one
  std::vector<BallbarCauseTerm> terms;  // with a machine
};

// With a machine: the terms of the model (PDGE basis `basis`) whose ballbar signature on the
// circle is squareness, scale mismatch or a straightness (at least 99 % of what they change
// beyond the centre and radius).
std::vector<BallbarCauseTerm> ballbar_cause_terms(const Model& model, const BallbarCircle& circle,
                                                  const PdgeBasisChoice& basis);

// Validates, reads the trace (and the machine), evaluates and diagnoses. std::invalid_argument
// for bad flags, InputError for bad files.
BallbarStudy run_ballbar(const BallbarRequest& request);

}  // namespace weilgen
