// How large a machine's error model is at an algebra order, before anything is generated: the
// generator's time and memory grow with the number of error monomials it may have to carry.
#pragma once

#include <cstddef>
#include <string>

#include "weilgen/machine/description.hpp"

namespace weilgen {

// The highest algebra order a machine file or --order may ask for.
constexpr int kMaxAlgebraOrder = 20;
// Above this many monomials generation takes minutes: warn (the pipe cutter's 70 errors at
// order 3, 62195 monomials, took more than 300 s on a loaded machine).
constexpr double kLargeAlgebraMonomials = 2e4;
// Above this many it would take hours and many GB: refuse.
constexpr double kMaxAlgebraMonomials = 1e6;

// The monomials of degree 1..order in `errors` symbols, C(errors + order, order) - 1: an upper
// bound on the error terms of each output (relations and the chain's structure remove some).
double algebra_monomials(std::size_t errors, int order);

// Checks the model of `desc` at `order` (0 = the file's) before generation. Throws
// std::invalid_argument starting with `what` (e.g. "--order 9") when it is too large to generate;
// returns a warning with the estimate when it is large, else "".
std::string check_algebra_size(const Description& desc, int order, const std::string& what);

}  // namespace weilgen
