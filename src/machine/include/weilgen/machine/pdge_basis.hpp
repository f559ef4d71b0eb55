// Basis functions for position-dependent geometric errors (PDGEs) on an axis travel [a, b]
// (mm; deg for a rotary axis): polynomial, Fourier, Legendre and Chebyshev. A `Basis` is a plain
// value: it evaluates its terms at a position without allocating, names itself ("poly:3",
// "fourier:2", "legendre:4", "chebyshev:4") and converts polynomial-family coefficients to
// physical power-series coefficients (µm/mm^k). The spelling parsed by `parse_basis` is the one
// of `weilgen fit-pdge --basis` and `weilgen identify --pdge E_YY=fourier:3`. docs/fit-pdge.md.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

namespace weilgen {

enum class BasisKind { Polynomial, Fourier, Legendre, Chebyshev };

// "poly", "fourier", "legendre", "chebyshev".
const char* basis_kind_name(BasisKind kind);

// The terms of each kind, with u = (2x - a - b) / (b - a) in [-1, 1] on the travel:
//   Polynomial (degree n):  1, u, u^2, ..., u^n                         n + 1 terms
//   Legendre   (degree n):  P_0(u), ..., P_n(u)                         n + 1 terms
//   Chebyshev  (degree n):  T_0(u), ..., T_n(u)                         n + 1 terms
//   Fourier    (order n):   1, cos(2πx/L), sin(2πx/L), ..., cos(2πnx/L), sin(2πnx/L)
//                           2n + 1 terms; x is the axis position itself (not u) and L the
//                           period (the travel b - a unless period_mm is set; period_mm is in
//                           the axis' unit: mm, or deg for a rotary axis).
// The three polynomial kinds span the same functions at the same degree (identical fits);
// they differ in conditioning and in what the coefficients mean.
struct Basis {
  BasisKind kind = BasisKind::Polynomial;
  int order = 0;           // degree (polynomial kinds) or number of harmonics (Fourier)
  double a = 0, b = 1;     // travel [a, b], a < b
  double period_mm = NAN;  // Fourier only; NaN = the travel b - a

  // Validated construction: throws std::invalid_argument for a zero-length or non-finite
  // travel ("travel [0, 0] mm has zero length"), a negative order or a period <= 0.
  static Basis make(BasisKind kind, int order, double a, double b, double period_mm = NAN);
  // Throws like make() when the fields are inconsistent.
  void validate() const;

  std::size_t size() const;  // number of terms (coefficients)
  std::string name() const;  // "poly:3", "fourier:2", "fourier:2:20" (explicit period, mm)
  double period() const;     // the Fourier period in use (b - a when period_mm is NaN)
  double scaled(double x) const { return (2 * x - a - b) / (b - a); }  // u

  // The size() terms at x into out[0 .. size()-1]; no allocation, no checks.
  void evaluate(double x, double* out) const;
  // The basis expansion sum_k c[k] * term_k(x); c has size() entries.
  double value(const double* c, double x) const;

  // Human-readable term names: "1", "u", "u^2" / "P2(u)" / "T2(u)" / "cos(2pi*1*x/L)".
  std::vector<std::string> term_names() const;

  // Polynomial kinds: the coefficients d_j of the same function as a power series in the
  // physical position, f(x) = sum_j d_j x^j (unit of y per mm^j). Throws std::invalid_argument
  // for Fourier. Conversion only: for high degrees on long travels the d_j span many decades.
  std::vector<double> power_coefficients(const std::vector<double>& c) const;
};

// A basis as spelled on the command line, before it is placed on a travel.
//   KIND[:ORDER[:PERIOD]]   KIND poly|polynomial|fourier|legendre|chebyshev|cheb
//                           ORDER a whole number >= 0, or "auto" (order chosen by
//                           cross-validation; only when allowed); missing = auto when allowed
//                           PERIOD (Fourier only) a length in mm ("20", "20mm") or "auto"
struct BasisSpec {
  BasisKind kind = BasisKind::Polynomial;
  int order = -1;              // -1 = auto
  double period_mm = NAN;      // Fourier: NaN = not given
  bool period_search = false;  // Fourier: PERIOD was "auto"

  bool auto_order() const { return order < 0; }
  std::string str() const;  // canonical spelling: "poly:3", "fourier:auto:auto", "fourier:2:20"
  // The basis on [a, b]; the order must be set and the period not "auto" (throws
  // std::invalid_argument otherwise, and for a zero-length travel).
  Basis on(double a, double b) const;
};

// Parses "fourier:3", "poly:7", "legendre:auto", "fourier:2:20mm". Throws std::invalid_argument
// with a message quoting the text, e.g. `basis "foo:3": unknown kind "foo" (expected poly,
// fourier, legendre or chebyshev, e.g. poly:3)` or, when allow_auto is false, `basis "poly": the
// order is missing: give a whole number (e.g. poly:3)`.
BasisSpec parse_basis(const std::string& text, bool allow_auto = false);

// The largest order the kind supports with `points` distinct positions (size() <= points), or
// -1 when even order 0 does not fit.
int max_order_for_points(BasisKind kind, std::size_t points);

// Number of terms of `kind` at `order`.
std::size_t basis_size(BasisKind kind, int order);

// The basis of a PDGE of joint `j` when neither a flag nor the machine file chooses one:
// "poly:3" on a linear axis; "fourier:2" on a rotary axis, whose errors repeat every turn
// (placed by basis_on_joint with one turn as its period).
std::string default_pdge_basis(const Joint& j);

// `spec` on the joint's travel [min, max] (its unit); a Fourier basis without a period takes one
// turn on a rotary axis (360 deg, 2π rad) and the travel on a linear one. Throws like
// BasisSpec::on.
Basis basis_on_joint(const BasisSpec& spec, const Joint& j);

}  // namespace weilgen
