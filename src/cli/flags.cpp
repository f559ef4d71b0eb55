#include "flags.hpp"

#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <iostream>
#include <system_error>

#include "weilgen/machine/algebra_size.hpp"

namespace weilgen::cli {

namespace fs = std::filesystem;

NumberRange thread_range() { return NumberRange::whole_numbers(0, 1024); }

void check_order(const Description& desc, int order, bool quiet) {
  const std::string warning = check_algebra_size(desc, order, "--order " + std::to_string(order));
  if (!warning.empty() && !quiet) std::cerr << "weilgen: " << warning << "\n";
}

}  // namespace weilgen::cli
