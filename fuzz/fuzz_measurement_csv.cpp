// libFuzzer harness: measurement csv (fuzz/README.md). The oracle is in targets.hpp.
#include <cstddef>
#include <cstdint>
#include <string>

#include "targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  weilgen::fuzz::measurement_csv(std::string(reinterpret_cast<const char*>(data), size));
  return 0;
}
