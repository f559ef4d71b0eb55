#include "weilgen/codegen/sparse_poly.hpp"

#include <algorithm>
#include <stdexcept>

namespace weilgen::gen {

using GiNaC::ex;

namespace {
constexpr int kBias = 32768;

std::uint16_t atom_of(std::uint32_t f) { return static_cast<std::uint16_t>(f >> 16); }
int exp_of(std::uint32_t f) { return static_cast<int>(f & 0xffffu) - kBias; }
std::uint32_t factor(std::uint16_t atom, long exp) {
  if (exp <= -kBias || exp >= kBias) throw std::overflow_error("SparsePoly: exponent out of range");
  return (static_cast<std::uint32_t>(atom) << 16) | static_cast<std::uint32_t>(exp + kBias);
}

// The product of two monomials: exponents of the same atom add, zero powers vanish.
AtomKey key_product(const AtomKey& a, const AtomKey& b) {
  AtomKey out;
  out.reserve(a.size() + b.size());
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && atom_of(a[i]) < atom_of(b[j]))) {
      out.push_back(a[i++]);
    } else if (i == a.size() || atom_of(b[j]) < atom_of(a[i])) {
      out.push_back(b[j++]);
    } else {
      const int e = exp_of(a[i]) + exp_of(b[j]);
      if (e != 0) out.push_back(factor(atom_of(a[i]), e));
      ++i;
      ++j;
    }
  }
  return out;
}

bool key_less(const SparsePoly::Term& a, const SparsePoly::Term& b) { return a.key < b.key; }

// Lex order on monomials with non-negative exponents, atoms by number: a > b.
struct LexGreater {
  bool operator()(const AtomKey& a, const AtomKey& b) const {
    std::size_t i = 0, j = 0;
    for (; i < a.size() && j < b.size(); ++i, ++j) {
      if (a[i] == b[j]) continue;
      if (atom_of(a[i]) != atom_of(b[j])) return atom_of(a[i]) < atom_of(b[j]);
      return exp_of(a[i]) > exp_of(b[j]);
    }
    return i < a.size();
  }
};

// a / b when b's exponents are at most a's, else nothing.
std::optional<AtomKey> key_quotient(const AtomKey& a, const AtomKey& b) {
  AtomKey inverse = b;
  for (auto& f : inverse) f = factor(atom_of(f), -exp_of(f));
  AtomKey q = key_product(a, inverse);
  for (std::uint32_t f : q)
    if (exp_of(f) < 0) return std::nullopt;
  return q;
}
}  // namespace

AtomTable::AtomTable() { key_id({}); }

std::size_t AtomTable::KeyHash::operator()(const AtomKey& k) const {
  std::size_t h = k.size();
  for (std::uint32_t f : k) h = h * 1000003u ^ f;
  return h;
}

std::uint16_t AtomTable::index(const ex& atom) {
  const auto it = index_.find(atom);
  if (it != index_.end()) return it->second;
  if (atoms_.size() >= 0xffffu) throw std::overflow_error("SparsePoly: too many atoms");
  const auto i = static_cast<std::uint16_t>(atoms_.size());
  atoms_.push_back(atom);
  index_.emplace(atom, i);
  return i;
}

std::uint32_t AtomTable::key_id(AtomKey key) {
  const auto it = key_ids_.find(key);
  if (it != key_ids_.end()) return it->second;
  const auto id = static_cast<std::uint32_t>(keys_.size());
  keys_.push_back(key);
  key_ids_.emplace(std::move(key), id);
  return id;
}

std::uint32_t AtomTable::product(std::uint32_t a, std::uint32_t b) {
  if (a == 0) return b;
  if (b == 0) return a;
  if (a > b) std::swap(a, b);
  const std::uint64_t pair = (static_cast<std::uint64_t>(a) << 32) | b;
  const auto it = products_.find(pair);
  if (it != products_.end()) return it->second;
  const std::uint32_t id = key_id(key_product(keys_[a], keys_[b]));
  products_.emplace(pair, id);
  return id;
}

SparsePoly::SparsePoly(const cln::cl_RA& c) {
  if (!cln::zerop(c)) terms_.push_back({0, c});
}

SparsePoly SparsePoly::atom(std::uint16_t index, AtomTable& atoms, int exp) {
  SparsePoly p;
  p.terms_.push_back({exp == 0 ? 0 : atoms.key_id({factor(index, exp)}), 1});
  return p;
}

std::optional<SparsePoly> SparsePoly::from_ex(const ex& e, AtomTable& atoms) {
  if (GiNaC::is_a<GiNaC::numeric>(e)) {
    const auto& n = GiNaC::ex_to<GiNaC::numeric>(e);
    if (!n.is_rational()) return std::nullopt;
    return SparsePoly(cln::the<cln::cl_RA>(n.to_cl_N()));
  }
  if (GiNaC::is_a<GiNaC::symbol>(e) || GiNaC::is_a<GiNaC::constant>(e))
    return atom(atoms.index(e), atoms);
  if (GiNaC::is_a<GiNaC::add>(e)) {
    std::vector<Term> all;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      auto p = from_ex(e.op(i), atoms);
      if (!p) return std::nullopt;
      for (auto& t : p->terms_) all.push_back(std::move(t));
    }
    return from_terms(std::move(all));
  }
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    SparsePoly r(1);
    for (std::size_t i = 0; i < e.nops(); ++i) {
      auto p = from_ex(e.op(i), atoms);
      if (!p) return std::nullopt;
      r = r.mul(*p, atoms);
    }
    return r;
  }
  if (GiNaC::is_a<GiNaC::power>(e)) {
    if (!GiNaC::is_a<GiNaC::numeric>(e.op(1))) return std::nullopt;
    const auto& n = GiNaC::ex_to<GiNaC::numeric>(e.op(1));
    if (!n.is_integer()) return std::nullopt;
    const long k = n.to_long();
    auto base = from_ex(e.op(0), atoms);
    if (!base) return std::nullopt;
    if (k < 0) {
      // Only a monomial has an inverse among polynomials in atoms.
      if (base->terms_.size() != 1) return std::nullopt;
      const Term& t = base->terms_[0];
      AtomKey key = atoms.key(t.key);
      for (auto& f : key) f = factor(atom_of(f), exp_of(f) * k);
      SparsePoly r;
      r.terms_.push_back({atoms.key_id(key), cln::expt(cln::recip(t.coeff), -k)});
      return r;
    }
    SparsePoly r(1);
    for (long i = 0; i < k; ++i) r = r.mul(*base, atoms);
    return r;
  }
  if (GiNaC::is_a<GiNaC::function>(e)) return atom(atoms.index(e.expand()), atoms);  // as expand
  return std::nullopt;
}

SparsePoly SparsePoly::from_terms(std::vector<Term> terms) {
  std::sort(terms.begin(), terms.end(), key_less);
  SparsePoly p;
  p.terms_.reserve(terms.size());
  for (auto& t : terms) {
    if (!p.terms_.empty() && p.terms_.back().key == t.key) {
      p.terms_.back().coeff = p.terms_.back().coeff + t.coeff;
      continue;
    }
    if (!p.terms_.empty() && cln::zerop(p.terms_.back().coeff)) p.terms_.pop_back();
    p.terms_.push_back(std::move(t));
  }
  if (!p.terms_.empty() && cln::zerop(p.terms_.back().coeff)) p.terms_.pop_back();
  return p;
}

const ex& AtomTable::monomial(std::uint32_t id) const {
  if (monomials_.size() <= id) monomials_.resize(keys_.size());
  ex& m = monomials_[id];
  if (m.is_zero()) {  // not built yet (a monomial is never 0)
    GiNaC::exvector factors;
    factors.reserve(keys_[id].size());
    for (std::uint32_t f : keys_[id]) {
      const int k = exp_of(f);
      factors.push_back(k == 1 ? atoms_[atom_of(f)] : GiNaC::pow(atoms_[atom_of(f)], k));
    }
    m = GiNaC::mul(factors);
  }
  return m;
}

// The expanded sum as GiNaC's add of (monomial, rational) pairs: the canonical form that the sum
// of the terms' products would have (add splits each product into these same pairs).
ex SparsePoly::to_ex(const AtomTable& atoms) const {
  GiNaC::epvector pairs;
  pairs.reserve(terms_.size());
  ex constant = 0;
  for (const Term& t : terms_) {
    if (t.key == 0) {
      constant = GiNaC::numeric(t.coeff);
      continue;
    }
    pairs.emplace_back(atoms.monomial(t.key), GiNaC::numeric(t.coeff));
  }
  return GiNaC::add(std::move(pairs), constant);
}

void SparsePoly::multiply_into(const SparsePoly& o, AtomTable& atoms,
                               std::vector<Term>& out) const {
  out.reserve(out.size() + terms_.size() * o.terms_.size());
  for (const Term& a : terms_)
    for (const Term& b : o.terms_) out.push_back({atoms.product(a.key, b.key), a.coeff * b.coeff});
}

SparsePoly SparsePoly::mul(const SparsePoly& o, AtomTable& atoms) const {
  if (terms_.size() == 1 && terms_[0].key == 0 && cln::equal(terms_[0].coeff, 1)) return o;
  std::vector<Term> raw;
  multiply_into(o, atoms, raw);
  return from_terms(std::move(raw));
}

SparsePoly SparsePoly::operator+(const SparsePoly& o) const {
  std::vector<Term> raw = terms_;
  raw.insert(raw.end(), o.terms_.begin(), o.terms_.end());
  return from_terms(std::move(raw));
}

SparsePoly SparsePoly::reduced(const std::vector<SquareRule>& rules, AtomTable& atoms) const {
  if (rules.empty()) return *this;
  const auto rule_of = [&](std::uint16_t a) -> const SparsePoly* {
    for (const auto& [atom, r] : rules)
      if (atom == a) return &r;
    return nullptr;
  };
  // Most results hold no square of a rule's atom: found without copying a key.
  const auto needs = [&](const Term& t) {
    for (std::uint32_t f : atoms.key(t.key))
      if (exp_of(f) >= 2 && rule_of(atom_of(f))) return true;
    return false;
  };
  if (std::none_of(terms_.begin(), terms_.end(), needs)) return *this;
  std::vector<Term> out;
  bool changed = false;
  for (const Term& t : terms_) {
    SparsePoly factor_poly(1);  // Π r^(k div 2) over the rule atoms of the term
    bool reduce = false;
    AtomKey rest;
    const AtomKey key = atoms.key(t.key);  // a copy: products below may grow the table
    for (std::uint32_t f : key) {
      const int k = exp_of(f);
      const SparsePoly* r = k >= 2 ? rule_of(atom_of(f)) : nullptr;
      if (!r) {
        rest.push_back(f);
        continue;
      }
      if (k % 2 == 1) rest.push_back(factor(atom_of(f), 1));
      reduce = true;
      for (int i = 0; i < k / 2; ++i) factor_poly = factor_poly.mul(*r, atoms);
    }
    if (!reduce) {
      out.push_back(t);
      continue;
    }
    changed = true;
    SparsePoly single;
    single.terms_.push_back({atoms.key_id(rest), t.coeff});
    single.multiply_into(factor_poly, atoms, out);
  }
  if (!changed) return *this;
  // A rule's right side may hold another rule's atom squared: reduce again until none is left.
  return from_terms(std::move(out)).reduced(rules, atoms);
}

bool SparsePoly::symbols_only(const AtomTable& atoms) const {
  for (const Term& t : terms_)
    for (std::uint32_t f : atoms.key(t.key))
      if (exp_of(f) < 0 || !GiNaC::is_a<GiNaC::symbol>(atoms.atom(atom_of(f)))) return false;
  return true;
}

int SparsePoly::degree(std::uint16_t atom, const AtomTable& atoms) const {
  int k = 0;
  for (const Term& t : terms_)
    for (std::uint32_t f : atoms.key(t.key))
      if (atom_of(f) == atom) k = std::max(k, exp_of(f));
  return k;
}

bool SparsePoly::divide_exact(const SparsePoly& d, AtomTable& atoms, SparsePoly& q) const {
  if (d.is_zero()) throw std::domain_error("SparsePoly: division by zero");
  std::vector<std::pair<AtomKey, cln::cl_RA>> den;
  den.reserve(d.terms_.size());
  for (const Term& t : d.terms_) den.emplace_back(atoms.key(t.key), t.coeff);
  std::sort(den.begin(), den.end(),
            [](const auto& a, const auto& b) { return LexGreater{}(a.first, b.first); });
  const auto& [lead_key, lead_coeff] = den.front();
  std::map<AtomKey, cln::cl_RA, LexGreater> rest;
  for (const Term& t : terms_) rest.emplace(atoms.key(t.key), t.coeff);
  std::vector<Term> quotient;
  while (!rest.empty()) {
    const auto lead = rest.begin();
    const auto m = key_quotient(lead->first, lead_key);
    if (!m) return false;
    const cln::cl_RA c = lead->second / lead_coeff;
    quotient.push_back({atoms.key_id(*m), c});
    rest.erase(lead);
    for (std::size_t i = 1; i < den.size(); ++i) {
      AtomKey key = key_product(*m, den[i].first);
      const cln::cl_RA delta = -(c * den[i].second);
      const auto [it, inserted] = rest.emplace(std::move(key), delta);
      if (inserted) continue;
      it->second = it->second + delta;
      if (cln::zerop(it->second)) rest.erase(it);
    }
  }
  q = from_terms(std::move(quotient));
  return true;
}

std::optional<SparsePoly> over_divisors(const SparsePoly& c,
                                        const std::vector<SparseReciprocal>& present,
                                        AtomTable& atoms) {
  SparsePoly num = c;
  std::vector<int> k(present.size(), 0);
  for (std::size_t i = 0; i < present.size(); ++i) {
    const std::uint16_t r = present[i].atom;
    k[i] = num.degree(r, atoms);
    if (k[i] == 0) continue;
    std::vector<SparsePoly> powers{SparsePoly(1)};  // D^0 … D^K
    for (int j = 1; j <= k[i]; ++j) powers.push_back(powers.back().mul(present[i].divisor, atoms));
    // a·r^j → a·D^(K−j)
    std::vector<SparsePoly::Term> raw;
    for (const SparsePoly::Term& t : num.terms()) {
      AtomKey rest;
      int j = 0;
      for (std::uint32_t f : atoms.key(t.key)) {
        if (atom_of(f) == r)
          j = exp_of(f);
        else
          rest.push_back(f);
      }
      const SparsePoly single = SparsePoly::from_terms({{atoms.key_id(std::move(rest)), t.coeff}});
      single.multiply_into(powers[static_cast<std::size_t>(k[i] - j)], atoms, raw);
    }
    num = SparsePoly::from_terms(std::move(raw));
  }
  if (num.is_zero()) return num;  // c vanishes: the reciprocals' terms cancel
  for (std::size_t i = 0; i < present.size(); ++i)
    for (SparsePoly q; k[i] > 0 && num.divide_exact(present[i].divisor, atoms, q); --k[i])
      num = std::move(q);
  const SparseReciprocal* left = nullptr;
  for (std::size_t i = 0; i < present.size(); ++i) {
    if (k[i] == 0) continue;
    if (k[i] > 1 || left) return std::nullopt;
    left = &present[i];
  }
  return left ? num.mul(SparsePoly::atom(left->atom, atoms), atoms) : num;
}

}  // namespace weilgen::gen
