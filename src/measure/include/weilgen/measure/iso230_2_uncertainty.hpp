// The measurement uncertainty of the ISO 230-2 figures, after ISO 230-9 and the GUM (JCGM
// 100:2008): a budget of contributions (the instrument, the air compensation, the material's
// temperature and expansion coefficient, the cosine and Abbe errors, the dead path, the
// environmental variation, the resolution and the run's own repeatability), each with its
// distribution, propagated to E, M, A, B, R (and every other figure a tolerance may limit) by
// their sensitivities, combined and expanded with k = 2; and the same budget propagated by Monte
// Carlo (GUM Supplement 1, JCGM 101:2008) through the figures themselves. Method, defaults per
// instrument class and the budget file: docs/iso230-2.md, "Measurement uncertainty".
//
// Every contribution acts on the per-target means x̄_i and estimators s_i the figures are made of
// (iso_figures), in one of four ways:
//   Scale      an error proportional to the travel from the datum, common to every reading
//              (instrument calibration, air sensors, material temperature and coefficient, cosine
//              error): x̄_i += c (P_i − P0)/1000, c in µm/m;
//   PerTarget  independent at each target, the same for both directions (Abbe error);
//   PerMean    independent for each target and direction (environmental variation, dead path,
//              resolution, the instrument's constant part);
//   TypeA      the run's own scatter: x̄_i ± s_i/√n and s_i ± s_i √(1 − c4(n)²), the exact
//              standard deviations of a normal sample's mean and standard deviation.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "weilgen/measure/iso230_2.hpp"
#include "weilgen/measure/normalisation.hpp"

namespace weilgen {

// The inputs of a budget: an instrument class whose defaults hold for every key not given
// ("auto": laser-edlen when weilgen corrected the air, else laser-compensated), and the keys
// given (docs/iso230-2.md lists them with their units and distributions).
struct UncertaintyBudget {
  std::string instrument_class = "auto";
  std::map<std::string, double> values;  // key -> value, in the key's unit
  std::string source = "defaults";       // the budget file, or "defaults"
  void validate() const;                 // known class and keys, values >= 0 (invalid_argument)
};

// The classes: laser-compensated, laser-edlen, laser-manual, scale.
const std::vector<std::string>& uncertainty_classes();
// Every key of a budget with its default for `instrument_class` (throws for an unknown class).
std::map<std::string, double> uncertainty_defaults(const std::string& instrument_class);
// "auto", a class name, or a budget file (YAML: `class:` and any keys); InputError
// "file:line:column: message" for a bad file, std::invalid_argument naming --uncertainty.
UncertaintyBudget parse_uncertainty_budget(const std::string& text, const std::string& file);
UncertaintyBudget uncertainty_budget_from_flag(const std::string& flag);

enum class ContributionKind { Scale, PerTarget, PerMean, TypeA };
enum class BudgetDistribution { Normal, Rectangular, OneSided };
const char* to_string(ContributionKind kind);            // "scale", "per target", ...
const char* to_string(BudgetDistribution distribution);  // "normal", "rectangular", ...

struct UncertaintyContribution {
  std::string name;   // "instrument calibration", "air temperature sensor" ...
  std::string input;  // the input as the budget gives it: "0.5 um/m (k = 2)"
  BudgetDistribution distribution = BudgetDistribution::Normal;
  ContributionKind kind = ContributionKind::Scale;
  double u = std::numeric_limits<double>::quiet_NaN();  // standard uncertainty, in `unit`
  std::string unit;  // "um/m" (Scale) or "um"; "" for TypeA (a u per target)
  // Per figure ("E", "M", "A", "B", "R", "E_up" ..., "band"): the sensitivity c (µm per unit of
  // u; for independent kinds the root sum of squares over the targets) and |c| u in µm.
  std::map<std::string, double> sensitivity, contribution_um;
};

struct FigureUncertainty {
  std::string name;  // "E" ...
  double value = 0;  // the figure (µm or µrad)
  double u = 0;      // combined standard uncertainty
  double U = 0;      // expanded, k × u
  // Monte Carlo: the standard deviation and the 95 % probabilistically symmetric interval of the
  // propagated distribution; NaN without trials.
  double mc_u = std::numeric_limits<double>::quiet_NaN();
  double mc_low = std::numeric_limits<double>::quiet_NaN();
  double mc_high = std::numeric_limits<double>::quiet_NaN();
  // The Monte Carlo's u within 5 % of the linearised one (GUM Supplement 1, 8): false where an
  // extreme of the figure switches between targets under the perturbations; the ISO 14253-1
  // decisions use U either way, the documents say which figures are not validated.
  bool validated = false;
};

struct UncertaintyResult {
  std::string instrument_class, source;
  double coverage_factor = 2;
  std::vector<UncertaintyContribution> contributions;
  std::vector<FigureUncertainty> figures;  // E, M, A, B, R, then E_up ... B_mean, band
  std::size_t trials = 0;
  std::uint64_t seed = 0;
  std::vector<std::string> notes;  // what the budget leaves out or assumes
  const FigureUncertainty* figure(const std::string& name) const;  // nullptr when absent
};

// The figures the budget reports, in order, and their values from per-target means and s (the
// band is the worst |x̄ ± k s|, B_mean its absolute value, as the tolerance checks read them).
const std::vector<std::string>& uncertainty_figure_names();
std::map<std::string, double> uncertainty_figure_values(const IsoFigures& figures);

class Iso230_2Uncertainty {
 public:
  explicit Iso230_2Uncertainty(UncertaintyBudget budget);  // validates
  const UncertaintyBudget& budget() const { return budget_; }
  // `classical` is the k = 2 evaluation of `runs`; `normalisation` says what was corrected and
  // the environment; `unit` the deviation unit ("um" or "urad").
  UncertaintyResult run(const IsoRuns& runs, const IsoFigures& classical,
                        const NormalisationResult& normalisation, const std::string& unit) const;

 private:
  UncertaintyBudget budget_;
};

}  // namespace weilgen
