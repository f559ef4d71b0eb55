// 6D line measurements: the six errors of one linear axis versus its position, as a 6D laser
// interferometer reports them in a single run, converted to the ISO 230-1 error names of that
// axis (X: E_XX, E_YX, E_ZX, E_AX, E_BX, E_CX) with the sign conversions of Zhang & Chen 2021's
// Table 2, and the straightness reference line removed by least squares (Zhang & Chen 2021, eq.
// (1)). CSV variant (`# format: line6d`, `# axis: X`) and every sign and choice:
// docs/data-format.md, section "6D line measurements".
#pragma once

#include <map>
#include <string>
#include <vector>

#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

// The six channels of a 6D laser, in the instrument's terms (Zhang & Chen 2021's Table 2 rows).
enum class LaserChannel { Linear, StraightnessH, StraightnessV, Yaw, Pitch, Roll };
constexpr int kLaserChannels = 6;

// CSV column of a channel: lin_um, str_h_um, str_v_um, yaw_urad, pitch_urad, roll_urad.
const char* laser_column(LaserChannel channel);

// Where a laser channel goes: value(iso) = sign * value(laser).
struct ChannelMapping {
  LaserChannel channel = LaserChannel::Linear;
  std::string iso;  // "E_CX"
  int sign = 1;     // +1 or -1
  std::string why;  // where the sign comes from (for reports)
};

// The default mapping of the linear axis "X", "Y" or "Z". The laser's beam runs along the axis
// K; its horizontal straightness channel measures along H, its vertical one along V; yaw is the
// rotation about V, pitch about H, roll about K. X: (H, V) = (Y, Z), exactly Zhang & Chen 2021,
// Table 2; Y: (X, Z); Z: (X, Y). Signs (Table 2): linear channels +1; yaw -1; pitch -1; roll +1.
// Throws std::invalid_argument for other axes.
std::vector<ChannelMapping> line6d_default_mapping(const std::string& axis);

// Overrides parts of `mapping` from a `# map:` header value, e.g.
// "yaw_urad=-E_CY, pitch_urad=-E_AY, str_h_um=E_ZY": each item a laser column, '=', an optional
// sign and one of the axis' six ISO names. Throws std::invalid_argument naming the bad item, and
// when two channels end up on the same ISO error.
std::vector<ChannelMapping> apply_line6d_map(std::vector<ChannelMapping> mapping,
                                             const std::string& axis, const std::string& text);

// E_XK, E_YK, E_ZK, E_AK, E_BK, E_CK for axis K.
std::vector<std::string> line6d_iso_errors(const std::string& axis);
// The CSV column of an ISO error of a line measurement: "E_YX_um", "E_AX_urad".
std::string line6d_iso_column(const std::string& iso);

// Zhang & Chen 2021, eq. (1): the least-squares line y ≈ intercept + slope·x of a profile; rows
// whose y is NaN are ignored. Throws std::invalid_argument with fewer than two distinct positions.
struct ReferenceLine {
  double intercept = 0;  // unit of y at x = 0
  double slope = 0;      // unit of y per mm
  double at(double x) const { return intercept + slope * x; }
};
ReferenceLine least_squares_line(const std::vector<double>& x, const std::vector<double>& y);
// y minus its least-squares line (NaN stays NaN); the line in *line when given.
std::vector<double> remove_reference_line(const std::vector<double>& x,
                                          const std::vector<double>& y,
                                          ReferenceLine* line = nullptr);

enum class ProfileKind { Positioning, Straightness, Angular };
const char* profile_kind_name(ProfileKind kind);  // "positioning", "straightness", "angular"

// What is removed from each kind of profile (after the sign conversion).
enum class AngularReference { Mean, None };
struct Line6dOptions {
  // Straightness: the least-squares line (eq. (1)); the beam's alignment to the axis is
  // arbitrary, and the line's slope belongs to the squareness, not to the straightness.
  bool remove_straightness_line = true;
  // Angular: the mean (a least-squares constant). The laser head's angular zero is set by its
  // alignment, not by the machine, so only the variation along the travel is the axis' error.
  AngularReference angular = AngularReference::Mean;
  // Positioning: kept as measured (the interferometer is zeroed at the start of the run).
};

struct Line6dProfile {
  std::string error;  // ISO name, "E_YX"
  std::string unit;   // "um" or "urad"
  ProfileKind kind = ProfileKind::Positioning;
  std::string source;          // CSV column it came from ("str_h_um" or "E_YX_um")
  int sign = 1;                // applied to the source
  std::string removed;         // "line", "mean" or "none"
  ReferenceLine reference;     // what was removed (intercept only for "mean"; zero for "none")
  std::vector<double> raw;     // sign * source, one per row (NaN = not measured)
  std::vector<double> values;  // raw minus the reference, one per row
};

struct Line6dData {
  std::string file;                     // CSV path ("" from plain vectors)
  std::string axis;                     // "X"
  std::string spelling;                 // "laser" (instrument channels) or "iso"
  std::vector<double> position;         // the axis coordinate of each row (mm)
  std::vector<int> cycle;               // one per row, or empty without a cycle column
  std::vector<Line6dProfile> profiles;  // those present, in the order E_XK .. E_CK
  // The profile of an ISO error, or nullptr.
  const Line6dProfile* find(const std::string& error) const;
};

// From plain vectors: `columns` maps CSV column names (laser channels or ISO columns, not both
// for the same error) to one value per position. Throws std::invalid_argument for unknown
// columns, mixed spellings of one error, size mismatches, non-finite positions or a straightness
// profile with fewer than two measured positions.
Line6dData convert_line6d(const std::string& axis, const std::vector<double>& position,
                          const std::map<std::string, std::vector<double>>& columns,
                          const std::vector<ChannelMapping>& mapping,
                          const Line6dOptions& options = {});

// The CSV variant. is_line6d: the `# format:` header key says line6d.
bool is_line6d(const MeasurementTable& table);
// Reader options accepting every laser and ISO column of the X, Y and Z axes.
ReadOptions line6d_read_options();
// Converts a table read with line6d_read_options(): `# axis:` (required), `# map:` (optional).
// Throws InputError "file:line: ..." for a missing or bad axis, a bad map, a missing axis column
// or a table without any 6D column.
Line6dData line6d_from_table(const MeasurementTable& table, const Line6dOptions& options = {});
// read_measurements(path, line6d_read_options()) then line6d_from_table; InputError when the
// file is not `# format: line6d`.
Line6dData read_line6d(const std::string& path, const Line6dOptions& options = {});

}  // namespace weilgen
