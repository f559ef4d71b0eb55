// The outputs of every machine model, in one place: the deviation of the tool point relative to
// the workpiece, dx dy dz (mm) and da db dc (rad), and dp = |(dx, dy, dz)| (mm), which studies
// derive from the first three. Generated code, studies, measurements and reports all name and
// order the outputs from here.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace weilgen {

enum class OutputId { Dx, Dy, Dz, Da, Db, Dc, Dp };
// dx ... dc: what a model computes (generated Deviation, Model::deviation), in this order.
inline constexpr int kNumDeviationOutputs = 6;
// dx ... dp.
inline constexpr int kNumOutputs = 7;

const std::vector<OutputId>& all_outputs();  // Dx ... Dp
const char* output_name(OutputId id);        // "dx"
// Outputs 0..6 (dx ... dp) by index, for per-output arrays.
inline const char* output_name(std::size_t index) {
  return output_name(static_cast<OutputId>(index));
}
const char* output_unit(OutputId id);  // "mm" or "rad"
inline const char* output_unit(std::size_t index) {
  return output_unit(static_cast<OutputId>(index));
}
bool output_is_angle(OutputId id);  // da, db, dc
// "dx" ... "dp" (case-insensitive); throws std::invalid_argument listing the outputs.
OutputId parse_output(const std::string& name);

// Measurements give deviations in µm and µrad (docs/data-format.md): the factor from the model's
// mm and rad, the unit, and the column name of each deviation output 0..5.
inline constexpr std::array<double, kNumDeviationOutputs> kMeasuredScale = {1e3, 1e3, 1e3,
                                                                            1e6, 1e6, 1e6};
const char* measured_unit(std::size_t output);  // "µm" for dx dy dz, "µrad" for da db dc
extern const std::array<const char*, kNumDeviationOutputs> kDeviationColumns;  // "dx_um" ...

}  // namespace weilgen
