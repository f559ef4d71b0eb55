// Exact polynomials over a small list of atoms, the fast coefficient arithmetic of the Weil
// algebra's truncated products.
//
// A GiNaC coefficient (parameters, coordinates, cos/sin symbols, reciprocal symbols and any
// non-polynomial subexpression such as Pi or cos(linked angle), each an opaque "atom") becomes a
// sorted list of terms: rational coefficient · Π atom^k (k may be negative for a symbol, as
// GiNaC's x⁻¹·x = 1). Products and sums then cost merges of small integer vectors instead of
// GiNaC's expand of products of sums; cos² → 1 − sin² acts on exponents. Converting back builds
// the expanded sum, which GiNaC canonicalises to the same expression that expand would give.
#pragma once

#include <cln/rational.h>
#include <ginac/ginac.h>

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

namespace weilgen::gen {

// One monomial Π atom^exp: factors packed as (atom << 16) | (exp + 32768), sorted by atom, exp !=
// 0.
using AtomKey = std::vector<std::uint32_t>;

// The atoms and monomials met so far, numbered in order of appearance (the numbering never
// reaches the output: converting back yields GiNaC's canonical form). Monomials are interned, so
// a term is an id and a product of monomials is one table look-up after its first computation.
class AtomTable {
 public:
  AtomTable();
  std::uint16_t index(const GiNaC::ex& atom);
  const GiNaC::ex& atom(std::uint16_t i) const { return atoms_[i]; }
  std::uint32_t key_id(AtomKey key);  // 0 is the unit monomial
  const AtomKey& key(std::uint32_t id) const { return keys_[id]; }
  std::uint32_t product(std::uint32_t a, std::uint32_t b);
  // The monomial as GiNaC's canonical product (1 for the unit), built once per monomial.
  const GiNaC::ex& monomial(std::uint32_t id) const;

 private:
  struct KeyHash {
    std::size_t operator()(const AtomKey& k) const;
  };
  std::vector<GiNaC::ex> atoms_;
  std::map<GiNaC::ex, std::uint16_t, GiNaC::ex_is_less> index_;
  std::vector<AtomKey> keys_;
  std::unordered_map<AtomKey, std::uint32_t, KeyHash> key_ids_;
  std::unordered_map<std::uint64_t, std::uint32_t> products_;
  mutable std::vector<GiNaC::ex> monomials_;  // by key id; empty until first asked
};

class SparsePoly {
 public:
  struct Term {
    std::uint32_t key;  // AtomTable::key_id
    cln::cl_RA coeff;   // non-zero
  };
  // atom → r: the rule atom² = r, applied to every power ≥ 2 of the atom.
  using SquareRule = std::pair<std::uint16_t, SparsePoly>;

  SparsePoly() = default;
  explicit SparsePoly(const cln::cl_RA& c);
  static SparsePoly atom(std::uint16_t index, AtomTable& atoms, int exp = 1);
  // Nothing when `e` is not a polynomial in atoms with rational coefficients (a non-integer
  // power, a negative power of a sum, a floating-point number).
  static std::optional<SparsePoly> from_ex(const GiNaC::ex& e, AtomTable& atoms);
  // Sorts and merges terms in any order, with repeated keys (a sum of products' raw terms).
  static SparsePoly from_terms(std::vector<Term> terms);
  GiNaC::ex to_ex(const AtomTable& atoms) const;

  bool is_zero() const { return terms_.empty(); }
  const std::vector<Term>& terms() const { return terms_; }
  SparsePoly mul(const SparsePoly& o, AtomTable& atoms) const;
  SparsePoly operator+(const SparsePoly& o) const;
  // Appends the product's unmerged terms to `out` (for from_terms).
  void multiply_into(const SparsePoly& o, AtomTable& atoms, std::vector<Term>& out) const;
  // Every atom^k (k ≥ 2) of a rule's atom replaced by atom^(k mod 2) · r^(k div 2).
  SparsePoly reduced(const std::vector<SquareRule>& rules, AtomTable& atoms) const;

  // True when every atom is a GiNaC symbol and every exponent positive: a polynomial over the
  // rationals as GiNaC::divide takes it (the precondition of degree and divide_exact).
  bool symbols_only(const AtomTable& atoms) const;
  // The highest exponent of `atom` over the terms (0 when absent).
  int degree(std::uint16_t atom, const AtomTable& atoms) const;
  // Exact division: true and q with *this = d·q when d divides *this, else false (q untouched).
  // Multivariate division by lex order on atom numbers; the first leading term that d's does not
  // divide proves a non-zero remainder, so a failing division stops there.
  bool divide_exact(const SparsePoly& d, AtomTable& atoms, SparsePoly& q) const;

 private:
  std::vector<Term> terms_;  // sorted by key, merged
};

// A reciprocal symbol's atom and its divisor D (expanded), in the order the model numbers them.
struct SparseReciprocal {
  std::uint16_t atom;
  SparsePoly divisor;
};

// The fraction form of c (ModelBuilder's as_fraction) over polynomials in symbols: with the
// reciprocals r_i = 1/D_i present in c, c = N / Π D_i^K_i, N = Σ_k a_k D_i^(K_i−k) divisor by
// divisor; each D_i is divided out of N while it divides exactly. The polynomial N, or N·r_i over
// one remaining D_i; nothing when c stays as it is (several divisors left, or a power of one).
// c and every divisor must be symbols_only.
std::optional<SparsePoly> over_divisors(const SparsePoly& c,
                                        const std::vector<SparseReciprocal>& present,
                                        AtomTable& atoms);

}  // namespace weilgen::gen
