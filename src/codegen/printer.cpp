#include "weilgen/codegen/printer.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "weilgen/base/format.hpp"

namespace weilgen::gen {

using GiNaC::ex;

OpCount& OpCount::operator+=(const OpCount& o) {
  adds += o.adds;
  muls += o.muls;
  divs += o.divs;
  functions += o.functions;
  return *this;
}

std::string OpCount::str() const {
  return std::to_string(total()) + " (adds " + std::to_string(adds) + ", muls " +
         std::to_string(muls) + ", divs " + std::to_string(divs) + ", functions " +
         std::to_string(functions) + ")";
}

ExprPrinter::ExprPrinter(Style style, std::map<std::string, std::string> names)
    : style_(style), names_(std::move(names)) {}

namespace {
bool has_symbol(const ex& e) {
  if (GiNaC::is_a<GiNaC::symbol>(e)) return true;
  for (std::size_t i = 0; i < e.nops(); ++i)
    if (has_symbol(e.op(i))) return true;
  return false;
}
}  // namespace

namespace {
std::string text(const GiNaC::numeric& n) {
  std::ostringstream os;
  os << n;
  return os.str();
}
}  // namespace

std::string ExprPrinter::number(const GiNaC::numeric& n) {
  if (style_ == Style::Cpp) {
    if (n.is_integer()) return "Scalar(" + text(n) + ")";
    return "Scalar(" + format_literal(n.to_double()) + ")";
  }
  if (n.is_integer()) return text(n);
  if (n.is_rational() && n.denom() < 1000) {
    if (style_ == Style::Latex) return "\\frac{" + text(n.numer()) + "}{" + text(n.denom()) + "}";
    return text(n.numer()) + "/" + text(n.denom());
  }
  return format_literal(n.to_double());
}

std::string ExprPrinter::symbol(const ex& e) {
  std::string n = GiNaC::ex_to<GiNaC::symbol>(e).get_name();
  auto it = names_.find(n);
  return it == names_.end() ? n : it->second;
}

namespace {
// Terms (negative, text without the sign) joined in canonical order, positive terms first:
// "(tool_length - z)" rather than "(-z + tool_length)". Counts the additions.
std::string joined(std::vector<std::pair<bool, std::string>> terms, long& adds) {
  std::stable_partition(terms.begin(), terms.end(), [](const auto& t) { return !t.first; });
  std::string s = terms.front().first ? "-" + terms.front().second : terms.front().second;
  for (std::size_t i = 1; i < terms.size(); ++i) {
    s += terms[i].first ? " - " : " + ";
    s += terms[i].second;
    ++adds;
  }
  return s;
}
}  // namespace

std::string ExprPrinter::print(const ex& e) {
  if (GiNaC::is_a<GiNaC::add>(e)) {
    std::vector<std::pair<bool, std::string>> terms;  // (negative, text without the sign)
    // C++: products with the same numeric factor are grouped, Scalar(0.25) * (a + b - c), one
    // multiplication instead of one per term (at order 3 most coefficients are such sums).
    // Groups in order of their first term: the order stays canonical.
    std::vector<std::string> factor_of;  // per term: its printed factor when groupable, else ""
    std::map<std::string, std::vector<std::size_t>> members;
    for (const ex& op : canon_.sorted_ops(e)) {
      bool neg = false;
      std::string t = term(op, neg);
      std::string f;
      if (style_ == Style::Cpp && GiNaC::is_a<GiNaC::mul>(op)) {
        GiNaC::numeric c = printed_coefficient(op);
        if (c.is_negative()) c = -c;
        const std::string prefix = number(c) + " * ";
        if (!c.is_equal(1) && t.compare(0, prefix.size(), prefix) == 0) {
          f = number(c);
          members[f].push_back(terms.size());
        }
      }
      factor_of.push_back(f);
      terms.emplace_back(neg, std::move(t));
    }
    std::vector<std::pair<bool, std::string>> out;
    for (std::size_t i = 0; i < terms.size(); ++i) {
      const std::string& f = factor_of[i];
      if (f.empty() || members.at(f).size() < 2) {
        out.push_back(std::move(terms[i]));
        continue;
      }
      if (members.at(f).front() != i) continue;  // printed with its group's first term
      std::vector<std::pair<bool, std::string>> inner;
      bool all_negative = true;
      for (std::size_t k : members.at(f)) {
        inner.emplace_back(terms[k].first, terms[k].second.substr(f.size() + 3));
        all_negative &= terms[k].first;
      }
      if (all_negative)
        for (auto& t : inner) t.first = false;
      ops_.muls -= static_cast<long>(inner.size()) - 1;  // one product for the group
      out.emplace_back(all_negative, f + " * (" + joined(std::move(inner), ops_.adds) + ")");
    }
    return joined(std::move(out), ops_.adds);
  }
  bool neg = false;
  std::string t = term(e, neg);
  return neg ? "-" + t : t;
}

namespace {
bool is_divisor(const ex& e) {
  return GiNaC::is_a<GiNaC::power>(e) && GiNaC::is_a<GiNaC::numeric>(e.op(1)) &&
         GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_negative();
}
// (a + b)^n, n odd and positive: its sign, like a sum's, is GiNaC's hash-order choice.
bool is_odd_power_of_sum(const ex& e) {
  return GiNaC::is_a<GiNaC::power>(e) && GiNaC::is_a<GiNaC::add>(e.op(0)) &&
         GiNaC::is_a<GiNaC::numeric>(e.op(1)) &&
         GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_pos_integer() &&
         GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_odd();
}
}  // namespace

GiNaC::numeric ExprPrinter::printed_coefficient(const ex& e) {
  if (GiNaC::is_a<GiNaC::numeric>(e)) return GiNaC::ex_to<GiNaC::numeric>(e);
  const bool divisor = is_divisor(e);
  if (!GiNaC::is_a<GiNaC::mul>(e) && !divisor) return 1;
  GiNaC::numeric coeff = 1;
  for (std::size_t i = 0; i < (divisor ? 1 : e.nops()); ++i) {
    const ex op = divisor ? e : e.op(i);
    if (GiNaC::is_a<GiNaC::numeric>(op)) {
      coeff *= GiNaC::ex_to<GiNaC::numeric>(op);
    } else if (is_divisor(op) && GiNaC::is_a<GiNaC::add>(op.op(0))) {
      // the divisor's sign as CanonicalText chooses it
      if (canon_.canonical_sign(op.op(0)).negated &&
          GiNaC::ex_to<GiNaC::numeric>(op.op(1)).is_odd())
        coeff = -coeff;
    } else if (GiNaC::is_a<GiNaC::add>(op)) {
      if (canon_.canonical_sign(op).negated) coeff = -coeff;
    } else if (is_odd_power_of_sum(op)) {
      if (canon_.canonical_sign(op.op(0)).negated) coeff = -coeff;
    }
  }
  return coeff;
}

bool ExprPrinter::prints_negative(const ex& e) { return printed_coefficient(e).is_negative(); }

std::string ExprPrinter::term(const ex& e, bool& negative) {
  negative = false;
  if (GiNaC::is_a<GiNaC::numeric>(e)) {
    GiNaC::numeric n = GiNaC::ex_to<GiNaC::numeric>(e);
    if (n.is_negative()) {
      negative = true;
      n = -n;
    }
    return number(n);
  }
  const bool divisor = is_divisor(e);
  if (!GiNaC::is_a<GiNaC::mul>(e) && !divisor) return factor(e);
  GiNaC::numeric coeff = printed_coefficient(e);
  std::vector<std::string> num, den;
  for (const ex& op : divisor ? std::vector<ex>{e} : canon_.sorted_ops(e)) {
    if (GiNaC::is_a<GiNaC::numeric>(op)) continue;
    if (is_divisor(op)) {
      const ex base =
          GiNaC::is_a<GiNaC::add>(op.op(0)) ? canon_.canonical_sign(op.op(0)).value : op.op(0);
      // Printed as base^n directly: GiNaC::pow(base, n) would take an odd power's sign out of a
      // sum by its hash order, which differs between runs.
      den.push_back(power(base, -GiNaC::ex_to<GiNaC::numeric>(op.op(1)).to_long()));
    } else if (GiNaC::is_a<GiNaC::add>(op)) {
      num.push_back(factor(canon_.canonical_sign(op).value));
    } else if (is_odd_power_of_sum(op)) {
      num.push_back(power(canon_.canonical_sign(op.op(0)).value,
                          GiNaC::ex_to<GiNaC::numeric>(op.op(1)).to_long()));
    } else {
      num.push_back(factor(op));
    }
  }
  if (coeff.is_negative()) {
    negative = true;
    coeff = -coeff;
  }
  const std::string times = style_ == Style::Cpp     ? " * "
                            : style_ == Style::Text  ? "·"
                            : style_ == Style::Sympy ? "*"
                                                     : " ";
  std::string s;
  if (!coeff.is_equal(1) || num.empty()) {
    s = number(coeff);
    if (!num.empty()) ++ops_.muls;
  }
  for (std::size_t i = 0; i < num.size(); ++i) {
    if (!s.empty()) s += times;
    if (i > 0) ++ops_.muls;
    s += num[i];
  }
  if (!den.empty()) {
    std::string d;
    for (std::size_t i = 0; i < den.size(); ++i) {
      d += (i ? times : "") + den[i];
      if (i > 0) ++ops_.muls;
    }
    ++ops_.divs;
    if (style_ == Style::Latex) return "\\frac{" + s + "}{" + d + "}";
    s += " / " + (den.size() > 1 ? "(" + d + ")" : d);
  }
  return s;
}

std::string ExprPrinter::power(const ex& base, long n) {
  const std::string b = factor(base);
  if (n == 1) return b;
  if (style_ == Style::Sympy) return b + "**" + std::to_string(n);
  if (style_ != Style::Cpp)
    return b + (style_ == Style::Latex ? "^{" : "^") + std::to_string(n) +
           (style_ == Style::Latex ? "}" : "");
  std::string s = b;
  for (long i = 1; i < n; ++i) {
    s += " * " + b;
    ++ops_.muls;
  }
  return "(" + s + ")";
}

std::string ExprPrinter::factor(const ex& e) {
  if (GiNaC::is_a<GiNaC::symbol>(e)) return symbol(e);
  if (!has_symbol(e)) {  // constants such as cos(Pi/9) or sqrt(2)
    const ex v = e.evalf();
    if (GiNaC::is_a<GiNaC::numeric>(v)) {
      const GiNaC::numeric n = GiNaC::ex_to<GiNaC::numeric>(v);
      std::string s =
          style_ == Style::Cpp
              ? "Scalar(" + format_literal(n.to_double()) + ")"
              : (GiNaC::is_a<GiNaC::numeric>(e) ? number(n) : format_literal(n.to_double()));
      return n.is_negative() ? "(" + s + ")" : s;
    }
  }
  if (GiNaC::is_a<GiNaC::add>(e)) {
    std::string s = print(e);
    return style_ == Style::Latex ? "\\left(" + s + "\\right)" : "(" + s + ")";
  }
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    bool neg = false;
    std::string s = term(e, neg);
    return neg ? "(-" + s + ")" : s;
  }
  if (GiNaC::is_a<GiNaC::power>(e)) {
    const ex base = e.op(0), expo = e.op(1);
    if (GiNaC::is_a<GiNaC::numeric>(expo) && GiNaC::ex_to<GiNaC::numeric>(expo).is_pos_integer()) {
      const long n = GiNaC::ex_to<GiNaC::numeric>(expo).to_long();
      // An even power of a sum: GiNaC picks the base's sign by hash order; print the canonical
      // one (the sign does not matter).
      return power(
          GiNaC::is_a<GiNaC::add>(base) && n % 2 == 0 ? canon_.canonical_sign(base).value : base,
          n);
    }
    if (GiNaC::is_a<GiNaC::numeric>(expo) && GiNaC::ex_to<GiNaC::numeric>(expo).is_integer() &&
        GiNaC::ex_to<GiNaC::numeric>(expo).is_negative()) {
      // A divisor (derived ratios): 1 / b^n.
      ++ops_.divs;
      const std::string den = power(base, -GiNaC::ex_to<GiNaC::numeric>(expo).to_long());
      if (style_ == Style::Latex) return "\\frac{1}{" + den + "}";
      return (style_ == Style::Cpp ? "Scalar(1) / " : "1 / ") + den;
    }
    if (expo.is_equal(GiNaC::numeric(1, 2))) {
      ++ops_.functions;
      const bool call = style_ == Style::Cpp || style_ == Style::Sympy;
      return (call ? "sqrt(" : "\\sqrt{") + print(base) + (call ? ")" : "}");
    }
    ++ops_.functions;
    return "pow(" + print(base) + ", " + print(expo) + ")";
  }
  if (GiNaC::is_a<GiNaC::function>(e)) {
    const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
    if (name != "sin" && name != "cos" && name != "tan" && name != "exp" && name != "log")
      throw std::runtime_error("cannot print function " + name);
    ++ops_.functions;
    return name + "(" + print(e.op(0)) + ")";
  }
  std::ostringstream os;
  os << e;
  return os.str();
}

}  // namespace weilgen::gen
