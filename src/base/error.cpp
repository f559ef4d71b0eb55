#include "weilgen/base/error.hpp"

namespace weilgen {

std::string SourceLoc::str() const {
  std::string s = file;
  if (line > 0) {
    s += ":" + std::to_string(line);
    if (column > 0) s += ":" + std::to_string(column);
  }
  return s;
}

InputError::InputError(const SourceLoc& loc, const std::string& message)
    : std::runtime_error(loc.str().empty() ? message : loc.str() + ": " + message),
      loc_(loc),
      message_(message) {}

}  // namespace weilgen
