// libFuzzer harness: tolerance files, read against the shipped gantry grinder (fuzz/README.md).
// The oracle is in targets.hpp.
#include <cstddef>
#include <cstdint>
#include <string>

#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const weilgen::Description machine =
      weilgen::load_machine_file(WEILGEN_SOURCE_DIR "/machines/gantry_grinder.yaml");
  weilgen::fuzz::tolerance_file(std::string(reinterpret_cast<const char*>(data), size), machine);
  return 0;
}
