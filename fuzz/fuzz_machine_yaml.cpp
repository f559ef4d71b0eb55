// libFuzzer harness: machine yaml (fuzz/README.md). The oracle is in targets.hpp.
#include <cstddef>
#include <cstdint>
#include <string>

#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  weilgen::fuzz::machine_yaml(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
