// Every algorithm object validates its options up front (docs/architecture.md, "Algorithm
// objects"): a bad value throws std::invalid_argument naming the field or flag, before any work.
#include <doctest/doctest.h>

#include <stdexcept>
#include <string>

#include "weilgen/analysis/allocation_study.hpp"
#include "weilgen/analysis/gap.hpp"
#include "weilgen/analysis/identify.hpp"
#include "weilgen/analysis/sensitivity_study.hpp"
#include "weilgen/measure/iso230_2_study.hpp"
#include "weilgen/measure/pdge_fit_study.hpp"
#include "weilgen/uq/allocation.hpp"
#include "weilgen/uq/reliability.hpp"
#include "weilgen/uq/sobol_indices.hpp"

using namespace weilgen;

namespace {

// The message of the std::invalid_argument `f` throws ("" when it throws none).
template <typename F>
std::string refusal(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool names(const std::string& message, const std::string& word) {
  INFO("message: " << message);
  return message.find(word) != std::string::npos;
}

}  // namespace

TEST_CASE("options: uq algorithms refuse bad options in their constructors") {
  SobolOptions so;
  so.confidence = 1.5;
  CHECK(names(refusal([&] { SobolAnalysis{so}; }), "confidence must be in (0, 1)"));
  so = {};
  so.samples = 1;
  CHECK(names(refusal([&] { SobolAnalysis{so}; }), "sample size N must be at least 2"));
  CHECK(refusal([] { SobolAnalysis{SobolOptions{}}; }).empty());

  ReliabilityOptions ro;
  ro.confidence = 0;
  CHECK(names(refusal([&] { ReliabilityAnalysis{ro}; }), "confidence"));
  ro = {};
  ro.form_max_iterations = 0;
  CHECK(names(refusal([&] { ReliabilityAnalysis{ro}; }), "FORM"));

  AllocationOptions ao;
  ao.min_target = 1.5;
  CHECK(names(refusal([&] { StepAllocation{ao}; }), "targets must be in (0, 1]"));
  ao = {};
  ao.cost_weights = {1.0, -1.0};
  CHECK(names(refusal([&] { CostAwareAllocation{ao}; }), "cost weights"));
}

TEST_CASE("options: studies refuse bad options, naming the flag") {
  SensitivityOptions s;
  s.local = s.exact = s.sobol = false;
  CHECK(names(refusal([&] { SensitivityStudy{s}; }), "--method"));
  s = {};
  s.outputs = {OutputId::Dx, OutputId::Dx};
  CHECK(names(refusal([&] { SensitivityStudy{s}; }), "\"dx\" given twice"));
  CHECK(names(refusal([] { parse_output_list("dx,dq"); }), "unknown output \"dq\""));
  CHECK(names(refusal([] { parse_sampling("lhs"); }), "--sampling"));

  AllocationStudyOptions a;
  a.rank = "loud";
  CHECK(names(refusal([&] { AllocationStudy{a}; }), "--rank"));
  a = {};
  a.max_loosen = 0.5;
  CHECK(names(refusal([&] { AllocationStudy{a}; }), "--max-loosen"));

  IdentifyOptions io;
  io.rank_tolerance = 2;
  CHECK(names(refusal([&] { Identification{io}; }), "--rank-tol"));

  GapOptions g;
  g.alpha = 0.7;
  CHECK(names(refusal([&] { GapDiagnosis{g}; }), "--alpha"));
  g = {};
  g.effects = {"gremlins"};
  CHECK(names(refusal([&] { GapDiagnosis{g}; }), "unknown effect 'gremlins'"));
}

TEST_CASE("options: measurement evaluations refuse bad options") {
  Iso230_2StudyOptions i;
  i.drift.alpha = 0;
  CHECK(names(refusal([&] { Iso230_2Study{i}; }), "--alpha"));
  i = {};
  i.target_tolerance_mm = -1;
  CHECK(names(refusal([&] { Iso230_2Study{i}; }), "--target-tolerance"));
  DriftOptions d;
  d.tolerance_mm = 0;
  CHECK(names(refusal([&] { DriftElimination{d}; }), "tolerance_mm"));

  PdgeFitStudyOptions p;
  p.cv = "random";
  CHECK(names(refusal([&] { PdgeFitStudy{p}; }), "--cv"));
  p = {};
  p.bases = {"spline:3"};
  CHECK(names(refusal([&] { PdgeFitStudy{p}; }), "--basis"));
  PdgeFitOptions f;
  f.min_order = 5;
  f.max_order = 2;
  CHECK(names(refusal([&] { PdgeFit{f}; }), "order range 5..2 is empty"));
}
