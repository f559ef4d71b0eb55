#include "weilgen/codegen/emit_compensation.hpp"

#include <stdexcept>

namespace weilgen::gen {

// The text of templates/compensate.hpp after its marker line, embedded at build time
// (src/codegen/CMakeLists.txt).
extern const char* const kCompensateTemplate;

std::string compensation_code(bool weigh_orientation) {
  std::string s = kCompensateTemplate;
  const std::string key = "WEILGEN_TEMPLATE_ORIENTATION";
  const auto at = s.find(key);
  if (at == std::string::npos) throw std::logic_error("compensate template: no " + key);
  s.replace(at, key.size(), weigh_orientation ? "true" : "false");
  return s;
}

}  // namespace weilgen::gen
