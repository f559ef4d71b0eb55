// Numeric golden files: text compared exactly, numbers within a relative tolerance.
//
// A golden file that holds the result of a floating-point computation (the identified parameter
// header, generated/vmc_3axis_params.hpp) cannot be compared byte for byte: glibc's libm picks
// FMA/AVX code paths at run time and the compiler may contract or vectorise sums differently, so
// the last bits of a least-squares solution differ between CPUs and flags. Symbolic output
// (headers, reports, C API) stays exact and is compared byte for byte elsewhere.
#pragma once

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

namespace weilgen::golden {

// A line split into its text (numbers replaced by '#') and its numbers. A number is a decimal
// literal not glued to an identifier: "kE_X3" and the hex digits of "5c916ea7" stay text.
struct SplitLine {
  std::string text;
  std::vector<double> numbers;
};

inline SplitLine split_numbers(const std::string& line) {
  SplitLine s;
  std::size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    const char prev = i > 0 ? line[i - 1] : ' ';
    const bool glued = std::isalnum(static_cast<unsigned char>(prev)) || prev == '_' || prev == '.';
    const bool starts = std::isdigit(static_cast<unsigned char>(c)) ||
                        ((c == '-' || c == '+' || c == '.') && i + 1 < line.size() &&
                         (std::isdigit(static_cast<unsigned char>(line[i + 1])) ||
                          (line[i + 1] == '.' && i + 2 < line.size() &&
                           std::isdigit(static_cast<unsigned char>(line[i + 2])))));
    if (!glued && starts) {
      char* end = nullptr;
      const double v = std::strtod(line.c_str() + i, &end);
      const std::size_t n = static_cast<std::size_t>(end - (line.c_str() + i));
      if (n > 0 && std::isfinite(v)) {
        s.numbers.push_back(v);
        s.text += '#';
        i += n;
        continue;
      }
    }
    s.text += c;
    ++i;
  }
  return s;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// "" when `actual` equals `expected` up to numbers that differ by at most
// rel_tol × (the largest magnitude on the expected line), else the first difference with its
// line number. Scaling by the line's largest number keeps a coefficient near zero in an array of
// millimetres from failing on rounding it cannot have below the array's own precision.
inline std::string numeric_text_mismatch(const std::string& expected, const std::string& actual,
                                         double rel_tol) {
  const std::vector<std::string> e = lines_of(expected), a = lines_of(actual);
  if (e.size() != a.size())
    return std::to_string(a.size()) + " lines, the golden file has " + std::to_string(e.size());
  for (std::size_t k = 0; k < e.size(); ++k) {
    const SplitLine se = split_numbers(e[k]), sa = split_numbers(a[k]);
    const std::string where = "line " + std::to_string(k + 1) + ": ";
    if (se.text != sa.text || se.numbers.size() != sa.numbers.size())
      return where + "text differs:\n  golden: " + e[k] + "\n  actual: " + a[k];
    double scale = 0;
    for (double v : se.numbers) scale = std::max(scale, std::abs(v));
    for (std::size_t j = 0; j < se.numbers.size(); ++j) {
      const double d = std::abs(se.numbers[j] - sa.numbers[j]);
      if (d > rel_tol * scale) {
        std::ostringstream msg;
        msg.precision(17);
        msg << where << "number " << j + 1 << " differs by " << d << " (tolerance "
            << rel_tol * scale << "):\n  golden: " << e[k] << "\n  actual: " << a[k];
        return msg.str();
      }
    }
  }
  return "";
}

// The tolerance of the identified parameter header: the coefficients come from an SVD
// least-squares solve whose last bits vary with the CPU's libm paths and the compiler's
// contraction (observed: 4e-16 of the line's largest coefficient between an AMD EPYC and an
// Intel Xeon); a real change of the data, the basis or the solver moves them by 1e-6 or more.
inline constexpr double kParamsRelTol = 1e-9;

}  // namespace weilgen::golden
