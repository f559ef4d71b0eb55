// The numeric golden comparison (tests/golden/numeric_text.hpp) itself: it must fail on a real
// change and pass on rounding.
#include <doctest/doctest.h>

#include "golden/numeric_text.hpp"

using weilgen::golden::numeric_text_mismatch;
using weilgen::golden::split_numbers;

TEST_CASE("numeric golden: numbers glued to identifiers stay text, signs and exponents parse") {
  const auto s = split_numbers("kE_X3 = {{-1.5e-06, 0.25, +.5}}; key \"5c916ea7\" rank 46 of 75");
  CHECK(s.text == "kE_X3 = {{#, #, #}}; key \"#c916ea7\" rank # of #");
  REQUIRE(s.numbers.size() == 6);
  CHECK(s.numbers[0] == -1.5e-06);
  CHECK(s.numbers[1] == 0.25);
  CHECK(s.numbers[2] == 0.5);
  CHECK(s.numbers[3] == 5);
  CHECK(s.numbers[4] == 46);
}

TEST_CASE("numeric golden: rounding passes, a real change or any text change fails") {
  const std::string golden =
      "// rank 46 of 75\nk = {{0.0028541741934906256, 1.9984444444887025e-06}};\n";
  // The last bits seen between two CPUs: relative to the line's largest number 4e-16.
  CHECK(numeric_text_mismatch(
            golden, "// rank 46 of 75\nk = {{0.0028541741934906286, 1.99844444448924e-06}};\n",
            1e-9) == "");
  // A change of 1e-6 relative is a different identification.
  const std::string moved = numeric_text_mismatch(
      golden, "// rank 46 of 75\nk = {{0.0028541770000000000, 1.99844e-06}};\n", 1e-9);
  CHECK(moved.find("line 2: number 1 differs") == 0);
  CHECK(numeric_text_mismatch(
            golden, "// rank 45 of 75\nk = {{0.0028541741934906256, 1.9984444444887025e-06}};\n",
            1e-9)
            .find("line 1: number 1 differs") == 0);
  CHECK(numeric_text_mismatch(
            golden, "// rank 46 of 75\nkk = {{0.0028541741934906256, 1.9984444444887025e-06}};\n",
            1e-9)
            .find("line 2: text differs") == 0);
  CHECK(numeric_text_mismatch(golden, "// rank 46 of 75\n", 1e-9) ==
        "1 lines, the golden file has 2");
}
