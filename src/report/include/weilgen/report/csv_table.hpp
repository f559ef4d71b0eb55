// CSV documents, in one place: a header row whose column names carry their units
// ("X_mm", "A_deg", "tolerance_mm", "dR_dsigma_E_XX_per_mm"), then one row per record. Columns
// whose unit changes from row to row (a long table over outputs) get a unit column beside them
// ("coefficient", "coefficient_unit"). docs/study-inputs.md, "CSV files".
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "weilgen/analysis/study_spec.hpp"

namespace weilgen {

// "name" for a dimensionless column, else "name_unit" with the unit in ASCII: "X_mm",
// "dx_um" (from "µm"), "coefficient_mm_per_rad" (from "mm/rad"), "dR_dsigma_E_XX_per_mm"
// (from "1/mm"), "R_percent" (from "%").
std::string csv_column_name(const std::string& name, const std::string& unit);

class CsvTable {
 public:
  // Comment lines ("# machine: ...") written before the header, without the "# ".
  void comment(const std::string& text);
  void column(const std::string& name, const std::string& unit = "");
  // A column per axis of the poses: "X_mm", "C_deg".
  void pose_columns(const PoseSet& poses);

  // The next cell of the current row: text (quoted when needed) or a number (empty for NaN and
  // infinities).
  CsvTable& text(const std::string& s);
  CsvTable& number(double v);
  CsvTable& count(std::size_t n);
  CsvTable& pose(const std::vector<double>& values);  // the pose_columns' cells
  // Ends the row; throws std::logic_error when it does not have one cell per column.
  void end_row();

  std::size_t columns() const { return header_.size(); }
  std::string str() const;

 private:
  std::vector<std::string> comments_, header_;
  std::vector<std::string> row_;
  std::string body_;
};

}  // namespace weilgen
