#include "weilgen/codegen/weil.hpp"

#include <algorithm>

namespace weilgen::gen {

using GiNaC::ex;

Monomial monomial_product(const Monomial& a, const Monomial& b) {
  Monomial out;
  out.reserve(a.size() + b.size());
  std::merge(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

bool divides(const Monomial& divisor, const Monomial& m) {
  return std::includes(m.begin(), m.end(), divisor.begin(), divisor.end());
}

Algebra::Algebra(int order, std::vector<Monomial> relations, GiNaC::exmap trig_rules)
    : order_(order), trig_rules_(std::move(trig_rules)) {
  for (const auto& [from, to] : trig_rules_)
    if (GiNaC::is_a<GiNaC::power>(from)) trig_bases_.push_back(from.op(0));
  // Rules symbol² → r only: reduce_squares may walk the terms itself.
  for (const auto& [from, to] : trig_rules_) {
    if (!GiNaC::is_a<GiNaC::power>(from) || !GiNaC::is_a<GiNaC::symbol>(from.op(0)) ||
        !from.op(1).is_equal(2)) {
      squares_.clear();
      break;
    }
    squares_.emplace_back(from.op(0), to);
  }
  sparse_ = trig_rules_.empty() || !squares_.empty();
  for (const auto& [x, to] : squares_) {
    auto r = SparsePoly::from_ex(to.expand(), atoms_);
    if (!r) {
      sparse_ = false;
      break;
    }
    square_rules_.emplace_back(atoms_.index(x), std::move(*r));
  }
  // Keep only minimal generators: drop those of degree > r (already vanish) and multiples.
  for (auto& r : relations) std::sort(r.begin(), r.end());
  std::sort(relations.begin(), relations.end(), [](const Monomial& a, const Monomial& b) {
    return a.size() != b.size() ? a.size() < b.size() : a < b;
  });
  for (const auto& r : relations) {
    if (static_cast<int>(r.size()) > order_) continue;
    bool redundant = std::any_of(relations_.begin(), relations_.end(),
                                 [&](const Monomial& g) { return divides(g, r); });
    if (!redundant) relations_.push_back(r);
  }
}

bool Algebra::vanishes(const Monomial& m) const {
  if (static_cast<int>(m.size()) > order_) return true;
  return std::any_of(relations_.begin(), relations_.end(),
                     [&](const Monomial& g) { return divides(g, m); });
}

namespace {
// True when e has a power (exponent >= 2) of one of `bases`: the only case cos² → 1 − sin² can
// change. A walk is far cheaper than GiNaC's algebraic substitution, which most coefficients do
// not need.
bool has_square_of(const ex& e, const GiNaC::exvector& bases) {
  if (GiNaC::is_a<GiNaC::power>(e)) {
    for (const ex& b : bases)
      if (e.op(0).is_equal(b)) return true;
    return has_square_of(e.op(0), bases);
  }
  if (GiNaC::is_a<GiNaC::symbol>(e) || GiNaC::is_a<GiNaC::numeric>(e)) return false;
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (has_square_of(e.op(i), bases)) return true;
  return false;
}

// b^n → b^(n mod 2)·r^(n div 2) for a rule b² → r, in one factor of an expanded term.
ex reduce_factor(const ex& f, const std::vector<std::pair<ex, ex>>& squares) {
  if (!GiNaC::is_a<GiNaC::power>(f) || !GiNaC::is_a<GiNaC::numeric>(f.op(1))) return f;
  const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(f.op(1));
  if (!n.is_pos_integer() || n.to_long() < 2) return f;
  for (const auto& [base, to] : squares) {
    if (!f.op(0).is_equal(base)) continue;
    const long k = n.to_long();
    return GiNaC::pow(base, k % 2) * GiNaC::pow(to, k / 2);
  }
  return f;
}

ex reduce_term(const ex& t, const std::vector<std::pair<ex, ex>>& squares) {
  if (!GiNaC::is_a<GiNaC::mul>(t)) return reduce_factor(t, squares);
  GiNaC::exvector v;
  v.reserve(t.nops());
  for (std::size_t i = 0; i < t.nops(); ++i) v.push_back(reduce_factor(t.op(i), squares));
  return GiNaC::mul(v);
}
}  // namespace

ex Algebra::reduce_squares(const ex& e) const {
  if (squares_.empty()) return e.subs(trig_rules_, GiNaC::subs_options::algebraic);
  // The same as the algebraic substitution on an expanded polynomial, term by term: GiNaC's
  // pattern matching is far dearer (a fifth of the build at order 3).
  if (!GiNaC::is_a<GiNaC::add>(e)) return reduce_term(e, squares_);
  GiNaC::exvector v;
  v.reserve(e.nops());
  for (std::size_t i = 0; i < e.nops(); ++i) v.push_back(reduce_term(e.op(i), squares_));
  return GiNaC::add(v);
}

ex Algebra::normalize(const ex& c) const {
  ex e = c.expand();
  if (trig_rules_.empty()) return e;
  if (trig_bases_.size() == trig_rules_.size() && !has_square_of(e, trig_bases_)) return e;
  // Repeat: one algebraic pass lowers cos^n to cos^(n-2)·(1 − sin²).
  for (int pass = 0; pass < 8; ++pass) {
    ex reduced = reduce_squares(e).expand();
    if (reduced.is_equal(e)) break;
    e = reduced;
  }
  return e;
}

std::optional<SparsePoly> Algebra::to_sparse(const ex& c) const {
  if (!sparse_) return std::nullopt;
  if (const auto it = sparse_of_.find(c); it != sparse_of_.end()) return it->second;
  auto s = SparsePoly::from_ex(c, atoms_);
  if (s) sparse_of_.emplace(c, *s);
  return s;
}

ex Algebra::from_sparse(const SparsePoly& p) const {
  SparsePoly r = p.reduced(square_rules_, atoms_);
  ex e = r.to_ex(atoms_);
  sparse_of_.emplace(e, std::move(r));
  return e;
}

Poly::Poly(const ex& constant) { add_term({}, constant); }

Poly Poly::error(std::uint16_t index) {
  Poly p;
  p.terms_[{index}] = 1;
  return p;
}

void Poly::add_term(const Monomial& m, const ex& c) {
  if (c.is_zero()) return;
  auto it = terms_.find(m);
  if (it == terms_.end()) {
    terms_.emplace(m, c);
    return;
  }
  it->second = (it->second + c).expand();
  if (it->second.is_zero()) terms_.erase(it);
}

ex Poly::constant() const {
  auto it = terms_.find(Monomial{});
  return it == terms_.end() ? ex(0) : it->second;
}

Poly Poly::without_constant() const {
  Poly p = *this;
  p.terms_.erase(Monomial{});
  return p;
}

int Poly::min_degree() const {
  int d = 0;
  bool first = true;
  for (const auto& [m, c] : terms_) {
    if (first || static_cast<int>(m.size()) < d) d = static_cast<int>(m.size());
    first = false;
  }
  return d;
}

Poly Poly::operator+(const Poly& o) const {
  Poly p = *this;
  for (const auto& [m, c] : o.terms_) p.add_term(m, c);
  return p;
}

Poly Poly::operator-(const Poly& o) const { return *this + (-o); }

Poly Poly::operator-() const {
  Poly p;
  for (const auto& [m, c] : terms_) p.terms_.emplace(m, (-c).expand());
  return p;
}

Poly Poly::scaled(const ex& c, const Algebra& alg) const {
  Poly p;
  if (const auto sc = alg.to_sparse(c)) {
    for (const auto& [m, t] : terms_) {
      const auto st = alg.to_sparse(t);
      p.add_term(m, st ? alg.from_sparse(st->mul(*sc, alg.atoms())) : alg.normalize(t * c));
    }
    return p;
  }
  for (const auto& [m, t] : terms_) p.add_term(m, alg.normalize(t * c));
  return p;
}

Poly Poly::mul(const Poly& o, const Algebra& alg) const {
  return sum_of_products({{this, &o}}, alg);
}

bool Poly::to_sparse(const Algebra& alg, SparseTerms& out) const {
  out.assign(static_cast<std::size_t>(alg.order()) + 1, {});
  for (const auto& [m, c] : terms_) {
    if (static_cast<int>(m.size()) > alg.order()) continue;
    auto s = alg.to_sparse(c);
    if (!s) return false;
    out[m.size()].emplace_back(&m, std::move(*s));
  }
  return true;
}

Poly Poly::sparse_sum_of_products(
    const std::vector<std::pair<const SparseTerms*, const SparseTerms*>>& pairs,
    const Algebra& alg) {
  const int r = alg.order();
  AtomTable& atoms = alg.atoms();
  std::map<Monomial, std::vector<SparsePoly::Term>> raw;
  for (const auto& [sa, sb] : pairs) {
    for (int da = 0; da <= r; ++da) {
      for (const auto& [ma, ca] : (*sa)[static_cast<std::size_t>(da)]) {
        for (int d = 0; d <= r - da; ++d) {
          for (const auto& [mb, cb] : (*sb)[static_cast<std::size_t>(d)]) {
            Monomial m = monomial_product(*ma, *mb);
            if (alg.vanishes(m)) continue;  // never formed: truncation inside the product
            ca.multiply_into(cb, atoms, raw[std::move(m)]);
          }
        }
      }
    }
  }
  Poly p;
  for (auto& [m, parts] : raw) {
    const SparsePoly s = SparsePoly::from_terms(std::move(parts));
    if (s.is_zero()) continue;
    ex c = alg.from_sparse(s);
    if (!c.is_zero()) p.terms_.emplace_hint(p.terms_.end(), m, c);
  }
  return p;
}

Poly Poly::sum_of_products(const std::vector<std::pair<const Poly*, const Poly*>>& pairs,
                           const Algebra& alg) {
  {
    std::vector<SparseTerms> sparse(2 * pairs.size());
    std::vector<std::pair<const SparseTerms*, const SparseTerms*>> sparse_pairs;
    bool ok = true;
    for (std::size_t k = 0; k < pairs.size() && ok; ++k) {
      ok = pairs[k].first->to_sparse(alg, sparse[2 * k]) &&
           pairs[k].second->to_sparse(alg, sparse[2 * k + 1]);
      sparse_pairs.emplace_back(&sparse[2 * k], &sparse[2 * k + 1]);
    }
    if (ok) return sparse_sum_of_products(sparse_pairs, alg);
  }
  // Raw products per monomial over all pairs, each sum normalised once.
  const int r = alg.order();
  std::map<Monomial, GiNaC::exvector> raw;
  for (const auto& [a, b] : pairs) {
    if (a->is_zero() || b->is_zero()) continue;
    // b's terms by degree: a term of degree d meets only those of degree <= r - d, so the pairs
    // that truncation drops are never visited.
    std::vector<std::vector<const Terms::value_type*>> by_degree(static_cast<std::size_t>(r) + 1);
    for (const auto& t : b->terms_)
      if (static_cast<int>(t.first.size()) <= r) by_degree[t.first.size()].push_back(&t);
    for (const auto& [ma, ca] : a->terms_) {
      const int room = r - static_cast<int>(ma.size());
      for (int d = 0; d <= room; ++d) {
        for (const auto* tb : by_degree[static_cast<std::size_t>(d)]) {
          Monomial m = monomial_product(ma, tb->first);
          if (alg.vanishes(m)) continue;  // never formed: truncation inside the product
          raw[std::move(m)].push_back(ca * tb->second);
        }
      }
    }
  }
  Poly p;
  for (auto& [m, parts] : raw) {
    ex c = alg.normalize(GiNaC::add(parts));
    if (!c.is_zero()) p.terms_.emplace_hint(p.terms_.end(), m, c);
  }
  return p;
}

ex Poly::to_ex(const std::vector<GiNaC::symbol>& error_symbols) const {
  GiNaC::exvector parts;
  for (const auto& [m, c] : terms_) {
    ex t = c;
    for (auto i : m) t *= error_symbols.at(i);
    parts.push_back(t);
  }
  return GiNaC::add(parts);
}

ex factored_sum(std::vector<std::pair<Monomial, ex>> terms,
                const std::vector<GiNaC::symbol>& error_symbols) {
  GiNaC::exvector parts;
  while (!terms.empty()) {
    std::map<std::uint16_t, int> count;  // terms in which each error occurs
    for (const auto& t : terms) {
      const Monomial& m = t.first;
      for (std::size_t i = 0; i < m.size(); ++i)
        if (i == 0 || m[i] != m[i - 1]) ++count[m[i]];
    }
    auto best = count.end();
    for (auto it = count.begin(); it != count.end(); ++it)
      if (best == count.end() || it->second > best->second) best = it;
    if (best == count.end() || best->second < 2) break;
    const std::uint16_t e = best->first;
    std::vector<std::pair<Monomial, ex>> with, without;
    for (auto& t : terms) {
      auto pos = std::find(t.first.begin(), t.first.end(), e);
      if (pos == t.first.end()) {
        without.push_back(std::move(t));
        continue;
      }
      t.first.erase(pos);
      with.push_back(std::move(t));
    }
    parts.push_back(error_symbols.at(e) * factored_sum(std::move(with), error_symbols));
    terms = std::move(without);
  }
  for (const auto& [m, c] : terms) {
    ex t = c;
    for (auto i : m) t *= error_symbols.at(i);
    parts.push_back(t);
  }
  return GiNaC::add(parts);
}

Mat4 Mat4::identity() {
  Mat4 r;
  for (int i = 0; i < 4; ++i) r.m[i][i] = Poly(1);
  return r;
}

Mat4 Mat4::zero() { return {}; }

Mat4 Mat4::mul(const Mat4& o, const Algebra& alg) const {
  Mat4 r;
  // Every entry converted once (each meets four products).
  Poly::SparseTerms sa[4][4], sb[4][4];
  bool ok = true;
  for (int i = 0; i < 4 && ok; ++i)
    for (int j = 0; j < 4 && ok; ++j)
      ok = m[i][j].to_sparse(alg, sa[i][j]) && o.m[i][j].to_sparse(alg, sb[i][j]);
  if (ok) {
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        std::vector<std::pair<const Poly::SparseTerms*, const Poly::SparseTerms*>> pairs;
        for (int k = 0; k < 4; ++k) pairs.emplace_back(&sa[i][k], &sb[k][j]);
        r.m[i][j] = Poly::sparse_sum_of_products(pairs, alg);
      }
    }
    return r;
  }
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      std::vector<std::pair<const Poly*, const Poly*>> pairs;
      for (int k = 0; k < 4; ++k) pairs.emplace_back(&m[i][k], &o.m[k][j]);
      r.m[i][j] = Poly::sum_of_products(pairs, alg);
    }
  }
  return r;
}

Mat4 Mat4::operator+(const Mat4& o) const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[i][j] + o.m[i][j];
  return r;
}

Mat4 Mat4::operator-(const Mat4& o) const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[i][j] - o.m[i][j];
  return r;
}

Mat4 Mat4::constant_part() const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = Poly(m[i][j].constant());
  return r;
}

Mat4 Mat4::nilpotent_part() const {
  Mat4 r;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r.m[i][j] = m[i][j].without_constant();
  return r;
}

Mat4 rigid_inverse(const Mat4& nominal, const Algebra& alg) {
  Mat4 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = Poly(nominal.m[j][i].constant());
  for (int i = 0; i < 3; ++i) {
    ex t = 0;
    for (int k = 0; k < 3; ++k) t -= nominal.m[k][i].constant() * nominal.m[k][3].constant();
    r.m[i][3] = Poly(alg.normalize(t));
  }
  r.m[3][3] = Poly(1);
  return r;
}

Mat4 neumann_inverse(const Mat4& m, const Algebra& alg) {
  const Mat4 m0_inv = rigid_inverse(m.constant_part(), alg);
  const Mat4 k = m0_inv.mul(m.nilpotent_part(), alg);
  // Horner form of Σ_{j=0}^{r} (−K)^j: X ← I − K·X, r times.
  Mat4 x = Mat4::identity();
  for (int j = 0; j < alg.order(); ++j) x = Mat4::identity() - k.mul(x, alg);
  return x.mul(m0_inv, alg);
}

Mat4 translation(const ex (&v)[3]) {
  Mat4 r = Mat4::identity();
  for (int i = 0; i < 3; ++i) r.m[i][3] = Poly(v[i]);
  return r;
}

Mat4 translation_by(const Poly& amount, const ex (&u)[3], const Algebra& alg) {
  Mat4 r = Mat4::identity();
  for (int i = 0; i < 3; ++i) r.m[i][3] = amount.scaled(u[i], alg);
  return r;
}

namespace {
// [u]x and [u]x² as exact 3x3 coefficient matrices.
void cross_matrices(const ex (&u)[3], ex (&k)[3][3], ex (&k2)[3][3]) {
  const ex kk[3][3] = {{0, -u[2], u[1]}, {u[2], 0, -u[0]}, {-u[1], u[0], 0}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      k[i][j] = kk[i][j];
      ex s = 0;
      for (int l = 0; l < 3; ++l) s += kk[i][l] * kk[l][j];
      k2[i][j] = s.expand();
    }
}
}  // namespace

Mat4 rotation_cs(const ex (&u)[3], const ex& c, const ex& s, const Algebra& alg) {
  ex k[3][3], k2[3][3];
  cross_matrices(u, k, k2);
  Mat4 r = Mat4::identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      ex e = (i == j ? ex(1) : ex(0)) + s * k[i][j] + (1 - c) * k2[i][j];
      r.m[i][j] = Poly(alg.normalize(e));
    }
  return r;
}

Mat4 rotation_small(const ex (&u)[3], const Poly& angle, const Algebra& alg) {
  // sin a = Σ_{k odd} (−1)^((k−1)/2) a^k / k!,  1 − cos a = Σ_{k even ≥ 2} (−1)^(k/2+1) a^k / k!
  Poly sin_a, one_minus_cos;
  Poly power = angle;
  GiNaC::numeric factorial = 1;
  for (int k = 1; k <= alg.order() && !power.is_zero(); ++k) {
    factorial *= k;
    const ex coeff = GiNaC::numeric(1) / factorial;
    if (k % 2 == 1) {
      sin_a = sin_a + power.scaled(((k - 1) / 2) % 2 == 0 ? coeff : -coeff, alg);
    } else {
      one_minus_cos = one_minus_cos + power.scaled((k / 2) % 2 == 1 ? coeff : -coeff, alg);
    }
    power = power.mul(angle, alg);
  }
  ex k[3][3], k2[3][3];
  cross_matrices(u, k, k2);
  Mat4 r = Mat4::identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = r.m[i][j] + sin_a.scaled(k[i][j], alg) + one_minus_cos.scaled(k2[i][j], alg);
  return r;
}

}  // namespace weilgen::gen
