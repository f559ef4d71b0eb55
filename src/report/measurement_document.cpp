#include "weilgen/report/measurement_document.hpp"

#include <algorithm>
#include <sstream>

#include "weilgen/base/format.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

namespace {

const char* format_name(InstrumentFormat f) {
  switch (f) {
    case InstrumentFormat::Carto:
      return "CARTO wide CSV";
    case InstrumentFormat::Wide:
      return "generic wide CSV";
    case InstrumentFormat::Tidy:
      break;
  }
  return "tidy CSV";
}

}  // namespace

std::string measurement_csv(const MeasurementTable& t, const std::vector<std::string>& comments) {
  std::ostringstream o;
  std::vector<std::pair<int, std::string>> keys;
  for (const auto& [k, v] : t.header_keys) {
    const auto it = t.header_key_lines.find(k);
    const int line = it == t.header_key_lines.end() || it->second <= 0 ? 1 << 30 : it->second;
    keys.emplace_back(line, k);
  }
  std::stable_sort(keys.begin(), keys.end());
  for (const auto& [line, k] : keys) o << "# " << k << ": " << t.header_keys.at(k) << "\n";
  for (const auto& c : comments) o << "# " << c << "\n";
  for (std::size_t i = 0; i < t.columns.size(); ++i) o << (i ? "," : "") << t.columns[i];
  o << "\n";
  for (std::size_t r = 0; r < t.rows(); ++r) {
    for (std::size_t i = 0; i < t.columns.size(); ++i)
      o << (i ? "," : "") << csv_number(t.values.at(t.columns[i])[r]);
    o << "\n";
  }
  return o.str();
}

std::vector<std::string> import_comments(const std::string& file, const ImportResult& r) {
  std::vector<std::string> out;
  out.push_back("written by weilgen import from " + file + " (" + format_name(r.format) + ", " +
                std::to_string(r.source_rows) + " rows)");
  for (const auto& m : r.mapping) out.push_back("  " + m);
  // A mapping line must not read as a header key ("key: value"): they start with a quote or
  // blank, which no key does.
  return out;
}

std::string import_summary(const std::string& file, const ImportResult& r) {
  std::ostringstream o;
  const auto axis = r.table.header_keys.find("axis");
  o << file << ": " << format_name(r.format) << ", " << r.source_rows << " rows -> "
    << r.table.rows() << " observations"
    << (axis == r.table.header_keys.end() ? std::string() : " (axis " + axis->second + ")") << "\n";
  for (const auto& m : r.mapping) o << "  " << m << "\n";
  return o.str();
}

}  // namespace weilgen
