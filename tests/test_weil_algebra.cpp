// The Weil algebra R[e_1..e_k]/I and matrices over it.
#include <doctest/doctest.h>

#include "weilgen/codegen/weil.hpp"

using namespace weilgen::gen;
using GiNaC::ex;

namespace {
const Algebra& plain(int order) {
  static std::map<int, Algebra> cache;
  return cache.try_emplace(order, order, std::vector<Monomial>{}, GiNaC::exmap{}).first->second;
}
Poly pow_of(const Poly& p, int n, const Algebra& alg) {
  Poly r(1);
  for (int i = 0; i < n; ++i) r = r.mul(p, alg);
  return r;
}
}  // namespace

TEST_CASE("D^r_k: products above the order vanish, the rest is the binomial expansion") {
  const Poly e1 = Poly::error(0);
  const Poly x = Poly(1) + e1;
  // (1 + e)^3 = 1 + 3e + 3e² + e³ truncated at order 2.
  const Poly c = pow_of(x, 3, plain(2));
  CHECK(c.terms().size() == 3);
  CHECK(c.constant().is_equal(1));
  CHECK(c.terms().at({0}).is_equal(3));
  CHECK(c.terms().at({0, 0}).is_equal(3));
  // Dual numbers: (1 + e)^5 = 1 + 5e.
  const Poly d = pow_of(x, 5, plain(1));
  CHECK(d.terms().size() == 2);
  CHECK(d.terms().at({0}).is_equal(5));
}

TEST_CASE(
    "relations: Hrdina & Vasik 2014's algebra (40), squares vanish but cross products are kept") {
  const Algebra w(2, {{0, 0}, {1, 1}}, {});
  const Poly s = Poly::error(0) + Poly::error(1);
  const Poly sq = s.mul(s, w);  // (e1 + e2)² = 2 e1 e2 when e1² = e2² = 0
  CHECK(sq.terms().size() == 1);
  CHECK(sq.terms().at({0, 1}).is_equal(2));
  CHECK(w.vanishes({0, 0}));
  CHECK_FALSE(w.vanishes({0, 1}));
  CHECK(w.vanishes({0, 1, 1}));
  // A relation of degree above the order is redundant and dropped; a multiple is not minimal.
  const Algebra v(2, {{0, 1}, {0, 1, 2}, {0, 0, 1}}, {});
  CHECK(v.relations().size() == 1);
}

TEST_CASE("small rotations: sin/cos series truncated in the algebra, inverse by negation") {
  const ex u[3] = {0, 0, 1};
  for (int r = 1; r <= 3; ++r) {
    CAPTURE(r);
    const Algebra& alg = plain(r);
    const Mat4 rp = rotation_small(u, Poly::error(0), alg);
    const Mat4 rm = rotation_small(u, -Poly::error(0), alg);
    const Mat4 id = rp.mul(rm, alg);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const Poly diff = id.m[i][j] - Poly(i == j ? 1 : 0);
        CHECK(diff.is_zero());
      }
    // cos e = 1 - e²/2 at order >= 2, 1 at order 1.
    const Poly c = rp.m[0][0];
    CHECK(c.constant().is_equal(1));
    if (r >= 2) CHECK(c.terms().at({0, 0}).is_equal(GiNaC::numeric(-1, 2)));
    if (r == 1) CHECK(c.terms().size() == 1);
  }
}

TEST_CASE("Neumann inverse of a chain with symbolic nominal rotation is exact in the algebra") {
  GiNaC::symbol c("c"), s("s"), q("q");
  GiNaC::exmap trig;
  trig[GiNaC::pow(c, 2)] = 1 - GiNaC::pow(s, 2);
  const Algebra alg(2, {}, trig);
  const ex ux[3] = {1, 0, 0}, uy[3] = {0, 1, 0};
  Mat4 m = rotation_cs(ux, c, s, alg);
  m = m.mul(translation_by(Poly(q) + Poly::error(0), uy, alg), alg);
  m = m.mul(rotation_small(uy, Poly::error(1), alg), alg);
  m = m.mul(rotation_small(ux, Poly::error(2), alg), alg);
  const Mat4 p = neumann_inverse(m, alg).mul(m, alg);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) CHECK((p.m[i][j] - Poly(i == j ? 1 : 0)).is_zero());
}

TEST_CASE("factored_sum: nested form equal to the sum of monomials, with fewer products") {
  const std::vector<GiNaC::symbol> e = {GiNaC::symbol("a"), GiNaC::symbol("b"), GiNaC::symbol("c")};
  const GiNaC::symbol k("k");
  const std::vector<std::pair<Monomial, ex>> terms = {
      {{0}, 3}, {{0, 0}, 2}, {{0, 1}, k}, {{0, 1, 2}, -1}, {{1, 2}, ex(1) / 2}, {{2}, k * k}};
  ex flat = 0;
  for (const auto& [m, c] : terms) {
    ex t = c;
    for (auto i : m) t *= e[i];
    flat += t;
  }
  const ex nested = factored_sum(terms, e);
  CHECK((nested - flat).expand().is_zero());
  // a occurs in four terms and is factored out first, b then c in what is left:
  // a·(3 + 2a + b·(k − c)) + c·(b/2 + k²): two top-level terms instead of six.
  REQUIRE(GiNaC::is_a<GiNaC::add>(nested));
  CHECK(nested.nops() == 2);
  CHECK(nested.expand().nops() == terms.size());
}

TEST_CASE("normalize: cos^n -> cos^(n mod 2)·(1 - sin²)^(n div 2), as GiNaC's algebraic subs") {
  const GiNaC::symbol c("cos(a)"), s("sin(a)"), cb("cos(b)"), sb("sin(b)"), x("x");
  GiNaC::exmap rules;
  rules[GiNaC::pow(c, 2)] = 1 - GiNaC::pow(s, 2);
  rules[GiNaC::pow(cb, 2)] = 1 - GiNaC::pow(sb, 2);
  const Algebra alg(2, {}, rules);
  const ex e = GiNaC::pow(c, 4) * x + 3 * GiNaC::pow(c, 3) * s * GiNaC::pow(cb, 2) -
               GiNaC::pow(c + cb * x, 3) + GiNaC::pow(c, 2) * GiNaC::pow(cb, 5) / 7 + c * sb;
  // The reference: GiNaC's algebraic substitution repeated to a fixed point.
  ex want = e.expand();
  for (int pass = 0; pass < 8; ++pass) {
    const ex next = want.subs(rules, GiNaC::subs_options::algebraic).expand();
    if (next.is_equal(want)) break;
    want = next;
  }
  const ex got = alg.normalize(e);
  CHECK(got.is_equal(want));
  CHECK(got.degree(c) <= 1);
  CHECK(got.degree(cb) <= 1);
  CHECK((got - e)
            .subs(GiNaC::exmap{{c, GiNaC::numeric(3, 5)},
                               {s, GiNaC::numeric(4, 5)},
                               {cb, GiNaC::numeric(5, 13)},
                               {sb, GiNaC::numeric(12, 13)},
                               {x, GiNaC::numeric(7, 3)}})
            .expand()
            .is_zero());
}
