// Ballbar circular tests (ISO 230-4) predicted from an error model and evaluated: the circle
// (plane, centre, radius, feed) from a trace file's header keys and flags, the machine poses of
// the circle, the predicted radial deviation dr(θ), the ISO 230-4 figures (centre offset,
// circular deviation G, radial deviation F, hysteresis H), the harmonics of the trace, and the
// comparison of a prediction with a measured trace. Definitions, approximations and the 6D-laser
// Zhang & Chen 2021's section 4: docs/ballbar.md; the file format: docs/data-format.md, "Ballbar
// traces".
//
// Angles: θ is measured in the plane from its first coordinate toward its second (XY: from +X
// toward +Y). A pose at θ has first = c1 + R cos θ, second = c2 + R sin θ (R converted to the
// axes' units) and every other coordinate at its centre value. Feed +1 (ccw) is θ increasing,
// -1 (cw) θ decreasing, whatever the plane's name.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"
#include "weilgen/measure/measurement_csv.hpp"

namespace weilgen {

// The model's deviation at one pose: axes in Description::axes() order and units; out6 =
// (dx, dy, dz) mm and (da, db, dc) rad of the tool relative to the workpiece, workpiece frame
// (as Model::deviation).
using DeviationFn = std::function<void(const double* axes, double* out6)>;
// The nominal tool position relative to the workpiece, workpiece frame, mm (zero errors).
using NominalFn = std::function<void(const double* axes, double* position_mm)>;

// What the ballbar functions need to know of a machine.
struct BallbarMachine {
  std::string name;                      // for messages ("vmc_3axis"; "" for a bare list)
  std::vector<std::string> coordinates;  // input axes, Description::axes() order
  std::vector<std::string> units;        // each axis's unit (Joint::unit: "mm", "deg", "m" ...)
  std::vector<double> to_base;           // unit -> mm (linear) or rad (rotary)
  std::vector<bool> prismatic;           // false: rotary
  std::vector<double> min, max;          // travel in axis units; min == max: no range known
  // Empty: the letter rule, coordinate X (or U) moves the tool relative to the workpiece along
  // +x, Y (V) along +y, Z (W) along +z. A machine whose table carries an axis moves the tool
  // the other way: use ballbar_machine(Description) (analysis/ballbar_model.hpp) for real
  // machines.
  NominalFn nominal;
};

// Linear axes in mm, no ranges, the letter rule.
BallbarMachine ballbar_machine_by_letters(const std::vector<std::string>& coordinates);
struct BallbarCircle {
  std::string plane;          // first + second coordinate name: "XY", "ZX", "XZ" ...
  std::string first, second;  // the in-plane coordinates (θ from +first toward +second)
  // Every machine coordinate -> its centre value (axis unit: mm, deg); a coordinate the key does
  // not name is 0.
  std::map<std::string, double> centre;
  double radius_mm = 0;
  int feed = 1;                // +1 ccw (θ increasing), -1 cw
  double start_angle_deg = 0;  // first angle of predictions
  // "plane", "centre", "radius", "feed" -> where the setting came from: file and line of the
  // header key, or file "--plane" (line 0) for a flag. Absent: not given (feed: default ccw).
  std::map<std::string, SourceLoc> sources;
};

// Flag values in the header keys' syntax; a non-empty flag overrides the header key.
struct BallbarFlags {
  std::string plane;   // "XY"; also "X,Y" or "X Y" (needed for multi-letter coordinates)
  std::string centre;  // "X=250, Y=0, Z=-100" (units allowed: "Y=0.1m"; default the axis unit)
  std::string radius;  // "150 mm", "0.15 m"; mm when no unit is written
  std::string feed;    // "ccw" or "cw" (case-insensitive)
};

// The circle of a ballbar trace file (`# plane:`, `# centre:`, `# radius:`, `# feed:`) with
// `flags` overriding. Plane, centre and radius are required, feed defaults to ccw. Checks: the
// plane names two distinct linear coordinates of the machine, the centre names known
// coordinates at most once, radius > 0, and the circle and centre lie within the axis ranges.
// A bad header key throws InputError "file:line: ballbar: '# radius: 0 mm': the radius must be
// > 0" (a missing key names the header row's line); a bad flag throws std::invalid_argument
// "--radius: \"0\": the radius must be > 0".
BallbarCircle parse_ballbar_circle(const MeasurementTable& table, const BallbarMachine& machine,
                                   const BallbarFlags& flags = {});
// From flags alone (a prediction without a data file); plane, centre and radius are required.
BallbarCircle parse_ballbar_circle(const BallbarFlags& flags, const BallbarMachine& machine);

// The pose at angle θ (Description::axes() order and units).
std::vector<double> ballbar_pose(const BallbarMachine& machine, const BallbarCircle& circle,
                                 double angle_deg);
// The unit vector from the table ball to the tool ball at each angle (workpiece frame, nominal
// kinematics): to first order dr = direction · (dx, dy, dz). Throws as predict_ballbar.
std::vector<std::array<double, 3>> ballbar_directions(const BallbarMachine& machine,
                                                      const BallbarCircle& circle,
                                                      const std::vector<double>& angles_deg);
// `points` angles in feed order from start_angle_deg, evenly spaced over one turn, each reduced
// to [0, 360): ccw 0, 1, ..., 359; cw 0, 359, ..., 1 (points = 360).
std::vector<double> ballbar_angles(const BallbarCircle& circle, std::size_t points);

// A trace: dr (µm, positive outward) at angles θ (deg), in the order of the feed.
struct BallbarTrace {
  std::vector<double> angle_deg;
  std::vector<double> dr_um;
  int feed = 1;            // +1 ccw, -1 cw
  int cycle = 0;           // measured: the `cycle` column's value (0 without one)
  std::vector<int> lines;  // measured: each point's source line; empty for predictions
  std::size_t size() const { return angle_deg.size(); }
};

// How the deviation becomes a change of the ball distance.
//   FirstOrder: dr = u·d, u the nominal unit vector from the table ball to the tool ball.
//   Exact:      dr = |v + d| − |v|, v the nominal table-ball-to-tool-ball vector.
// 0 <= Exact − FirstOrder <= d_t² / (2 (R + u·d)), d_t the part of d perpendicular to u.
enum class RadialProjection { FirstOrder, Exact };

// The predicted trace at `points` angles in feed order (ballbar_angles). The table ball sits at
// the nominal centre; the tool ball at the model's tool point. Throws std::invalid_argument when
// the machine's nominal motions of the two coordinates are not orthogonal unit vectors in the
// workpiece frame (the circle would not be a circle), or the deviation is not finite.
BallbarTrace predict_ballbar(const BallbarMachine& machine, const BallbarCircle& circle,
                             const DeviationFn& deviation, std::size_t points = 360,
                             RadialProjection projection = RadialProjection::FirstOrder);
// The same at given angles (any order; feed and start of the result from the circle).
BallbarTrace predict_ballbar_at(const BallbarMachine& machine, const BallbarCircle& circle,
                                const DeviationFn& deviation, const std::vector<double>& angles_deg,
                                RadialProjection projection = RadialProjection::FirstOrder);

// The measured traces of a ballbar file: columns angle_deg and dr_um (required), dir and cycle
// (optional); one trace per (dir, cycle) in order of first appearance, rows in file order. A row
// without dir takes circle.feed. An empty dr_um cell is a point not measured (skipped); an empty
// angle_deg cell with a measured dr_um is an InputError naming the row's line.
std::vector<BallbarTrace> ballbar_traces(const MeasurementTable& table,
                                         const BallbarCircle& circle);

struct BallbarHarmonic {
  int order = 0;  // k: the term cos_um·cos kθ + sin_um·sin kθ
  double cos_um = 0, sin_um = 0;
  double amplitude_um = 0;  // hypot(cos_um, sin_um)
  double phase_deg = 0;     // the term is amplitude·cos(k (θ − phase)); phase in [0, 360/k)
};

// ISO 230-4 figures of one trace, with the least-squares (LSQ) centre.
struct BallbarEvaluation {
  std::size_t points = 0;
  double coverage_deg = 0;  // 360 − the largest angular gap between neighbouring points
  // The LSQ fit dr ≈ c + a cos θ + b sin θ (the linearised LSQ circle).
  // (a, b): the traced circle's centre relative to the table ball, along +first and +second.
  std::array<double, 2> centre_offset_um{};
  double radius_deviation_um = 0;      // c
  double max_minus_min_um = 0;         // max dr − min dr, centre not removed
  std::vector<double> centred_um;      // dr − a cos θ − b sin θ, input order
  double circular_deviation_um = 0;    // G = max − min of centred_um
  double radial_deviation_max_um = 0;  // F: max and min of centred_um (from nominal R)
  double radial_deviation_min_um = 0;
  // The minimum zone (ISO 230-4's G with the minimum-zone centre): the centre (µm, as
  // centre_offset_um) of the two concentric circles of least radial separation that enclose the
  // trace (linearised, exact as a linear programme), that separation, and the radius deviation
  // of the circle midway between them. G_mz <= G.
  std::array<double, 2> mz_centre_offset_um{};
  double mz_circular_deviation_um = 0;
  double mz_radius_deviation_um = 0;
  // Joint LSQ fit of orders 0..max_harmonic; orders 2..max_harmonic reported. Empty unless
  // there are 2·max_harmonic + 1 distinct angles and no gap of 180°/max_harmonic or more.
  std::vector<BallbarHarmonic> harmonics;
  // The 2θ term read as the two classic ballbar causes (µrad, µm/m), both along the coordinate
  // directions: out-of-squareness S with d_first = S·(second − c2) (the angle between the two
  // motions is 90° − S), sin term = S·R/2; scale mismatch k1 − k2 with d_i = k_i·(coord − c_i),
  // cos term = (k1 − k2)·R/2. NaN without harmonics.
  double squareness_urad = 0;
  double scale_mismatch_um_per_m = 0;
};

// Throws std::invalid_argument when angles and values differ in size, a value is not finite,
// radius_mm <= 0, max_harmonic < 1, or fewer than 3 distinct angles.
BallbarEvaluation evaluate_ballbar(const std::vector<double>& angle_deg,
                                   const std::vector<double>& dr_um, double radius_mm,
                                   int max_harmonic = 4);
BallbarEvaluation evaluate_ballbar(const BallbarTrace& trace, double radius_mm,
                                   int max_harmonic = 4);

// The minimum zone of dr(θ): min over (a, b) of max − min of dr − a cos θ − b sin θ, solved as a
// linear programme (its dual has four rows: a revised simplex). Returns the centre (a, b), the
// zone's width and its mid value; throws std::invalid_argument for fewer than 4 distinct angles.
struct MinimumZone {
  std::array<double, 2> centre_um{};
  double width_um = 0, mid_um = 0;
};
MinimumZone minimum_zone(const std::vector<double>& angle_deg, const std::vector<double>& dr_um);

// The direction of travel of an in-plane axis at each point of a trace (ISO 230-4 circles: the
// first coordinate moves as cos θ, the second as sin θ): +1 or −1, the direction in which the axis
// approached the point, so a point exactly at a reversal (θ = 0° or 180° for the first axis,
// 90° or 270° for the second) belongs to the motion before it. `axis` 0: first, 1: second.
std::vector<int> ballbar_travel_direction(const std::vector<double>& angle_deg, int feed, int axis);

// Linear interpolation of a trace at `angles_deg`, periodic in 360°; points at the same angle
// (an overrun) are averaged. Throws std::invalid_argument when the trace has a gap wider than
// max_gap_deg (it does not cover the circle) or fewer than 2 distinct angles.
std::vector<double> interpolate_trace(const BallbarTrace& trace,
                                      const std::vector<double>& angles_deg,
                                      double max_gap_deg = 15);

// ISO 230-4 circular hysteresis H: the largest |a(θ) − b(θ)| over a's angles, b interpolated.
double circular_hysteresis_um(const BallbarTrace& a, const BallbarTrace& b,
                              double max_gap_deg = 15);

// measured − predicted at the measured angles.
struct TraceDifference {
  double mean_um = 0;
  double rms_um = 0;
  double max_abs_um = 0;
  double correlation = 0;  // Pearson's r of measured and predicted; NaN when one is constant
};

struct BallbarComparison {
  int feed = 1, cycle = 0;  // the measured trace's direction (+1 ccw, -1 cw) and cycle
  std::vector<double> angle_deg, measured_um, predicted_um;  // the measured points, file order
  TraceDifference raw;                                       // as measured and predicted
  TraceDifference centred;  // each with its own LSQ centre (a, b) removed (the set-up offset)
  BallbarEvaluation measured, predicted;  // both at the measured angles
  // measured − predicted: its G is Zhang & Chen 2021's "circularity after ideal compensation".
  BallbarEvaluation difference;
};

// Compares a measured trace with a prediction (interpolated at the measured angles, see
// interpolate_trace; a prediction made at the measured angles is used as is).
BallbarComparison compare_ballbar(const BallbarTrace& measured, const BallbarTrace& predicted,
                                  double radius_mm, double max_gap_deg = 15, int max_harmonic = 4);

}  // namespace weilgen
