// SparsePoly, the Weil algebra's fast coefficient arithmetic, against GiNaC's expand.
#include <doctest/doctest.h>

#include <optional>
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

namespace {
// A random polynomial in a, b, x (non-negative powers), the divisors' and numerators' ring.
ex random_symbol_poly(const Atoms& at, std::mt19937& rng, int max_terms = 4) {
  const std::vector<ex> s{at.a, at.b, at.x};
  std::uniform_int_distribution<int> n_terms(1, max_terms), n_factors(0, 3), pick(0, 2), num(-9, 9),
      den(1, 6);
  ex sum = 0;
  for (int t = n_terms(rng); t > 0; --t) {
    ex term = GiNaC::numeric(num(rng), den(rng));
    for (int k = n_factors(rng); k > 0; --k) term *= s[static_cast<std::size_t>(pick(rng))];
    sum += term;
  }
  return sum.expand();
}

// ModelBuilder's GiNaC path, written out: N = Σ_k a_k D^(K−k) divisor by divisor, D divided out
// by GiNaC::divide while it divides; nothing when c stays as it is.
std::optional<ex> fraction_reference(const ex& c,
                                     const std::vector<std::pair<GiNaC::symbol, ex>>& r) {
  ex num = c.expand();
  std::vector<int> k(r.size(), 0);
  for (std::size_t i = 0; i < r.size(); ++i) {
    k[i] = num.degree(r[i].first);
    ex acc = 0;
    for (int j = 0; j <= k[i]; ++j)
      acc += num.coeff(r[i].first, j) * GiNaC::pow(r[i].second, k[i] - j);
    num = acc.expand();
  }
  if (num.is_zero()) return ex(0);
  for (std::size_t i = 0; i < r.size(); ++i)
    for (ex q; k[i] > 0 && GiNaC::divide(num, r[i].second, q); --k[i]) num = q.expand();
  ex out = num;
  int left = 0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (k[i] == 0) continue;
    if (k[i] > 1 || left++) return std::nullopt;
    out = (num * r[i].first).expand();
  }
  return out;
}
}  // namespace

TEST_CASE("SparsePoly: exact division equals GiNaC::divide, dividing or not") {
  const Atoms at;
  AtomTable table;
  std::mt19937 rng(41);
  int divided = 0, refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const ex d = random_symbol_poly(at, rng), q = random_symbol_poly(at, rng);
    if (d.is_zero()) continue;
    // Every third numerator is d·q (divides), the others d·q + a random polynomial (mostly not).
    const ex n = (trial % 3 == 0 ? d * q : d * q + random_symbol_poly(at, rng, 2)).expand();
    const auto sn = SparsePoly::from_ex(n, table), sd = SparsePoly::from_ex(d, table);
    REQUIRE(sn);
    REQUIRE(sd);
    REQUIRE(sn->symbols_only(table));
    ex want;
    const bool ginac = GiNaC::divide(n, d, want);
    SparsePoly got;
    const bool sparse = sn->divide_exact(*sd, table, got);
    CHECK(sparse == ginac);
    if (ginac && sparse) CHECK(got.to_ex(table).is_equal(want.expand()));
    (sparse ? divided : refused)++;
  }
  CHECK(divided > 100);
  CHECK(refused > 100);
  // Neither a monomial nor a polynomial without the divisor's variables is divisible by more.
  SparsePoly q;
  CHECK_FALSE(SparsePoly::from_ex(ex(at.a) * at.b, table)
                  ->divide_exact(*SparsePoly::from_ex(at.a * at.a, table), table, q));
  CHECK_FALSE(SparsePoly::from_ex(ex(3), table)
                  ->divide_exact(*SparsePoly::from_ex(at.a + 1, table), table, q));
  CHECK(SparsePoly::from_ex(2 * at.a * at.b + 2 * at.a, table)
            ->divide_exact(*SparsePoly::from_ex(4 * at.a, table), table, q));
  CHECK(q.to_ex(table).is_equal((at.b + 1) / 2));
  CHECK(SparsePoly::from_ex(ex(at.a) * at.b, table)->symbols_only(table));
  CHECK_FALSE(SparsePoly::from_ex(GiNaC::pow(at.a, -1), table)->symbols_only(table));
  CHECK_FALSE(SparsePoly::from_ex(at.pi * at.a, table)->symbols_only(table));
}

TEST_CASE("over_divisors in SparsePoly form: the GiNaC path's fraction on random coefficients") {
  const Atoms at;
  AtomTable table;
  const GiNaC::symbol inv1("_inv1");
  std::mt19937 rng(1125);
  std::uniform_int_distribution<int> power(0, 3), coin(0, 2);
  int polynomial = 0, one_left = 0, unchanged = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const ex d0 = random_symbol_poly(at, rng, 3) + 1, d1 = at.x - random_symbol_poly(at, rng, 2);
    // c = Q·D0^m·r0^K + P·(D0·r0 − 1)·r0^j (+ a term in r1): the second part vanishes once r0 is
    // 1/D0, so N = Q·D0^m divides by D0 m times: every outcome of the fraction occurs.
    const int m = power(rng), kk = power(rng) + (coin(rng) == 0 ? 0 : 1);
    ex c = random_symbol_poly(at, rng) * GiNaC::pow(d0, m) * GiNaC::pow(at.inv, kk) +
           random_symbol_poly(at, rng) * (d0 * at.inv - 1) * GiNaC::pow(at.inv, power(rng));
    if (coin(rng) == 0) c += random_symbol_poly(at, rng) * GiNaC::pow(inv1, power(rng) % 2 + 1);
    if (coin(rng) == 0) c += random_symbol_poly(at, rng, 2);
    c = c.expand();
    std::vector<std::pair<GiNaC::symbol, ex>> ref;
    std::vector<SparseReciprocal> present;
    for (const auto& [sym, den] : {std::pair<GiNaC::symbol, ex>{at.inv, d0.expand()},
                                   std::pair<GiNaC::symbol, ex>{inv1, d1.expand()}}) {
      if (!c.has(sym)) continue;
      ref.emplace_back(sym, den);
      present.push_back({table.index(sym), *SparsePoly::from_ex(den, table)});
    }
    const auto sc = SparsePoly::from_ex(c, table);
    REQUIRE(sc);
    const auto want = fraction_reference(c, ref);
    const auto got = over_divisors(*sc, present, table);
    REQUIRE(want.has_value() == got.has_value());
    if (!want) {
      ++unchanged;
      continue;
    }
    const ex g = got->to_ex(table);
    CHECK(g.is_equal(*want));
    (g.has(at.inv) || g.has(inv1) ? one_left : polynomial)++;
  }
  CHECK(polynomial > 10);
  CHECK(one_left > 10);
  CHECK(unchanged > 10);
}
