// SparsePoly, the Weil algebra's fast coefficient arithmetic, against GiNaC's expand.
#include <doctest/doctest.h>

#include <random>

#include "weilgen/codegen/sparse_poly.hpp"
#include "weilgen/codegen/weil.hpp"

using namespace weilgen::gen;
using GiNaC::ex;

namespace {
struct Atoms {
  GiNaC::symbol a{"a"}, b{"b"}, x{"x"}, c{"cos(q)"}, s{"sin(q)"}, inv{"_inv0"};
  // Opaque atoms: a constant and a function of a linked angle.
  ex pi = GiNaC::Pi, f = GiNaC::cos(a * GiNaC::Pi / 180);
  std::vector<ex> all() const { return {a, b, x, c, s, inv, pi, f}; }
};

// A random polynomial in the atoms with rational coefficients, in unexpanded form: a sum of
// products of atoms' powers (a symbol's power may be −1) and of small sums.
ex random_poly(const Atoms& at, std::mt19937& rng, int depth = 0) {
  const std::vector<ex> atoms = at.all();
  std::uniform_int_distribution<int> n_terms(1, 4), n_factors(0, 3), pick(0, 7), power(1, 3),
      num(-9, 9), den(1, 6), coin(0, 5);
  ex sum = 0;
  for (int t = n_terms(rng); t > 0; --t) {
    ex term = GiNaC::numeric(num(rng), den(rng));
    for (int k = n_factors(rng); k > 0; --k) {
      const int i = pick(rng);
      const int p = (i < 3 && coin(rng) == 0) ? -1 : power(rng);
      term *= GiNaC::pow(atoms[static_cast<std::size_t>(i)], p);
    }
    if (depth < 1 && coin(rng) == 0) term *= random_poly(at, rng, depth + 1);
    sum += term;
  }
  return sum;
}

ex reduce_reference(const ex& e, const GiNaC::exmap& rules) {
  ex want = e.expand();
  for (int pass = 0; pass < 8; ++pass) {
    const ex next = want.subs(rules, GiNaC::subs_options::algebraic).expand();
    if (next.is_equal(want)) break;
    want = next;
  }
  return want;
}
}  // namespace

TEST_CASE("SparsePoly: products and sums of random polynomials equal GiNaC's expand") {
  const Atoms at;
  AtomTable table;
  std::mt19937 rng(20261125);
  for (int trial = 0; trial < 200; ++trial) {
    const ex p = random_poly(at, rng), q = random_poly(at, rng);
    const auto sp = SparsePoly::from_ex(p, table), sq = SparsePoly::from_ex(q, table);
    REQUIRE(sp);
    REQUIRE(sq);
    CHECK(sp->to_ex(table).is_equal(p.expand()));
    CHECK(sp->mul(*sq, table).to_ex(table).is_equal((p * q).expand()));
    CHECK((*sp + *sq).to_ex(table).is_equal((p + q).expand()));
    // A sum's terms in any order with repeated keys merge to the expanded sum (p − p = 0).
    std::vector<SparsePoly::Term> raw;
    sp->multiply_into(*sq, table, raw);
    sp->multiply_into(SparsePoly(cln::cl_RA(-1)), table, raw);
    sp->multiply_into(SparsePoly(cln::cl_RA(1)), table, raw);
    CHECK(SparsePoly::from_terms(raw).to_ex(table).is_equal((p * q).expand()));
  }
}

TEST_CASE("SparsePoly: cos² → 1 − sin² on exponents equals the repeated algebraic substitution") {
  const Atoms at;
  AtomTable table;
  GiNaC::exmap rules;
  rules[GiNaC::pow(at.c, 2)] = 1 - GiNaC::pow(at.s, 2);
  const std::vector<SparsePoly::SquareRule> sparse_rules{
      {table.index(at.c), *SparsePoly::from_ex(1 - GiNaC::pow(at.s, 2), table)}};
  std::mt19937 rng(17);
  int reduced = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const ex p = random_poly(at, rng) * random_poly(at, rng);
    const ex want = reduce_reference(p, rules);
    const ex got = SparsePoly::from_ex(p, table)->reduced(sparse_rules, table).to_ex(table);
    CHECK(got.is_equal(want));
    CHECK(got.degree(at.c) <= 1);
    reduced += !want.is_equal(p.expand());
  }
  CHECK(reduced > 20);  // the rule did act on many of them
}

TEST_CASE("SparsePoly: no form for what is not a polynomial in atoms") {
  const Atoms at;
  AtomTable table;
  CHECK_FALSE(SparsePoly::from_ex(GiNaC::sqrt(ex(2)) * at.a, table));
  CHECK_FALSE(SparsePoly::from_ex(GiNaC::pow(at.a + at.b, -1), table));
  CHECK_FALSE(SparsePoly::from_ex(ex(0.5) * at.a, table));
  // A monomial's inverse is one: (2a²)⁻¹ · a = 1/(2a).
  const auto m = SparsePoly::from_ex(GiNaC::pow(2 * GiNaC::pow(at.a, 2), -1) * at.a, table);
  REQUIRE(m);
  CHECK(m->to_ex(table).is_equal(GiNaC::pow(2 * at.a, -1)));
}

TEST_CASE(
    "Poly products over SparsePoly coefficients: truncation and cos² as the GiNaC expansion") {
  const Atoms at;
  GiNaC::exmap rules;
  rules[GiNaC::pow(at.c, 2)] = 1 - GiNaC::pow(at.s, 2);
  const Algebra alg(2, {{0, 1}}, rules);  // order 2, e0·e1 = 0
  const GiNaC::symbol e0("e0"), e1("e1");
  const std::vector<GiNaC::symbol> es{e0, e1};
  std::mt19937 rng(5);
  const std::vector<Monomial> monomials{{}, {0}, {1}, {0, 0}, {1, 1}};
  for (int trial = 0; trial < 20; ++trial) {
    Poly p, q;
    for (const Monomial& m : monomials) {
      Poly t(random_poly(at, rng)), u(random_poly(at, rng));
      for (auto i : m) {
        t = t.mul(Poly::error(i), alg);
        u = u.mul(Poly::error(i), alg);
      }
      p = p + t;
      q = q + u;
    }
    const Poly pq = p.mul(q, alg);
    const ex full = (p.to_ex(es) * q.to_ex(es)).expand();
    for (const Monomial& m : monomials) {
      ex want = full;
      for (int i = 0; i < 2; ++i) {
        const int k = static_cast<int>(std::count(m.begin(), m.end(), i));
        want = want.coeff(es[static_cast<std::size_t>(i)], k);
      }
      want = reduce_reference(want, rules);
      const auto it = pq.terms().find(m);
      CHECK((it == pq.terms().end() ? ex(0) : it->second).is_equal(want));
    }
    CHECK(pq.terms().count({0, 1}) == 0);  // the relation: never formed
    CHECK(pq.terms().count({0, 0, 1}) == 0);
  }
}
