// Identification of a machine model's error parameters from point measurements (issue 5 §4,
// docs/identify.md). Every error of the model becomes one or more parameters:
//   PIGE (or an error on a body without a joint)   one constant, in the error's declared unit;
//   PDGE                                           the coefficients of a basis (machine/
//                                                  pdge_basis.hpp) in the position of its own
//                                                  joint, on that joint's travel.
// At algebra order 1 the deviation is linear in the parameters, d = A θ, with A built from the
// generated coefficient matrix; it is solved by a column-equilibrated SVD, which also gives the
// rank, the minimum-norm solution and the parameter combinations the data cannot separate (the
// null space). Models of order ≥ 2 are refined by Gauss-Newton from that start (central
// differences of the deviation, exact for the quadratic terms).
//
// Algorithm objects (ErrorParameterisation, Identification) are separate from the result
// (IdentifyResult), which carries its own uncertainty: standard errors from the residual
// variance, identifiability flags and the residual RMS per output.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "weilgen/analysis/error_parameterisation.hpp"
#include "weilgen/analysis/study_spec.hpp"
#include "weilgen/machine/pdge_basis.hpp"
#include "weilgen/measure/ballbar.hpp"
#include "weilgen/measure/measurement_csv.hpp"
#include "weilgen/model/model.hpp"
#include "weilgen/uq/dense.hpp"
#include "weilgen/uq/lsq.hpp"

namespace weilgen {

// What an observation measures (its kind): the deviation outputs 0..5 (dx dy dz da db dc); 6, a
// ballbar's change of ball distance dr (the deviation's component along the ball-to-ball
// direction); 7..9, one error of a linear axis as a 6D laser line measures it (docs/data-format.md,
// "6D line measurements"): 7 its positioning (E_XX on X), 8 a straightness (E_YX, E_ZX), 9 an
// angular error (E_AX, E_BX, E_CX).
inline constexpr std::size_t kObservationKinds = 10;
inline constexpr int kRadialOutput = 6;
inline constexpr int kLinePositioning = 7, kLineStraightness = 8, kLineAngular = 9;

// One measured value of kind `output` at a pose, in µm or µrad.
struct PointObservation {
  std::size_t row = 0;  // row in the table
  int line = 0;         // source line
  int output = 0;
  double value = 0;  // µm (dx..dz, dr, positioning, straightness) or µrad (da..dc, angular)
  // dr only: the unit vector from the table ball to the tool ball (workpiece frame), so that
  // dr = radial · (dx, dy, dz) to first order.
  std::array<double, 3> radial{};
  // Kinds 7..9: the error observed (index into Description::errors); its value is that error at
  // the pose, in µm or µrad. -1 for the deviation kinds.
  int error = -1;
};

// "dx" ... "dc", "dr", "lin", "str", "ang".
const char* observation_name(std::size_t output);
// "µm" for dx dy dz, dr, lin and str; "µrad" for da db dc and ang.
const char* observation_unit(std::size_t output);

// How much of deviation output o (0..5) observation `ob` sees: 1 for its own output, the radial
// component for dr, else 0 (an error observation sees no deviation output).
inline double observation_weight(const PointObservation& ob, int o) {
  if (ob.output == o) return 1;
  if (ob.output == kRadialOutput && o < 3) return ob.radial[static_cast<std::size_t>(o)];
  return 0;
}
// The observation's value (µm, µrad) for a deviation given per output in µm and µrad.
inline double observe(const PointObservation& ob, const std::array<double, 6>& deviation) {
  double v = 0;
  for (int o = 0; o < 6; ++o)
    v += observation_weight(ob, o) * deviation[static_cast<std::size_t>(o)];
  return v;
}

// A reference an instrument's set-up leaves undetermined and its data remove: the observations
// of one group are taken modulo the span of some functions of the pose (their least-squares fit
// is subtracted), in the data and in the model alike. A ballbar trace's set-up places the
// table ball anywhere near the centre (cos θ, sin θ over the trace's points); a 6D laser's beam
// is aligned to the axis only roughly (a straightness profile's line 1, x) and its angular zero
// is arbitrary (an angular profile's mean 1).
struct ObservationReference {
  std::string what;                        // "ballbar centre of b.csv", "E_YX line of l.csv"
  std::vector<std::size_t> observations;   // indices into PointData::observations
  std::vector<std::vector<double>> basis;  // each function's value at every one of them
};

// Point measurements of a machine: the poses (independent axes, Description::axes() order, in
// their units) and one observation per measured value.
struct PointData {
  std::string file;
  std::vector<std::vector<double>> poses;  // per table row
  std::vector<PointObservation> observations;
  std::array<std::size_t, kObservationKinds> count{};  // observations per kind
  std::vector<ObservationReference> references;        // set-up references the data remove
  // Appends `other` (its rows after these, its references re-indexed).
  void append(PointData other);
};

// Reads the poses and deviations of `table` for the machine. Every independent coordinate must
// be a column (InputError "file: missing column 'Z' ..."), coordinate cells finite (file:line
// naming the column), and at least one deviation cell measured.
PointData point_data(const MeasurementTable& table, const Description& desc);

// A ballbar trace's dr observations: the poses on the circle (from the trace's header keys,
// `flags` overriding), the ball-to-ball unit vectors, the circle in `circle`. No reference:
// ballbar_centre_reference adds the set-up's centre.
PointData ballbar_point_data(const MeasurementTable& table, const Description& desc,
                             const BallbarFlags& flags, const std::vector<double>& parameters,
                             std::optional<BallbarCircle>& circle);
// The set-up reference of a ballbar trace: its centre offset a cos θ + b sin θ (θ of every
// observation from `angles_deg`, one per observation of `data`).
ObservationReference ballbar_centre_reference(const PointData& data,
                                              const std::vector<double>& angles_deg);

// A 6D line file (`# format: line6d`, read with line6d_read_options) as observations of the
// measured axis's errors (kinds 7..9), each with its reference (straightness: the line; angular:
// the mean; positioning: none), as the reader removes them. The other axes sit at the middle of
// their travel (a line measurement sees only its own axis's errors). A profile of an error the
// machine lacks is skipped with a message to `warn`; InputError when the axis is not one of the
// machine's linear axes or no profile is left.
PointData line6d_point_data(const MeasurementTable& table, const Description& desc,
                            const std::function<void(const std::string&)>& warn = {});

// An R-test file (a point file with the header key `# instrument: rtest`): its sensors are zeroed
// at the start, so each measured output (dx, dy, dz …) carries an unknown constant: one
// reference per output over the file's observations.
void add_rtest_references(PointData& data);

// One table's observations by its kind (below), with its set-up references.
PointData table_point_data(const MeasurementTable& table, const Description& desc,
                           const BallbarFlags& circle, const std::vector<double>& parameters,
                           const std::function<void(const std::string&)>& warn = {});

// Every --data file's observations as one set (rows keep their file for messages): point
// measurements (R-test files with their zero references), ballbar traces (is_ballbar_table;
// the circle from the header keys, `circle` overriding) and 6D line files (`# format: line6d`);
// `warn` receives each file's reader warnings
// (may be empty).
PointData merged_point_data(const std::vector<std::string>& files, const Description& desc,
                            const ReadOptions& options,
                            const std::function<void(const std::string&)>& warn = {},
                            const BallbarFlags& circle = {},
                            const std::vector<double>& parameters = {});

// The references removed from the rows of A (and from y when given): for each reference, the
// least-squares fit of its functions over its observations is subtracted. Returns the number of
// functions removed (the degrees of freedom the references take).
std::size_t remove_references(const PointData& data, Eigen::MatrixXd& A,
                              Eigen::VectorXd* y = nullptr);

// The first-order design matrix: row i is observation i, column p parameter p, in µm (µrad) per
// unit of θ_p: scale_o · C[o][error_p](pose) · ∂error_p/∂θ_p(pose).
Eigen::MatrixXd design_matrix(const Model& model, const ErrorParameterisation& param,
                              const PointData& data);

struct IdentifyOptions {
  double rank_tolerance = 1e-9;    // singular values below tol · σ_max (equilibrated) are null
  int max_gauss_newton = 8;        // iterations at order >= 2
  std::vector<std::string> fixed;  // errors held at zero (names, aliases, group:<group>)
  // rank_tolerance in (0, 1), max_gauss_newton >= 0 (std::invalid_argument naming the field).
  void validate() const;
};

// A parameter combination the data cannot determine: adding t·Σ coeff_p e_p (θ units) changes
// no prediction at the measured poses. Normalised so that the leading coefficient is 1.
struct NullCombination {
  std::vector<std::pair<std::size_t, double>> terms;                 // (parameter, coefficient)
  std::string str(const std::vector<IdentParameter>& params) const;  // "E_XX[1] - E_XY[1]"
};

// The null space of an equilibrated SVD (every column beyond its rank) as readable
// combinations: reduced row-echelon form, so that each combination has a leading parameter the
// others lack, in θ units, leading coefficient 1. `cols`: the parameter of each SVD column.
std::vector<NullCombination> null_combinations(const EquilibratedSvd& svd,
                                               const std::vector<std::size_t>& cols);

struct IdentifyResult {
  std::vector<double> theta;           // parameter values (declared units); min-norm
  std::vector<double> standard_error;  // NaN where not identifiable or no residual dof
  std::vector<bool> identifiable;
  std::vector<bool> fixed;
  std::size_t rank = 0, observations = 0, free_parameters = 0;
  double condition = 0;                 // σ_max / σ_min over the kept singular values
  std::vector<double> singular_values;  // equilibrated, descending
  std::vector<NullCombination> unidentifiable;
  // √(SSE / (m − rank − references)), µm/µrad mixed as measured; `references` counts the
  // functions the set-up references removed (PointData::references).
  double residual_sigma = 0;
  std::size_t references = 0;
  // Per observation kind (NaN if none); "before" is after the references' removal.
  std::array<double, kObservationKinds> rms_before{}, rms_after{}, max_after{};
  std::array<std::size_t, kObservationKinds> count{};
  int gauss_newton_iterations = 0;
  // The span of the measured poses along every independent axis (Description::axes() order, the
  // axis' unit): where the PDGEs are identified. A controller holds each PDGE at its axis' span
  // ends instead of extrapolating the basis (params_header, params_json).
  std::vector<double> span_min, span_max;
};

class Identification {
 public:
  explicit Identification(IdentifyOptions options = {});  // validates the options
  const IdentifyOptions& options() const { return options_; }
  // The parameters of `param` for the model from the observations in `data`.
  IdentifyResult run(const Model& model, const ErrorParameterisation& param,
                     const PointData& data) const;

 private:
  IdentifyOptions options_;
};

// The model's value of every observation of `data` (µm, µrad) for parameters θ, on the full
// model (every order), before the references' removal.
Eigen::VectorXd predict_observations(const Model& model, ModelData& md,
                                     const ErrorParameterisation& param,
                                     const std::vector<double>& theta, const PointData& data);

// µm per mm for a translation error, µrad per rad for a rotation: what a direct observation of
// the error (a 6D line) reads per base unit.
inline double error_measured_scale(const ErrorDef& e) {
  return e.effect == ErrorEffect::Rotation ? 1e6 : 1e3;
}

// Predicted deviations (dx..dz µm, da..dc µrad) at a pose from identified parameters.
std::array<double, 6> predict_deviation(const Model& model, ModelData& data,
                                        const ErrorParameterisation& param,
                                        const std::vector<double>& theta, const double* axes);

}  // namespace weilgen
