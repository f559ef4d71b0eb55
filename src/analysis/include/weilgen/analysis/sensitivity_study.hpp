// The sensitivity of every output to every error at every pose of a study: local coefficients
// and contributions, the exact indices of the linear model, and Sobol' indices sampled through
// the model (first order and total, with their confidence intervals). Method: docs/sensitivity.md.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "weilgen/analysis/study.hpp"
#include "weilgen/base/constants.hpp"
#include "weilgen/machine/outputs.hpp"
#include "weilgen/uq/sobol_indices.hpp"

namespace weilgen {

struct SensitivityOptions {
  bool local = true, exact = true, sobol = true;  // which methods
  std::vector<OutputId> outputs = all_outputs();  // dp: sampling only
  SobolOptions sobol_options;                     // samples, sampling, seed, intervals, ...

  // Throws std::invalid_argument naming the flag: at least one method and one output, no
  // output twice, --confidence in (0, 1), and the Sobol' options (--samples >= 2) when sampling.
  void validate() const;
};

// "local" | "exact" | "sobol" | "all" into the three method switches; std::invalid_argument
// naming --method otherwise.
void parse_sensitivity_method(const std::string& text, SensitivityOptions& options);
// "dx,dy,dp": each output once; std::invalid_argument naming --outputs otherwise.
std::vector<OutputId> parse_output_list(const std::string& text);
// "qmc" | "mc"; std::invalid_argument naming --sampling otherwise.
Sampling parse_sampling(const std::string& text);
// The interval flags into `options` (whose samples, sampling and seed are already set):
// --bootstrap B (B >= 0; 0 = no intervals) selects the bootstrap, --replicates R (2..1024) the
// randomised replicates, neither the replicates with their default R; both is an error. Checks
// that N is a multiple of R with N/R >= 2 and that QMC replicates have a seed != 0; throws
// std::invalid_argument naming the flag otherwise. Negative values are given as such.
void set_sobol_intervals(SobolOptions& options, const long long* replicates,
                         const long long* bootstrap);

struct SensitivityRecord {     // one pose, output and error; NaN where not computed
  double coefficient = kNaN;   // c: output unit (mm, rad) per base unit of the error (mm, rad)
  double contribution = kNaN;  // c·σ, output unit
  double S = kNaN, S_lo = kNaN, S_hi = kNaN;     // first-order index and its interval
  double ST = kNaN, ST_lo = kNaN, ST_hi = kNaN;  // total index and its interval
  double S_exact = kNaN;                         // c²σ² / Σ c²σ² (linear model)
};

struct SensitivitySummary {             // one pose and output
  double mean = kNaN, variance = kNaN;  // sampled (output unit, unit²)
  double variance_linear = kNaN;        // Σ c²σ² (unit²)
};

struct SensitivityResult {
  std::vector<OutputId> outputs;
  std::size_t poses = 0, errors = 0;
  std::vector<SensitivityRecord> records;   // [pose][output][error]
  std::vector<SensitivitySummary> summary;  // [pose][output]
  std::size_t evaluations = 0;              // model evaluations for the Sobol' indices
  double confidence = 0.95;                 // of every interval
  SobolIntervals intervals = SobolIntervals::Replicates;  // where the intervals come from
  std::size_t replicates = 1;  // randomised replicates behind the Sobol' estimates
  std::size_t bootstrap = 0;   // bootstrap resamples behind the intervals (0 unless bootstrap)

  const SensitivityRecord& at(std::size_t pose, std::size_t output, std::size_t error) const {
    return records[(pose * outputs.size() + output) * errors + error];
  }
  const SensitivitySummary& summary_at(std::size_t pose, std::size_t output) const {
    return summary[pose * outputs.size() + output];
  }
};

class SensitivityStudy {
 public:
  explicit SensitivityStudy(SensitivityOptions options);  // validates the options
  const SensitivityOptions& options() const { return options_; }

  // `progress(done, total)` after each pose of the sampled indices (may be empty).
  SensitivityResult run(const Study& study,
                        const std::function<void(std::size_t, std::size_t)>& progress = {}) const;

 private:
  SensitivityOptions options_;
};

}  // namespace weilgen
