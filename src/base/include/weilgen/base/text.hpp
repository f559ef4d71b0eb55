// Text helpers: joining, case, trimming, splitting and quoting, for messages and parsers.
// Numbers are formatted in weilgen/base/format.hpp.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace weilgen {

// "a, b, c".
std::string join(const std::vector<std::string>& items);
// ASCII lower case.
std::string lower(std::string s);
// Without leading and trailing blanks (space, tab, CR, LF).
std::string trim(const std::string& s);
// Splits at every `sep` (empty items kept).
std::vector<std::string> split(const std::string& s, char sep);
// "\"text\"" for messages.
std::string quoted(const std::string& s);
// `s` cut to at most `max` characters with "..." for messages that quote user text (a 200 kB
// expression is shown by its start).
std::string abbreviated(const std::string& s, std::size_t max = 60);

}  // namespace weilgen
