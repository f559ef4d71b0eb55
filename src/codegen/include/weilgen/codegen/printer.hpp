// Prints GiNaC expressions as C++ (templated Scalar), readable text, LaTeX or Python syntax that
// sympy.sympify reads (`*`, `**`), with operands in
// canonical order (so output does not depend on GiNaC's hash order) and operation counts.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <string>

#include "weilgen/base/format.hpp"
#include "weilgen/codegen/cse.hpp"

namespace weilgen::gen {

struct OpCount {
  long adds = 0, muls = 0, divs = 0, functions = 0;
  long total() const { return adds + muls + divs + functions; }
  OpCount& operator+=(const OpCount& o);
  std::string str() const;  // "123 (adds 60, muls 60, divs 0, functions 3)"
};

class ExprPrinter {
 public:
  enum class Style { Cpp, Text, Latex, Sympy };
  // `names` maps symbol names to the text printed for them (others print as their name).
  ExprPrinter(Style style, std::map<std::string, std::string> names = {});
  std::string print(const GiNaC::ex& e);
  // True when print(e) of a single term starts with '-' (its printed numeric factor is negative).
  bool prints_negative(const GiNaC::ex& e);
  const OpCount& ops() const { return ops_; }
  void reset_ops() { ops_ = {}; }

 private:
  std::string term(const GiNaC::ex& e, bool& negative);  // one summand, sign split off
  // The numeric factor term() prints: the product's numbers, with the sign flips of sums and
  // odd divisors taken in their canonical sign.
  GiNaC::numeric printed_coefficient(const GiNaC::ex& e);
  std::string factor(const GiNaC::ex& e);            // operand of a product
  std::string power(const GiNaC::ex& base, long n);  // base^n, n >= 1, as a factor
  std::string number(const GiNaC::numeric& n);
  std::string symbol(const GiNaC::ex& e);
  Style style_;
  std::map<std::string, std::string> names_;
  CanonicalText canon_;
  OpCount ops_;
};

}  // namespace weilgen::gen
