// numeric_golden_check GOLDEN FRESH: exit 0 when FRESH equals the committed GOLDEN file up to
// floating-point rounding (tests/golden/numeric_text.hpp), else 1 with the first difference.
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "golden/numeric_text.hpp"

namespace {

bool read(const char* path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  text = s.str();
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: numeric_golden_check GOLDEN FRESH\n";
    return 2;
  }
  std::string golden, fresh;
  if (!read(argv[1], golden) || !read(argv[2], fresh)) {
    std::cerr << "cannot read " << (golden.empty() ? argv[1] : argv[2]) << "\n";
    return 2;
  }
  const std::string why =
      weilgen::golden::numeric_text_mismatch(golden, fresh, weilgen::golden::kParamsRelTol);
  if (why.empty()) return 0;
  std::cerr << argv[1] << " is stale (cmake --build <build> --target update_generated):\n"
            << why << "\n";
  return 1;
}
