// What weilgen's HTML reports share (internal to the report layer): the style sheet and the
// ASCII units of the shared text statements in print.
#pragma once

#include <cctype>
#include <string>

namespace weilgen {

// The style of a self-contained report (inline, print styles keep tables and charts whole).
inline const char* report_style() {
  return R"(
body { font-family: Helvetica, Arial, sans-serif; font-size: 13px; color: #222; margin: 0;
       background: #fff; }
main { max-width: 1160px; margin: 0 auto; padding: 18px 20px 30px; }
header { border-bottom: 3px solid #1f3b63; margin-bottom: 10px; }
h1 { font-size: 21px; margin: 0 0 4px; color: #1f3b63; }
h2 { font-size: 16px; margin: 18px 0 6px; color: #1f3b63; border-bottom: 1px solid #c8d0dc; }
h3 { font-size: 14px; margin: 6px 0; }
.sub { color: #555; margin: 0 0 8px; }
table { border-collapse: collapse; }
td, th { border: 1px solid #c8d0dc; padding: 3px 7px; }
th { background: #eef2f7; text-align: left; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.sym { text-align: center; font-style: italic; }
td.na { color: #aaa; text-align: center; }
table.meta td:first-child { background: #f6f8fb; width: 150px; }
.pair { display: flex; gap: 16px; align-items: flex-start; }
.pair > div { flex: 1 1 0; min-width: 0; }
figure { margin: 8px 0; }
figcaption { color: #555; font-size: 12px; margin-top: 2px; }
.pass { color: #1a7f37; font-weight: bold; }
.open { color: #a15c00; font-weight: bold; }
.banner { border: 2px solid #c62828; background: #fdecea; padding: 6px 10px; margin: 10px 0; }
.banner p { margin: 0 0 4px; font-weight: bold; color: #c62828; }
.banner ul { margin: 0; padding-left: 20px; }
.warnings { border: 1px solid #a15c00; background: #fff4e0; padding: 6px 10px; margin: 8px 0; }
td.fill { min-width: 260px; }
table.budget { font-size: 11px; margin-top: 6px; }
p.note { color: #555; font-size: 12px; }
.fail { color: #c62828; font-weight: bold; }
.verdict { font-size: 15px; margin: 8px 0; }
ul.statements li { margin: 3px 0; }
table.env { margin-bottom: 4px; }
table.targets { font-size: 12px; }
.signature { display: flex; gap: 40px; margin-top: 28px; }
.signature div { flex: 1; border-top: 1px solid #444; padding-top: 4px; color: #444; }
footer { margin-top: 22px; color: #666; font-size: 11px; border-top: 1px solid #c8d0dc;
         padding-top: 6px; }
@media print { main { max-width: none; } .pair { break-inside: avoid; } }
)";
}

inline bool word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

// The ASCII units of the shared statements in print: um -> µm, urad -> µrad, degC -> °C,
// +- -> ±, alpha -> α, ".." -> "…" (whole words only).
inline std::string pretty(const std::string& s) {
  static const std::pair<const char*, const char*> words[] = {{"um", "\xC2\xB5m"},
                                                              {"urad", "\xC2\xB5rad"},
                                                              {"degC",
                                                               "\xC2\xB0"
                                                               "C"},
                                                              {"alpha", "\xCE\xB1"}};
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    bool done = false;
    for (const auto& [from, to] : words) {
      const std::size_t n = std::char_traits<char>::length(from);
      if (s.compare(i, n, from) == 0 &&
          (i == 0 || !std::isalpha(static_cast<unsigned char>(s[i - 1]))) &&
          (i + n >= s.size() || !word_char(s[i + n]))) {
        out += to;
        i += n;
        done = true;
        break;
      }
    }
    if (done) continue;
    if (s.compare(i, 2, "+-") == 0) {
      out += "\xC2\xB1";
      i += 2;
    } else if (s.compare(i, 4, " .. ") == 0) {
      out += " \xE2\x80\xA6 ";
      i += 4;
    } else {
      out += s[i++];
    }
  }
  return out;
}

}  // namespace weilgen
