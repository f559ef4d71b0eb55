// Tolerance files: the distributions of a machine's errors, kept apart from the machine file so a
// study (or `weilgen allocate`) can state or save a set of tolerances. Same distribution syntax as
// the machine file (machines/README.md) plus `const`; the format is in docs/study-inputs.md:
//
//   weilgen_tolerances: 1
//   machine: gantry_grinder                        # optional; must match the machine
//   groups:                                        # optional, every error of a group
//     straightness: {sigma: 2, unit: um}
//   errors:                                        # optional, by error name or alias
//     E_XX: {sigma: 0.005, unit: mm}
//     E_BX: {normal: [0, 1], unit: urad}
//     E_CX: {const: 3, unit: urad}
//
// `errors` entries override `groups` entries. Problems throw InputError "file:line:col: ...".
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/uq/distribution.hpp"

namespace weilgen {

// Distributions set by the file, in BASE units (mm, rad), indexed like Description::errors
// (nullopt: the file does not mention the error).
using ToleranceOverrides = std::vector<std::optional<InputDistribution>>;

ToleranceOverrides read_tolerance_file(const std::string& path, const Description& desc);
// Same, from YAML text; `filename` is used in messages.
ToleranceOverrides read_tolerance_text(const std::string& yaml, const std::string& filename,
                                       const Description& desc);

// Fixed error values from a tolerance file (YAML or its JSON spelling) whose entries are all
// `const`: base units (mm, rad), kErrors order, 0 for errors the file does not mention. A
// distribution that is not constant is an InputError naming the file, the error's line and the
// error (a compensation needs values, not spreads). `weilgen linuxcnc --params`.
std::vector<double> read_error_values(const std::string& path, const Description& desc);

// The text write_tolerance_file writes: every error by name, values in its declared unit
// (sigma / normal / uniform / truncnormal / const), `header_comment` as leading "# " lines.
// Reading it back gives the same distributions to within 1e-15 relative (each value is printed
// with the fewest digits that do, so 0.06/6000 rad reads 1e-05). Throws std::invalid_argument
// when the sizes differ.
std::string tolerance_file_text(const Description& desc,
                                const std::vector<InputDistribution>& base_unit_distributions,
                                const std::string& header_comment);
// Writes tolerance_file_text atomically (atomic_file.hpp). Throws std::runtime_error on I/O errors.
void write_tolerance_file(const std::string& path, const Description& desc,
                          const std::vector<InputDistribution>& base_unit_distributions,
                          const std::string& header_comment);

// The factor from error `err`'s declared unit to base units, from ErrorDef::unit (the loader leaves
// ErrorDef::to_base at 1 for `errors: iso` errors whose unit comes from error_defaults); falls back
// to ErrorDef::to_base when the unit is empty or unknown.
double error_to_base(const ErrorDef& err);

// A machine-file Distribution (values in the error's unit) in base units: values * to_base.
// nullopt for Kind::None. Throws std::invalid_argument when InputDistribution rejects it.
std::optional<InputDistribution> to_base_distribution(const Distribution& d, double to_base);

// The distribution of -X when X has distribution d (an alias with sign -1).
InputDistribution negated(const InputDistribution& d);

}  // namespace weilgen
