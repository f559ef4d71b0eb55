// Elements of a Weil algebra R[e_1..e_k] / I over a coefficient ring of GiNaC expressions, and
// 4x4 homogeneous matrices over it.
//
// I is a monomial ideal: all monomials of degree r+1 plus the relation monomials. A product never
// forms a monomial of I ("truncation inside every product"): the pair of terms is skipped before
// its coefficient is multiplied. Coefficients are polynomials in axis coordinates, parameters and
// the symbols cos/sin of revolute coordinates, kept expanded and reduced by cos² = 1 − sin².
#pragma once

#include <ginac/ginac.h>

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "weilgen/codegen/sparse_poly.hpp"

namespace weilgen::gen {

// A monomial e_{i1} e_{i2} ... as the sorted multiset of error indices ({} is the unit 1).
using Monomial = std::vector<std::uint16_t>;

Monomial monomial_product(const Monomial& a, const Monomial& b);
// True when every index of `divisor` occurs in `m` at least as often.
bool divides(const Monomial& divisor, const Monomial& m);

// The quotient: truncation order, relation monomials and the trigonometric reduction rules.
class Algebra {
 public:
  Algebra(int order, std::vector<Monomial> relations, GiNaC::exmap trig_rules);
  int order() const { return order_; }
  // True when m lies in the ideal I (so it is zero in the algebra).
  bool vanishes(const Monomial& m) const;
  // Expands and reduces a coefficient (cos² → 1 − sin²) into canonical polynomial form.
  GiNaC::ex normalize(const GiNaC::ex& c) const;
  const std::vector<Monomial>& relations() const { return relations_; }
  // The fast coefficient arithmetic: c as a SparsePoly over the algebra's atoms, nothing when c
  // is not a polynomial in atoms or the rules are not all symbol² → r (then GiNaC does it).
  std::optional<SparsePoly> to_sparse(const GiNaC::ex& c) const;
  // The normalised coefficient of a SparsePoly (cos² → 1 − sin² on exponents): normalize's result.
  GiNaC::ex from_sparse(const SparsePoly& p) const;
  AtomTable& atoms() const { return atoms_; }

 private:
  int order_;
  std::vector<Monomial> relations_;  // minimal generators besides the degree bound
  GiNaC::exmap trig_rules_;
  GiNaC::exvector trig_bases_;                                // x of every rule x^2 -> ...
  std::vector<std::pair<GiNaC::ex, GiNaC::ex>> squares_;      // (x, r) when every rule is x^2 -> r
  GiNaC::ex reduce_squares(const GiNaC::ex& expanded) const;  // one substitution pass
  bool sparse_ = true;
  mutable AtomTable atoms_;  // grows as coefficients meet new atoms
  // SparsePoly form by coefficient: the products' results come back as their inputs.
  mutable std::unordered_map<GiNaC::ex, SparsePoly, std::hash<GiNaC::ex>, GiNaC::ex_is_equal>
      sparse_of_;
  std::vector<SparsePoly::SquareRule> square_rules_;
};

// An algebra element: Σ coefficient · monomial. Zero coefficients are never stored.
class Poly {
 public:
  using Terms = std::map<Monomial, GiNaC::ex>;

  Poly() = default;
  explicit Poly(const GiNaC::ex& constant);  // constant (degree-0) element
  static Poly error(std::uint16_t index);    // the generator e_index

  bool is_zero() const { return terms_.empty(); }
  const Terms& terms() const { return terms_; }
  GiNaC::ex constant() const;  // degree-0 coefficient
  Poly without_constant() const;
  // The same element with every coefficient c replaced by f(c) (zero results dropped).
  template <typename F>
  Poly mapped(F f) const {
    Poly p;
    for (const auto& [m, c] : terms_) p.add_term(m, f(c));
    return p;
  }
  int min_degree() const;  // of stored monomials; 0 for zero
  // True when the element has no error term (zero or a constant): a nominal quantity.
  bool is_constant() const { return terms_.empty() || (terms_.size() == 1 && min_degree() == 0); }

  Poly operator+(const Poly& o) const;
  Poly operator-(const Poly& o) const;
  Poly operator-() const;
  Poly scaled(const GiNaC::ex& c, const Algebra& alg) const;
  // The truncating product.
  Poly mul(const Poly& o, const Algebra& alg) const;
  // Σ a_k · b_k over the pairs, truncating, with one normalisation per monomial of the result
  // (a matrix product's entry).
  static Poly sum_of_products(const std::vector<std::pair<const Poly*, const Poly*>>& pairs,
                              const Algebra& alg);
  // Σ coefficient · Π error_symbols[i]: the element as an expression.
  GiNaC::ex to_ex(const std::vector<GiNaC::symbol>& error_symbols) const;

 private:
  friend struct Mat4;
  // The terms with SparsePoly coefficients by degree ≤ r; false when one has no SparsePoly form.
  using SparseTerms = std::vector<std::vector<std::pair<const Monomial*, SparsePoly>>>;
  bool to_sparse(const Algebra& alg, SparseTerms& out) const;
  // sum_of_products over coefficients in SparsePoly form: the same truncation, the same sums per
  // monomial, one conversion back per monomial.
  static Poly sparse_sum_of_products(
      const std::vector<std::pair<const SparseTerms*, const SparseTerms*>>& pairs,
      const Algebra& alg);
  void add_term(const Monomial& m, const GiNaC::ex& c);
  Terms terms_;
};

// Σ c_k · Π error_symbols[m_k] in nested (Horner) form: the error that occurs in most terms is
// factored out, recursively, so that every monomial costs about one multiplication and the text
// grows with the number of terms rather than with their degree. Deterministic: ties go to the
// smaller error index.
GiNaC::ex factored_sum(std::vector<std::pair<Monomial, GiNaC::ex>> terms,
                       const std::vector<GiNaC::symbol>& error_symbols);

// A 4x4 matrix over the algebra (homogeneous transforms and their nilpotent parts).
struct Mat4 {
  Poly m[4][4];

  static Mat4 identity();
  static Mat4 zero();
  Mat4 mul(const Mat4& o, const Algebra& alg) const;
  Mat4 operator+(const Mat4& o) const;
  Mat4 operator-(const Mat4& o) const;
  Mat4 constant_part() const;   // degree-0 part (the nominal transform)
  Mat4 nilpotent_part() const;  // everything else
};

// Exact inverse of a rigid transform with degree-0 entries: [Rᵀ, −Rᵀp; 0, 1].
Mat4 rigid_inverse(const Mat4& nominal, const Algebra& alg);
// Inverse of M = M0 + N (M0 rigid, N nilpotent) by the Neumann series
// (I + M0⁻¹N)⁻¹ M0⁻¹ = Σ_{j=0}^{r} (−M0⁻¹N)^j M0⁻¹, finite because (M0⁻¹N)^{r+1} = 0 in the
// algebra.
Mat4 neumann_inverse(const Mat4& m, const Algebra& alg);

// Elementary transforms. `u` is a unit vector of exact coefficients.
Mat4 translation(const GiNaC::ex (&v)[3]);
Mat4 translation_by(const Poly& amount, const GiNaC::ex (&u)[3], const Algebra& alg);
// Rotation by the nominal angle with cosine c and sine s: I + s[u]x + (1 − c)[u]x².
Mat4 rotation_cs(const GiNaC::ex (&u)[3], const GiNaC::ex& c, const GiNaC::ex& s,
                 const Algebra& alg);
// Rotation by a nilpotent angle `angle` (an error): sin and 1 − cos by their series, truncated
// in the algebra (so e.g. e² = 0 relations remove the e²/2 term).
Mat4 rotation_small(const GiNaC::ex (&u)[3], const Poly& angle, const Algebra& alg);

}  // namespace weilgen::gen
