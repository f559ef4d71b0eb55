#include "weilgen/measure/comp_table.hpp"

#include <cmath>
#include <stdexcept>

#include "weilgen/base/constants.hpp"
#include "weilgen/base/format.hpp"

namespace weilgen {

namespace {
constexpr double kMmPerInch = 25.4;
}  // namespace

void CompTable::validate() const {
  const std::string what = "compensation table of " + axis + ": ";
  if (nominal.empty()) throw std::invalid_argument(what + "no entries");
  if (nominal.size() > kMaxCompEntries)
    throw std::invalid_argument(what + std::to_string(nominal.size()) +
                                " entries; LinuxCNC takes at most " +
                                std::to_string(kMaxCompEntries) + " per joint");
  if (forward.size() != nominal.size() || reverse.size() != nominal.size())
    throw std::invalid_argument(what + "columns of different lengths");
  for (std::size_t i = 0; i < nominal.size(); ++i) {
    if (!std::isfinite(nominal[i]) || !std::isfinite(forward[i]) || !std::isfinite(reverse[i]))
      throw std::invalid_argument(what + "a value at nominal " + format_short(nominal[i]) +
                                  " is not finite");
    if (i > 0 && !(nominal[i] > nominal[i - 1]))
      throw std::invalid_argument(what + "nominal positions must increase (" +
                                  format_short(nominal[i - 1]) + ", then " +
                                  format_short(nominal[i]) + ")");
  }
}

void CompTableOptions::validate() const {
  if (type != 0 && type != 1)
    throw std::invalid_argument("--comp-type " + std::to_string(type) +
                                ": COMP_FILE_TYPE is 0 (positions) or 1 (trims)");
  if (linear_unit != "mm" && linear_unit != "inch")
    throw std::invalid_argument("--comp-units " + linear_unit +
                                ": a linear axis' machine units are mm or inch");
  if (source != "classical" && source != "drift")
    throw std::invalid_argument("--comp-source " + source + ": classical or drift");
}

double to_machine_units(double value_mm_or_deg, bool rotary, const CompTableOptions& options) {
  return rotary || options.linear_unit == "mm" ? value_mm_or_deg : value_mm_or_deg / kMmPerInch;
}

std::string machine_unit(bool rotary, const CompTableOptions& options) {
  return rotary ? "deg" : options.linear_unit;
}

CompTable comp_table_from_iso(const Iso230_2StudyResult& r, const CompTableOptions& options) {
  options.validate();
  const bool rotary = r.columns.unit == "urad";
  const IsoFigures* figures = &r.classical.figures;
  if (options.source == "drift") {
    if (!r.drift)
      throw std::invalid_argument(
          r.iso_only ? "--comp-source drift: --iso-only computes no drift-eliminated evaluation"
                     : "--comp-source drift: no drift-eliminated evaluation (it needs at least 2 "
                       "targets)");
    figures = &r.drift->figures;
  }
  // Deviations µm -> mm, µrad -> deg; the axis column is in mm (deg for a rotary axis).
  const double scale = rotary ? 1e-6 * 180.0 / kPi : 1e-3;
  CompTable t;
  t.axis = r.columns.axis;
  t.unit = machine_unit(rotary, options);
  for (std::size_t i = 0; i < r.runs.positions_mm.size(); ++i) {
    t.nominal.push_back(to_machine_units(r.runs.positions_mm[i], rotary, options));
    t.forward.push_back(to_machine_units(figures->mean_up[i] * scale, rotary, options));
    t.reverse.push_back(to_machine_units(figures->mean_down[i] * scale, rotary, options));
  }
  t.validate();
  return t;
}

}  // namespace weilgen
