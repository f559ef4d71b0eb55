#include "weilgen/codegen/cse.hpp"

#include <algorithm>
#include <unordered_map>

namespace weilgen::gen {

using GiNaC::ex;

namespace {
bool is_atom(const ex& e) {
  return GiNaC::is_a<GiNaC::symbol>(e) || GiNaC::is_a<GiNaC::numeric>(e) ||
         GiNaC::is_a<GiNaC::constant>(e);
}
// A product's numeric factor is not worth a temporary of its own: c·(rest) shares `rest`.
ex strip_coefficient(const ex& e) {
  if (!GiNaC::is_a<GiNaC::mul>(e)) return e;
  ex rest = 1;
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (!GiNaC::is_a<GiNaC::numeric>(e.op(i))) rest *= e.op(i);
  return rest;
}
// b^n for a sum b and a whole n (a divisor's reciprocal, or its square).
bool is_integer_power_of_sum(const ex& e) {
  return GiNaC::is_a<GiNaC::power>(e) && GiNaC::is_a<GiNaC::add>(e.op(0)) &&
         GiNaC::is_a<GiNaC::numeric>(e.op(1)) && GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_integer();
}
}  // namespace

std::size_t operation_count(const ex& e) {
  if (is_atom(e)) return 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < e.nops(); ++i) n += operation_count(e.op(i));
  if (GiNaC::is_a<GiNaC::add>(e)) return n + e.nops() - 1;
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    std::size_t factors = 0;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex& op = e.op(i);
      const bool sign_only = GiNaC::is_a<GiNaC::numeric>(op) && (op.is_equal(1) || op.is_equal(-1));
      if (!sign_only) ++factors;
    }
    return n + (factors > 0 ? factors - 1 : 0);
  }
  if (GiNaC::is_a<GiNaC::power>(e) && GiNaC::is_a<GiNaC::numeric>(e.op(1)) &&
      GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_integer()) {
    const long k = GiNaC::ex_to<GiNaC::numeric>(e.op(1)).to_long();
    return n + static_cast<std::size_t>(k < 0 ? -k : k - 1);  // |k| − 1 products, 1 division
  }
  return n + 1;  // a function call
}

namespace {
ex canonical_signs(const ex& e, CanonicalText& canon) {
  if (is_atom(e)) return e;
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    GiNaC::numeric sign = 1;
    GiNaC::exvector factors;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex op = canonical_signs(e.op(i), canon);
      if (!GiNaC::is_a<GiNaC::add>(op)) {
        factors.push_back(op);
        continue;
      }
      const CanonicalText::Signed r = canon.canonical_sign(op);
      if (r.negated) sign = -sign;
      factors.push_back(r.value);
    }
    return GiNaC::mul(factors) * sign;
  }
  if (GiNaC::is_a<GiNaC::add>(e)) {
    GiNaC::exvector terms;
    for (std::size_t i = 0; i < e.nops(); ++i) terms.push_back(canonical_signs(e.op(i), canon));
    return GiNaC::add(terms);
  }
  return e;
}
}  // namespace

ex with_common_factors(const ex& e, CanonicalText& canon) {
  if (!GiNaC::is_a<GiNaC::add>(e)) return e;
  const ex factored = GiNaC::collect_common_factors(e);
  return operation_count(factored) < operation_count(e) ? canonical_signs(factored, canon) : e;
}

const std::string& CanonicalText::of(const ex& e) {
  auto it = memo_.find(e);
  if (it != memo_.end()) return it->second;
  std::string s;
  if (is_atom(e)) {
    std::ostringstream os;
    os << e;
    s = os.str();
  } else if (GiNaC::is_a<GiNaC::mul>(e)) {
    // Sign-canonical: a sum factor is taken with the sign whose text is smaller and the sign is
    // moved to the numeric coefficient, so that c·(a − b) and (−c)·(b − a) read the same.
    GiNaC::numeric coeff = 1;
    std::vector<std::string> parts;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex& op = e.op(i);
      if (GiNaC::is_a<GiNaC::numeric>(op)) {
        coeff *= GiNaC::ex_to<GiNaC::numeric>(op);
      } else if (GiNaC::is_a<GiNaC::add>(op)) {
        const Signed r = canonical_sign(op);
        if (r.negated) coeff = -coeff;
        parts.push_back(of(r.value));
      } else if (is_integer_power_of_sum(op)) {
        // (−b)^n = (−1)^n b^n: the base's sign is GiNaC's choice too.
        const Signed r = canonical_sign(op.op(0));
        if (r.negated && GiNaC::ex_to<GiNaC::numeric>(op.op(1)).is_odd()) coeff = -coeff;
        parts.push_back("pow(" + of(r.value) + "," + of(op.op(1)) + ")");
      } else {
        parts.push_back(of(op));
      }
    }
    std::sort(parts.begin(), parts.end());
    std::ostringstream os;
    os << "mul(" << coeff;
    for (const auto& p : parts) os << "," << p;
    os << ")";
    s = os.str();
  } else if (is_integer_power_of_sum(e)) {
    const Signed r = canonical_sign(e.op(0));
    const bool flip = r.negated && GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_odd();
    s = std::string(flip ? "neg" : "") + "pow(" + of(r.value) + "," + of(e.op(1)) + ")";
  } else {
    std::vector<std::string> parts;
    for (std::size_t i = 0; i < e.nops(); ++i) parts.push_back(of(e.op(i)));
    if (GiNaC::is_a<GiNaC::add>(e) || GiNaC::is_a<GiNaC::mul>(e))
      std::sort(parts.begin(), parts.end());
    if (GiNaC::is_a<GiNaC::add>(e)) {
      s = "add(";
    } else if (GiNaC::is_a<GiNaC::mul>(e)) {
      s = "mul(";
    } else if (GiNaC::is_a<GiNaC::power>(e)) {
      s = "pow(";
    } else if (GiNaC::is_a<GiNaC::function>(e)) {
      s = GiNaC::ex_to<GiNaC::function>(e).get_name() + "(";
    } else {
      s = "node(";
    }
    for (std::size_t i = 0; i < parts.size(); ++i) s += (i ? "," : "") + parts[i];
    s += ")";
  }
  return memo_.emplace(e, std::move(s)).first->second;
}

CanonicalText::Signed CanonicalText::canonical_sign(const ex& sum) {
  auto it = sign_memo_.find(sum);
  if (it != sign_memo_.end()) return it->second;
  const Signed r = compute_canonical_sign(sum);
  sign_memo_.emplace(sum, r);
  return r;
}

CanonicalText::Signed CanonicalText::compute_canonical_sign(const ex& sum) {
  // Term by term, not expand(): a nested (factored) sum keeps its form.
  ex neg;
  if (GiNaC::is_a<GiNaC::add>(sum)) {
    GiNaC::exvector terms;
    for (std::size_t i = 0; i < sum.nops(); ++i) terms.push_back(-sum.op(i));
    neg = GiNaC::add(terms);
  } else {
    neg = (-sum).expand();
  }
  if (of(neg) < of(sum)) return {neg, true};
  return {sum, false};
}

std::string CanonicalText::unsigned_text(const ex& e) {
  if (!GiNaC::is_a<GiNaC::mul>(e)) return of(e);
  // −x is mul(−1, x): its text must be x's, or flipping a sum's sign would reorder its terms
  // (and renumber the temporaries) from one run to the next.
  const ex core = strip_coefficient(e);
  if (!GiNaC::is_a<GiNaC::mul>(core)) return of(core);
  const std::string& t = of(e);  // "mul(<coeff>,<factors...>)"
  const auto comma = t.find(',');
  return comma == std::string::npos ? t : "mul(" + t.substr(comma + 1);
}

std::vector<ex> CanonicalText::sorted_ops(const ex& e) {
  std::vector<ex> ops;
  for (std::size_t i = 0; i < e.nops(); ++i) ops.push_back(e.op(i));
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    std::stable_sort(ops.begin(), ops.end(),
                     [&](const ex& a, const ex& b) { return of(a) < of(b); });
  } else if (GiNaC::is_a<GiNaC::add>(e)) {
    // By the term without its numeric factor: the order must not change when GiNaC flips the
    // sign of the whole sum.
    std::vector<std::pair<std::string, ex>> keyed;
    for (const ex& op : ops) keyed.emplace_back(unsigned_text(op), op);
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (std::size_t i = 0; i < ops.size(); ++i) ops[i] = keyed[i].second;
  }
  return ops;
}

namespace {
struct Eliminator {
  CanonicalText canon;
  std::unordered_map<std::string, int> count;
  std::unordered_map<std::string, ex> replaced;
  CseResult result;
  std::string prefix;

  // A product's or a sum's key ignores its sign: GiNaC may hold x·(a − b) in one run and
  // −x·(b − a) in the next (the sign of a sum inside a product follows hash order), and a
  // coefficient a − b of one output may be b − a of another; each pair must share one temporary
  // whose value has the canonical sign.
  std::string key_of(const ex& node) {
    if (GiNaC::is_a<GiNaC::mul>(node)) return canon.unsigned_text(node);
    if (GiNaC::is_a<GiNaC::add>(node)) return canon.of(canon.canonical_sign(node).value);
    return canon.of(node);
  }
  // −1 when the canonical text of a product has a negative coefficient or a sum is the negation
  // of its canonical sign, else 1.
  int canonical_sign_of(const ex& node) {
    if (GiNaC::is_a<GiNaC::add>(node)) return canon.canonical_sign(node).negated ? -1 : 1;
    if (!GiNaC::is_a<GiNaC::mul>(node)) return 1;
    const std::string& t = canon.of(node);
    return t.size() > 4 && t[4] == '-' ? -1 : 1;
  }

  void tally(const ex& node) {
    if (is_atom(node)) return;
    const ex core = strip_coefficient(node);
    if (!core.is_equal(node)) {
      tally(core);
      return;
    }
    if (count[key_of(node)]++ > 0) return;
    for (const ex& op : canon.sorted_ops(node)) tally(op);
  }

  ex rewrite(const ex& node) {
    if (is_atom(node)) return node;
    const ex core = strip_coefficient(node);
    if (!core.is_equal(node)) return rewrite(core) * (node / core).expand();
    const std::string key = key_of(node);
    const int sign = canonical_sign_of(node);
    if (auto it = replaced.find(key); it != replaced.end()) return sign * it->second;
    ex rebuilt;
    if (GiNaC::is_a<GiNaC::add>(node)) {
      GiNaC::exvector v;
      for (const ex& op : canon.sorted_ops(node)) v.push_back(rewrite(op));
      rebuilt = GiNaC::add(v);
    } else if (GiNaC::is_a<GiNaC::mul>(node)) {
      GiNaC::exvector v;
      for (const ex& op : canon.sorted_ops(node)) v.push_back(rewrite(op));
      rebuilt = GiNaC::mul(v);
    } else if (GiNaC::is_a<GiNaC::power>(node)) {
      rebuilt = GiNaC::pow(rewrite(node.op(0)), rewrite(node.op(1)));
    } else {
      struct Rewriter : GiNaC::map_function {
        Eliminator* self;
        explicit Rewriter(Eliminator* s) : self(s) {}
        ex operator()(const ex& e) override { return self->rewrite(e); }
      } rewriter(this);
      rebuilt = node.map(rewriter);
    }
    // A product or a sum is stored with the canonical sign and used as sign·value.
    if (sign < 0) rebuilt = -rebuilt;
    if (count[key] >= 2) {
      GiNaC::symbol t(prefix + std::to_string(result.temps.size()));
      // A sum's sign is GiNaC's (hash-order) choice: store the canonical sign in the temporary.
      ex value = rebuilt, use = t;
      if (GiNaC::is_a<GiNaC::add>(rebuilt)) {
        const CanonicalText::Signed r = canon.canonical_sign(rebuilt);
        value = r.value;
        if (r.negated) use = -t;
      }
      result.temps.push_back({t, value});
      replaced.emplace(key, use);
      return sign * use;
    }
    replaced.emplace(key, rebuilt);
    return sign * rebuilt;
  }
};
}  // namespace

CseResult eliminate_common_subexpressions(const std::vector<ex>& outputs,
                                          const std::string& prefix) {
  Eliminator el;
  el.prefix = prefix;
  for (const ex& e : outputs) el.tally(e);
  for (const ex& e : outputs) el.result.outputs.push_back(el.rewrite(e));
  return std::move(el.result);
}

}  // namespace weilgen::gen
