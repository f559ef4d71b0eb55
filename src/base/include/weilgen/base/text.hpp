// Small text helpers shared by the machine loader and the study-input parsers' messages.
#pragma once

#include <cctype>
#include <cstdio>
#include <string>
#include <vector>

namespace weilgen {

// "a, b, c".
inline std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// ASCII lower case.
inline std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// A number for messages: "%g" (1000, 0.05, 1e-06).
inline std::string format_short(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace weilgen
