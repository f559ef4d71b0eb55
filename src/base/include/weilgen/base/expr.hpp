// Scalar expressions in machine files ("0.05/6", "-L_tool", "L04 - L23", "pi/2").
// A tiny AST so that the runtime can evaluate them numerically and the generator can turn them
// into GiNaC expressions, without the runtime depending on GiNaC.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace weilgen {

struct Expr {
  enum class Kind { Number, Param, Neg, Add, Sub, Mul, Div, Pow };
  Kind kind = Kind::Number;
  double number = 0.0;               // Kind::Number
  std::string name;                  // Kind::Param
  std::shared_ptr<const Expr> a, b;  // operands

  static Expr num(double v);
  static Expr param(std::string n);

  // Numeric value; parameters are looked up in `values` (throws std::out_of_range naming the
  // parameter when absent).
  double eval(const std::map<std::string, double>& values) const;
  // Parameter names used, sorted and unique.
  std::vector<std::string> params() const;
  bool is_number() const { return kind == Kind::Number; }
  std::string str() const;
};

// Σ c_i · e_i, without the terms whose coefficient is 0 (1 and −1 print without a factor); 0 for
// no terms. Used to write derived vectors such as ω × v readably.
Expr linear_combination(const std::vector<std::pair<double, Expr>>& terms);

// Parses `text`. Identifiers must be parameter names (or `pi`); throws std::invalid_argument with a
// message naming the offending character position.
Expr parse_expr(const std::string& text);

}  // namespace weilgen
