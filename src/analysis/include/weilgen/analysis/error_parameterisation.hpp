// How error parameters θ (each in its error's declared unit) give the machine's error values at a
// pose: every PIGE (or error on a body without a joint) one constant; every PDGE the coefficients
// of a basis (machine/pdge_basis.hpp) in the position of its own joint, on that joint's travel.
// identify estimates θ, gap extends it, plan designs measurements for it (docs/identify.md).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/machine/pdge_basis.hpp"

namespace weilgen {

// Which basis each PDGE uses. Precedence: a per-error override, then the run-wide override,
// then the error's `basis:` in the machine file, then the machine's `pdge_basis:` for the joint's
// type, then `fallback` (empty: default_pdge_basis, poly:3 on a linear axis and fourier:2 over
// one turn on a rotary one).
struct PdgeBasisChoice {
  std::string fallback;
  std::optional<std::string> all;                              // --pdge poly:3
  std::vector<std::pair<std::string, std::string>> per_error;  // --pdge E_YY=fourier:3
};

// Parses --pdge values: "poly:3" (all PDGEs) or "E_YY=fourier:3" (an error or alias name).
// Throws std::invalid_argument naming the flag.
PdgeBasisChoice parse_pdge_flags(const Description& desc, const std::vector<std::string>& flags,
                                 PdgeBasisChoice base = {});

// One identified parameter: a basis coefficient of one error (or the error itself).
struct IdentParameter {
  int error = -1;        // index into Description::errors
  std::size_t term = 0;  // basis term index (0 for constants)
  std::string label;     // "E_XX[u^2]", "E_C0Y"
  std::string unit;      // the error's declared unit (µm, µrad, ...)
};

// How parameters θ (each in its error's declared unit) give error values at a pose.
class ErrorParameterisation {
 public:
  // `parameters`: the machine parameters (Description::parameters order, mm/deg) used for linked
  // coordinates; empty = the file's defaults.
  ErrorParameterisation(const Description& desc, const PdgeBasisChoice& choice,
                        std::vector<double> parameters = {});

  std::size_t size() const { return params_.size(); }
  const std::vector<IdentParameter>& parameters() const { return params_; }
  // The basis of error k, or nullopt when the error is a single constant.
  const std::optional<Basis>& basis_of(std::size_t k) const { return bases_[k]; }
  // The position (joint unit) that error k's basis is evaluated at, for a pose of the
  // independent axes (Description::axes() order) and the machine parameters.
  double position_of(std::size_t k, const double* axes) const;
  // Fills d errors / d θ for the pose: for each parameter p, errors[params[p].error] gets
  // jac[p] per unit of θ_p, in base units (mm or rad). jac has size().
  void derivatives(const double* axes, double* jac) const;
  // Error values in base units (mm, rad), Description::errors order.
  void errors_at(const double* axes, const double* theta, double* errors) const;
  // The joint coordinate each error's basis runs along ("X"), or "" for constants.
  const std::string& coordinate_of(std::size_t k) const { return coordinate_[k]; }

 private:
  const Description* desc_;
  std::vector<IdentParameter> params_;
  std::vector<std::optional<Basis>> bases_;
  std::vector<std::size_t> first_;  // first parameter of each error
  std::vector<int> axis_index_;     // index into axes of the error's coordinate, -1 if linked
  std::vector<std::string> coordinate_;
  std::vector<double> param_values_;  // machine parameters for linked coordinates
  std::vector<double> to_base_;       // declared unit → base unit, per error
};

}  // namespace weilgen
