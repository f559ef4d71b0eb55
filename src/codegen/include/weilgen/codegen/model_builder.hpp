// Description → symbolic error model over the Weil algebra.
#pragma once

#include <ginac/ginac.h>

#include <array>
#include <string>
#include <vector>

#include "weilgen/codegen/weil.hpp"
#include "weilgen/machine/description.hpp"
#include "weilgen/machine/outputs.hpp"

namespace weilgen::gen {

struct AxisSymbols {
  int body = -1;
  GiNaC::symbol coordinate;  // the joint variable in its unit (mm, deg, ...)
  GiNaC::symbol cos, sin;    // revolute only: cos/sin of the angle in rad
  bool revolute = false;
};

// 1/divisor of a derived ratio, as a symbol: coefficients stay polynomials (GiNaC would
// otherwise choose the sign of a divisor by hash order, which varies between runs), and generated
// code computes each reciprocal once. `divisor` has the sign CanonicalText chooses.
struct Reciprocal {
  GiNaC::symbol symbol;  // "_inv0", "_inv1", ...
  GiNaC::ex divisor;     // over coordinates and parameters
};

struct SymbolicModel {
  Description desc;
  int order = 1;
  std::vector<Monomial> relations;  // minimal relation monomials (besides degree > order)
  std::vector<AxisSymbols> axes;    // in Description::axes() order
  std::vector<GiNaC::symbol> errors;
  std::vector<GiNaC::symbol> params;
  std::array<Poly, kNumDeviationOutputs>
      outputs;                          // deviation, as algebra elements (no constant term)
  std::vector<Reciprocal> reciprocals;  // symbols standing for 1/divisor in coefficients
  // The nominal pose P0 (every error zero): rows 0..2 of the 4x4 transform, R0 | p0, over the
  // coordinates, their cos/sin symbols and the parameters.
  std::array<std::array<GiNaC::ex, 4>, 3> nominal;
  // d(nominal output)/d(axis) in base units (per mm, per rad), row-major [output][axis], axes in
  // `axes` order: position rows dp0/dq, orientation rows vee(dR0/dq · R0ᵀ) (the convention of
  // the orientation outputs, ΔR = R·R0ᵀ). A derivative by the GiNaC differentiation of the chain.
  std::vector<GiNaC::ex> nominal_jacobian;
  // True when some axis turns the output frame (an orientation row of nominal_jacobian is not
  // identically zero): Compensate then weighs orientation rows too.
  bool axes_turn_output() const;

  // c with each reciprocal symbol replaced by 1/divisor: for printing and numeric evaluation.
  GiNaC::ex with_divisors(const GiNaC::ex& c) const;

  // Coefficient of a monomial in output o (0 when absent).
  GiNaC::ex coefficient(int o, const Monomial& m) const;
  // All monomials of degree >= 2 that appear in some output, sorted by degree then indices.
  std::vector<Monomial> higher_monomials() const;
  // Monomial as text with error names: "E_AX·E_BY", "E_AX^2".
  std::string monomial_name(const Monomial& m) const;
};

// Builds the model; order_override > 0 replaces the file's algebra order.
SymbolicModel build_model(const Description& desc, int order_override = 0);

// Exact rational for a decimal double (0.1 → 1/10): the shortest decimal that round-trips.
GiNaC::numeric exact_decimal(double v);
// Expr (machine file scalar) → GiNaC, with parameters mapped to `params` by name.
GiNaC::ex to_ginac(const Expr& e, const Description& desc,
                   const std::vector<GiNaC::symbol>& params);

}  // namespace weilgen::gen
