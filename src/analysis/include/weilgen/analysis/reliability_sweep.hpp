// Reliability of every (pose, toleranced output) of a study: the sweep behind
// `weilgen reliability` and `weilgen allocate`. Order-1 components are passed to the engine as
// exact linear forms (so `auto` is exact for Gaussian errors); dp and higher orders go through
// the model itself.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "weilgen/analysis/study.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen {

enum class LimitChoice { TwoSided, OneSided, Radial };
LimitChoice parse_limit(const std::string& text);  // two-sided | one-sided | radial
const char* limit_name(LimitChoice limit, OutputId output);

struct SweepCase {
  std::size_t pose = 0, tolerance = 0;  // indices into Study::poses.poses and Study::tolerances
  ReliabilityResult result;
};

// --sensitivities auto | form | sampling. auto: sampling-based (importance sampling
// differentiating its own estimate) for the radial limit, where FORM's single-point linearisation
// of a sphere is off by a factor 2-3; FORM-based elsewhere.
enum class SensitivityChoice { Auto, Form, Sampling };
SensitivityChoice parse_sensitivities(const std::string& text);

// The sweep's settings, from the flags shared by `reliability` and `allocate` (--method
// --limit --sensitivities --samples --confidence; std::invalid_argument naming the flag).
struct ReliabilitySettings {
  LimitChoice limit = LimitChoice::TwoSided;
  SensitivityChoice sensitivities = SensitivityChoice::Auto;
  ReliabilityOptions options;  // threads: set from the study
};
ReliabilitySettings parse_reliability_settings(const std::string& method, const std::string& limit,
                                               const std::string& sensitivities,
                                               std::size_t samples, double confidence,
                                               std::uint64_t seed);

// Those flags as written, with the defaults of `weilgen reliability` (every front end fills
// this and parses it with parse_reliability_flags, so the defaults have one home).
struct ReliabilityFlags {
  std::string limit = "two-sided", method = "auto", sensitivities = "auto";
  std::size_t samples = 1u << 14;
  double confidence = 0.95;
  // `weilgen allocate`'s defaults: fewer samples per pose (it recomputes every step).
  static ReliabilityFlags for_allocation() {
    ReliabilityFlags f;
    f.samples = 1u << 13;
    return f;
  }
};
// Parsed and checked (std::invalid_argument naming the flag).
ReliabilitySettings parse_reliability_flags(const ReliabilityFlags& flags, std::uint64_t seed);

// R of every (pose, toleranced output) of a study, for the given error distributions (the
// study's own or an allocation's). Order-1 outputs go to ReliabilityAnalysis as exact linear
// forms, dp and higher orders through the model. Cases ordered tolerance-major: all poses of
// tolerances[0], then tolerances[1], ... `progress(done, total)` after each case.
class ReliabilitySweep {
 public:
  explicit ReliabilitySweep(ReliabilitySettings settings);  // validates the options
  const ReliabilitySettings& settings() const { return settings_; }
  std::vector<SweepCase> run(
      const Study& study, const std::vector<InputDistribution>& inputs,
      const std::function<void(std::size_t, std::size_t)>& progress = {}) const;

 private:
  ReliabilitySettings settings_;
};

// Per tolerance (output): min and mean reliability over the poses and the pose of the minimum.
struct SweepSummary {
  double min = 1, mean = 0;
  std::size_t argmin = 0;
};
std::vector<SweepSummary> summarize(const Study& study, const std::vector<SweepCase>& cases);

// Errors ranked by the mean over the poses of |dR/dsigma_i| * sigma_i (the change of R when the
// spread changes by 100 %), for one toleranced output: (error index, value), largest first.
std::vector<std::pair<std::size_t, double>> ranked_sensitivity(
    const std::vector<SweepCase>& cases, std::size_t tolerance,
    const std::vector<InputDistribution>& inputs);

}  // namespace weilgen
