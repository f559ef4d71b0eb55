#include "weilgen/base/expr.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/text.hpp"

namespace weilgen {
namespace {

Expr unary(Expr::Kind kind, Expr a) {
  Expr e;
  e.kind = kind;
  e.a = std::make_shared<const Expr>(std::move(a));
  return e;
}

Expr binary(Expr::Kind kind, Expr a, Expr b) {
  Expr e = unary(kind, std::move(a));
  e.b = std::make_shared<const Expr>(std::move(b));
  return e;
}

// Recursive descent over
//   sum     := product (('+' | '-') product)*
//   product := signed (('*' | '/') signed)*
//   signed  := ('-' | '+') signed | power
//   power   := primary ('^' signed)?          (right-associative; -2^2 = -(2^2))
//   primary := number | identifier ('.' ('x'|'y'|'z'))? | '(' sum ')'
class Parser {
 public:
  explicit Parser(const std::string& text) : text_(text) {}

  Expr parse() {
    skip_space();
    if (pos_ == text_.size()) fail("empty expression");
    Expr e = sum();
    if (pos_ != text_.size()) fail(std::string("unexpected '") + text_[pos_] + "'");
    return e;
  }

 private:
  // Deep enough for any hand-written expression, shallow enough not to exhaust the stack.
  static constexpr int kMaxDepth = 200;

  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument("expression '" + abbreviated(text_) + "': " + what +
                                " at position " + std::to_string(pos_ + 1));
  }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }

  bool accept(char c) {
    skip_space();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      skip_space();
      return true;
    }
    return false;
  }

  Expr sum() {
    Expr e = product();
    for (;;) {
      if (accept('+')) {
        e = binary(Expr::Kind::Add, std::move(e), product());
      } else if (accept('-')) {
        e = binary(Expr::Kind::Sub, std::move(e), product());
      } else {
        return e;
      }
    }
  }

  Expr product() {
    Expr e = signed_term();
    for (;;) {
      if (accept('*')) {
        e = binary(Expr::Kind::Mul, std::move(e), signed_term());
      } else if (accept('/')) {
        e = binary(Expr::Kind::Div, std::move(e), signed_term());
      } else {
        return e;
      }
    }
  }

  Expr signed_term() {
    if (++depth_ > kMaxDepth) fail("expression nested too deeply");
    Expr e;
    if (accept('-')) {
      Expr operand = signed_term();
      // A negative literal stays a number so that "-5" is_number().
      e = operand.is_number() ? Expr::num(-operand.number)
                              : unary(Expr::Kind::Neg, std::move(operand));
    } else if (accept('+')) {
      e = signed_term();
    } else {
      e = power();
    }
    --depth_;
    return e;
  }

  Expr power() {
    Expr base = primary();
    if (accept('^')) return binary(Expr::Kind::Pow, std::move(base), signed_term());
    return base;
  }

  Expr primary() {
    skip_space();
    if (pos_ == text_.size()) fail("unexpected end");
    const char c = text_[pos_];
    if (c == '(') {
      accept('(');
      Expr e = sum();
      if (!accept(')')) fail("expected ')'");
      return e;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') return identifier();
    fail(std::string("unexpected '") + c + "'");
  }

  Expr number() {
    const size_t start = pos_;
    auto digits = [&] {
      while (pos_ < text_.size() && std::isdigit(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    };
    digits();
    if (pos_ < text_.size() && text_[pos_] == '.') {
      ++pos_;
      digits();
    }
    // An exponent only when digits follow, so that "2e" is reported rather than half-read.
    if (pos_ < text_.size() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
      size_t p = pos_ + 1;
      if (p < text_.size() && (text_[p] == '+' || text_[p] == '-')) ++p;
      if (p < text_.size() && std::isdigit(static_cast<unsigned char>(text_[p]))) {
        pos_ = p;
        digits();
      }
    }
    double v = 0;
    const char* first = text_.data() + start;
    const char* last = text_.data() + pos_;
    const auto [end, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) {
      pos_ = start;
      fail("number '" + abbreviated(std::string(first, last)) +
           "' is out of range (magnitudes from 2.2e-308 to 1.8e308, or 0)");
    }
    if (ec != std::errc() || end != last) {
      pos_ = start;
      fail("malformed number");
    }
    skip_space();
    return Expr::num(v);
  }

  Expr identifier() {
    const size_t start = pos_;
    while (pos_ < text_.size() &&
           (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_')) {
      ++pos_;
    }
    // A component of a chain point: `E031.x` (machines/README.md, "Derived quantities").
    if (pos_ + 1 < text_.size() && text_[pos_] == '.' &&
        std::string("xyz").find(text_[pos_ + 1]) != std::string::npos &&
        (pos_ + 2 == text_.size() ||
         !(std::isalnum(static_cast<unsigned char>(text_[pos_ + 2])) || text_[pos_ + 2] == '_'))) {
      pos_ += 2;
    }
    std::string id = text_.substr(start, pos_ - start);
    skip_space();
    if (id == "pi") return Expr::num(kPi);
    return Expr::param(std::move(id));
  }

  const std::string& text_;
  size_t pos_ = 0;
  int depth_ = 0;
};

// Binding strength for printing: higher binds tighter.
int precedence(const Expr& e) {
  switch (e.kind) {
    case Expr::Kind::Add:
    case Expr::Kind::Sub:
      return 1;
    case Expr::Kind::Mul:
    case Expr::Kind::Div:
      return 2;
    case Expr::Kind::Neg:
      return 3;
    case Expr::Kind::Pow:
      return 4;
    case Expr::Kind::Number:
      return e.number < 0 ? 3 : 5;
    case Expr::Kind::Param:
      return 5;
  }
  return 5;
}

// Shortest decimal form that reads back as the same double; pi by name (expressions only).
std::string number_text(double v) {
  if (v == kPi) return "pi";
  if (v == -kPi) return "-pi";
  char buf[64];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

std::string wrap(const Expr& e, bool parens) { return parens ? "(" + e.str() + ")" : e.str(); }

void collect_params(const Expr& e, std::set<std::string>& out) {
  if (e.kind == Expr::Kind::Param) out.insert(e.name);
  if (e.a) collect_params(*e.a, out);
  if (e.b) collect_params(*e.b, out);
}

}  // namespace

Expr Expr::num(double v) {
  Expr e;
  e.kind = Kind::Number;
  e.number = v;
  return e;
}

Expr Expr::param(std::string n) {
  Expr e;
  e.kind = Kind::Param;
  e.name = std::move(n);
  return e;
}

double Expr::eval(const std::map<std::string, double>& values) const {
  switch (kind) {
    case Kind::Number:
      return number;
    case Kind::Param: {
      const auto it = values.find(name);
      if (it == values.end()) throw std::out_of_range("no value for parameter '" + name + "'");
      return it->second;
    }
    case Kind::Neg:
      return -a->eval(values);
    case Kind::Add:
      return a->eval(values) + b->eval(values);
    case Kind::Sub:
      return a->eval(values) - b->eval(values);
    case Kind::Mul:
      return a->eval(values) * b->eval(values);
    case Kind::Div:
      return a->eval(values) / b->eval(values);
    case Kind::Pow:
      return std::pow(a->eval(values), b->eval(values));
  }
  return 0.0;
}

std::vector<std::string> Expr::params() const {
  std::set<std::string> names;
  collect_params(*this, names);
  return {names.begin(), names.end()};
}

std::string Expr::str() const {
  const int p = precedence(*this);
  switch (kind) {
    case Kind::Number:
      return number_text(number);
    case Kind::Param:
      return name;
    case Kind::Neg:
      // "--x", not "-(-x)": the parenthesised form nests twice as deep, and a long chain of
      // signs printed that way no longer read back (kMaxDepth; found by fuzz_expression).
      return "-" + wrap(*a, precedence(*a) < p);
    case Kind::Pow:
      // Right-associative: the base needs parentheses when it is itself a power or signed.
      return wrap(*a, precedence(*a) <= p) + "^" + wrap(*b, precedence(*b) < 3);
    default:
      break;
  }
  const char* op = kind == Kind::Add   ? " + "
                   : kind == Kind::Sub ? " - "
                   : kind == Kind::Mul ? "*"
                                       : "/";
  return wrap(*a, precedence(*a) < p) + op + wrap(*b, precedence(*b) <= p);
}

Expr parse_expr(const std::string& text) { return Parser(text).parse(); }

Expr linear_combination(const std::vector<std::pair<double, Expr>>& terms) {
  std::optional<Expr> sum;
  for (const auto& [c, e] : terms) {
    if (c == 0 || (e.is_number() && e.number == 0)) continue;
    // −(−e) is e: the sign of a negated operand joins the coefficient's.
    const bool inner_negated = e.kind == Expr::Kind::Neg;
    const Expr& base = inner_negated ? *e.a : e;
    const bool negative = (c < 0) != inner_negated;
    const Expr term =
        std::abs(c) == 1 ? base : binary(Expr::Kind::Mul, Expr::num(std::abs(c)), base);
    if (!sum) {
      sum = negative ? unary(Expr::Kind::Neg, term) : term;
    } else {
      sum = binary(negative ? Expr::Kind::Sub : Expr::Kind::Add, *sum, term);
    }
  }
  return sum ? *sum : Expr::num(0);
}

}  // namespace weilgen
