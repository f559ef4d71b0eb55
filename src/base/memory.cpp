#include "weilgen/base/memory.hpp"

#include <unistd.h>

#include <cstdio>
#include <stdexcept>

namespace weilgen {

double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

std::string format_bytes(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000 && u < 6) {
    bytes /= 1000;
    ++u;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, bytes < 10 && u > 0 ? "%.1f %s" : "%.0f %s", bytes, units[u]);
  return buf;
}

void check_memory(double bytes, const std::string& what, const std::string& advice) {
  const double have = physical_memory_bytes();
  if (have <= 0 || bytes <= have) return;
  throw std::invalid_argument(what + ": the run needs about " + format_bytes(bytes) +
                              " of memory, more than the " + format_bytes(have) +
                              " of this machine: " + advice);
}

}  // namespace weilgen
