#include "weilgen/machine/algebra_size.hpp"

#include <stdexcept>

#include "weilgen/base/format.hpp"

namespace weilgen {

double algebra_monomials(std::size_t errors, int order) {
  // C(k + r, r) by the product formula, in double: exact far beyond the limits used here.
  double c = 1;
  for (int i = 1; i <= order; ++i)
    c = c * static_cast<double>(errors + static_cast<std::size_t>(i)) / i;
  return c - 1;
}

std::string check_algebra_size(const Description& desc, int order, const std::string& what) {
  const int r = order > 0 ? order : desc.algebra.order;
  const double m = algebra_monomials(desc.errors.size(), r);
  const std::string estimate = desc.name + " at order " + std::to_string(r) + " has " +
                               std::to_string(desc.errors.size()) + " errors, up to " +
                               format_short(m) + " error monomials per output";
  if (m > kMaxAlgebraMonomials)
    throw std::invalid_argument(what + ": " + estimate + "; more than " +
                                format_short(kMaxAlgebraMonomials) +
                                " cannot be generated in reasonable time and memory: choose a "
                                "lower order");
  if (m > kLargeAlgebraMonomials)
    return "warning: " + estimate + "; generating it may take many minutes and GB of memory";
  return "";
}

}  // namespace weilgen
