#include "weilgen/report/csv_table.hpp"

#include <stdexcept>

#include "weilgen/base/units.hpp"
#include "weilgen/report/json_common.hpp"

namespace weilgen {

std::string csv_column_name(const std::string& name, const std::string& unit) {
  if (unit.empty()) return name;
  std::string u = ascii_unit(unit);
  if (u == "%") return name + "_percent";
  if (u.rfind("1/", 0) == 0) return name + "_per_" + u.substr(2);
  std::string out;
  for (char c : u) out += c == '/' ? std::string("_per_") : std::string(1, c);
  return name + "_" + out;
}

void CsvTable::comment(const std::string& text) { comments_.push_back(text); }

void CsvTable::column(const std::string& name, const std::string& unit) {
  header_.push_back(csv_field(csv_column_name(name, unit)));
}

void CsvTable::pose_columns(const PoseSet& poses) {
  for (std::size_t a = 0; a < poses.axes.size(); ++a)
    column(poses.axes[a], a < poses.units.size() ? poses.units[a] : "");
}

CsvTable& CsvTable::text(const std::string& s) {
  row_.push_back(csv_field(s));
  return *this;
}

CsvTable& CsvTable::number(double v) {
  row_.push_back(csv_number(v));
  return *this;
}

CsvTable& CsvTable::count(std::size_t n) {
  row_.push_back(std::to_string(n));
  return *this;
}

CsvTable& CsvTable::pose(const std::vector<double>& values) {
  for (double v : values) number(v);
  return *this;
}

void CsvTable::end_row() {
  if (row_.size() != header_.size())
    throw std::logic_error("CsvTable: a row of " + std::to_string(row_.size()) + " cells for " +
                           std::to_string(header_.size()) + " columns");
  for (std::size_t i = 0; i < row_.size(); ++i) body_ += (i ? "," : "") + row_[i];
  body_ += "\n";
  row_.clear();
}

std::string CsvTable::str() const {
  std::string s;
  for (const std::string& c : comments_) s += "# " + c + "\n";
  for (std::size_t i = 0; i < header_.size(); ++i) s += (i ? "," : "") + header_[i];
  return s + "\n" + body_;
}

}  // namespace weilgen
