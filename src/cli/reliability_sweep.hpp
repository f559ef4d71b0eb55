// Reliability of every (pose, toleranced output) of a study: the sweep behind
// `weilgen reliability` and `weilgen allocate`. Order-1 components are passed to the engine as
// exact linear forms (so `auto` is exact for Gaussian errors); dp and higher orders go through
// the model itself.
#pragma once

#include <string>
#include <vector>

#include "study.hpp"
#include "weilgen/uq/reliability.hpp"

namespace weilgen::cli {

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

// The reliability flags shared by `reliability` and `allocate`: --limit --method --samples
// --confidence --sensitivities.
struct ReliabilityFlags {
  std::string limit = "two-sided", method = "auto", sensitivities = "auto";
  std::size_t samples = 1u << 14;
  double confidence = 0.95;
};
void add_reliability_options(boost::program_options::options_description& opts,
                             ReliabilityFlags& flags);
// Parsed and checked (std::invalid_argument on bad values); threads are set by the caller.
struct ReliabilitySettings {
  LimitChoice limit;
  SensitivityChoice sensitivities;
  ReliabilityOptions options;
};
ReliabilitySettings parse_reliability_flags(const ReliabilityFlags& flags, std::uint64_t seed);

// Cases ordered tolerance-major: all poses of tolerances[0], then tolerances[1], ...
std::vector<SweepCase> reliability_sweep(const Study& study,
                                         const std::vector<InputDistribution>& inputs,
                                         LimitChoice limit, const ReliabilityOptions& options,
                                         SensitivityChoice sensitivities, bool quiet);

// Per tolerance (output): min and mean reliability over the poses and the pose of the minimum.
struct SweepSummary {
  double min = 1, mean = 0;
  std::size_t argmin = 0;
};
std::vector<SweepSummary> summarize(const Study& study, const std::vector<SweepCase>& cases);

}  // namespace weilgen::cli
