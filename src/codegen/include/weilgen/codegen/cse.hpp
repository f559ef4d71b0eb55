// Common-subexpression elimination over GiNaC expression trees (GiNaC has none).
//
// One pass over all outputs of a function: every non-atomic subtree that occurs twice or more
// becomes a temporary `_tmpN`. Traversal follows a canonical operand order (by canonical text),
// not GiNaC's hash order, so temporaries are numbered identically on every run.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <string>
#include <vector>

namespace weilgen::gen {

// Text of an expression with add/mul operands sorted: identical for equal expressions regardless
// of symbol creation order.
class CanonicalText {
 public:
  const std::string& of(const GiNaC::ex& e);
  // A sum or its negation, whichever has the smaller canonical text. GiNaC picks the sign of a
  // sum inside a product by hash order, which varies between runs; every emitter that must be
  // deterministic takes the sign from here.
  struct Signed {
    GiNaC::ex value;
    bool negated;
  };
  Signed canonical_sign(const GiNaC::ex& sum);
  // of(e) without a product's numeric coefficient: the same for c·x and −c·x.
  std::string unsigned_text(const GiNaC::ex& e);
  // Operands of e in canonical order.
  std::vector<GiNaC::ex> sorted_ops(const GiNaC::ex& e);

 private:
  Signed compute_canonical_sign(const GiNaC::ex& sum);
  std::map<GiNaC::ex, std::string, GiNaC::ex_is_less> memo_;
  std::map<GiNaC::ex, Signed, GiNaC::ex_is_less> sign_memo_;  // the CSE asks once per sum node
};

struct CseResult {
  struct Temp {
    GiNaC::symbol symbol;  // named _tmpN
    GiNaC::ex value;       // may refer to earlier temporaries
  };
  std::vector<Temp> temps;
  std::vector<GiNaC::ex> outputs;  // rewritten in terms of temporaries
};

// Operations to evaluate e as written (additions, multiplications by a symbol or a number other
// than ±1, divisions, function calls): the measure by which with_common_factors chooses. Not
// ExprPrinter's count, which credits the factors the printer groups itself and so keeps fewer
// collected forms (pipe cutter DeviationAndCoefficients 513 operations instead of 509).
std::size_t operation_count(const GiNaC::ex& e);

// e, or GiNaC::collect_common_factors(e) when that needs fewer operations: a·b·x + a·b·y − a·b·z
// becomes a·b·(x + y − z), 3 operations instead of 8, and the sum (x + y − z) is then a candidate
// for sharing by the CSE. Every sum inside a product is taken in canonical sign (the sign moved
// to the product's number): GiNaC's choice follows its hash order, which differs between runs and
// binaries, and the CSE must see the same sum in every coefficient. Applied to each coefficient
// before the CSE (docs/generator.md §4).
GiNaC::ex with_common_factors(const GiNaC::ex& e, CanonicalText& canon);

CseResult eliminate_common_subexpressions(const std::vector<GiNaC::ex>& outputs,
                                          const std::string& prefix = "_tmp");

}  // namespace weilgen::gen
