/* The C API header that `weilgen generate --c-api` writes beside a model header (<name>_c.h), as
 * a real C file. The generator (src/codegen/emit_c_api.cpp) emits everything after the marker
 * line, with the stand-in names replaced by the model's (standin -> vmc_3axis, STANDIN ->
 * VMC_3AXIS, as whole identifiers or identifier prefixes) and the block between the enum markers
 * replaced by the model's counts and indices. It is compiled on its own as C99 with -Wall
 * -Wextra -Wpedantic -Werror (the stand-in enums below stand for a model with two axes, two
 * errors and one parameter) by src/codegen/templates/c_api_check.c (CTest c_api_template).
 */
/* clang-format off: the text below is emitted byte for byte (the generated files are golden). */
/* ---- weilgen template: emitted from the next line ---- */
#ifndef WEILGEN_C_API_STANDIN_H
#define WEILGEN_C_API_STANDIN_H

#ifdef __cplusplus
extern "C" {
#endif

/* noexcept for C++ callers: these functions never throw (the implementation calls only the
 * model header's templates, which use std::array and <cmath> and allocate nothing). */
#ifndef WEILGEN_C_API_NOEXCEPT
#ifdef __cplusplus
#define WEILGEN_C_API_NOEXCEPT noexcept
#else
#define WEILGEN_C_API_NOEXCEPT
#endif
#endif

/* ---- weilgen template: enums begin ---- */
#define STANDIN_MACHINE_NAME "standin"
#define STANDIN_MODEL_KEY "0000000000000000"
enum {
  STANDIN_ORDER = 1,
  STANDIN_NUM_AXES = 2,
  STANDIN_NUM_ERRORS = 2,
  STANDIN_NUM_PARAMS = 1,
  STANDIN_NUM_OUTPUTS = 6
};
enum standin_axis {
  STANDIN_AXIS_X = 0, /* mm */
  STANDIN_AXIS_Y = 1  /* mm */
};
enum standin_error {
  STANDIN_ERROR_E_X0 = 0, /* mm */
  STANDIN_ERROR_E_XX = 1  /* mm per mm of X */
};
enum standin_param {
  STANDIN_PARAM_TOOL_LENGTH = 0 /* mm */
};
/* ---- weilgen template: enums end ---- */

/* What every function returns. */
enum standin_status {
  STANDIN_STATUS_OK = 0,
  /* standin_compensate: singular weighted Jacobian, a value not finite, or not converged within
   * max_iterations; *command is then the target, uncompensated. */
  STANDIN_STATUS_NOT_COMPENSATED = -1,
  /* A required pointer is NULL (params may be NULL when STANDIN_NUM_PARAMS is 0), or
   * max_iterations / tolerance_mm is out of range. Nothing was written. */
  STANDIN_STATUS_BAD_ARGUMENT = -2
};

/* The largest max_iterations standin_compensate accepts: every call is bounded. */
#define STANDIN_MAX_ITERATIONS 100

/* Arrays are in the index order of the enums above: axes[STANDIN_NUM_AXES] in the axes' units
 * (mm or deg, as commented), errors[STANDIN_NUM_ERRORS] in base units (mm, rad),
 * params[STANDIN_NUM_PARAMS] in mm or deg. The functions allocate nothing, throw nothing, and
 * are safe to call from several threads at once (no shared state). */

/* Deviation of the tool point relative to the workpiece (or of the output point), workpiece
 * frame: position (dx, dy, dz) in mm, orientation (da, db, dc) in rad. position or orientation
 * may be NULL (not computed). Returns STANDIN_STATUS_OK or STANDIN_STATUS_BAD_ARGUMENT. */
int standin_deviation(const double* axes, const double* errors, const double* params,
                      double* position, double* orientation) WEILGEN_C_API_NOEXCEPT;

/* First-order coefficients d(output)/d(error) at zero error, row-major [output][error]:
 * position_coeff[3 * STANDIN_NUM_ERRORS] rows dx, dy, dz (mm per base unit of the error),
 * orientation_coeff[3 * STANDIN_NUM_ERRORS] rows da, db, dc (rad per base unit). Either may be
 * NULL. */
int standin_coefficients(const double* axes, const double* params, double* position_coeff,
                         double* orientation_coeff) WEILGEN_C_API_NOEXCEPT;

/* standin_deviation and standin_coefficients at one pose in one call, sharing the trigonometry
 * and the terms common to both (the same results to rounding, at about the cost of the deviation
 * alone). Any of the four outputs may be NULL (not computed). */
int standin_deviation_and_coefficients(const double* axes, const double* errors,
                                       const double* params, double* position, double* orientation,
                                       double* position_coeff,
                                       double* orientation_coeff) WEILGEN_C_API_NOEXCEPT;

/* The nominal pose (every error zero): position[3] in mm, rotation[9] row-major. Either may be
 * NULL. */
int standin_nominal_pose(const double* axes, const double* params, double* position,
                         double* rotation) WEILGEN_C_API_NOEXCEPT;

/* d(nominal pose)/d(axes), row-major [output][axis], jacobian[6 * STANDIN_NUM_AXES]: rows dx, dy,
 * dz in mm and da, db, dc in rad, per axis unit. */
int standin_nominal_jacobian(const double* axes, const double* params,
                             double* jacobian) WEILGEN_C_API_NOEXCEPT;

/* The corrected command for target (docs/compensation.md): the command whose predicted pose
 * (nominal pose plus deviation with the errors at the command) is the nominal pose at the
 * target, with errors that do not depend on the pose. max_iterations in 1..STANDIN_MAX_ITERATIONS
 * (10 is the C++ default), tolerance_mm > 0 (1e-9 is the C++ default). *iterations (iterations
 * may be NULL) receives the iterations used. Returns STANDIN_STATUS_OK,
 * STANDIN_STATUS_NOT_COMPENSATED (command = target) or STANDIN_STATUS_BAD_ARGUMENT. */
int standin_compensate(const double* target, const double* errors, const double* params,
                       double* command, int max_iterations, double tolerance_mm,
                       int* iterations) WEILGEN_C_API_NOEXCEPT;

/* The errors at a pose: errors[STANDIN_NUM_ERRORS] in base units (mm, rad) at axes. Called up to
 * max_iterations times per standin_compensate_at; it must not throw (a C++ callee) or block. */
typedef void (*standin_errors_fn)(const double* axes, double* errors, void* context);

/* standin_compensate with errors that depend on the pose: errors_at(axes, errors, context) is
 * evaluated at the command, where the machine will stand. */
int standin_compensate_at(const double* target, standin_errors_fn errors_at, void* context,
                          const double* params, double* command, int max_iterations,
                          double tolerance_mm, int* iterations) WEILGEN_C_API_NOEXCEPT;

/* The name of an axis, error or parameter by index ("X", "E_XX", "tool_length"), and an axis'
 * unit ("mm", "deg"); NULL when out of range. */
const char* standin_axis_name(int axis) WEILGEN_C_API_NOEXCEPT;
const char* standin_axis_unit(int axis) WEILGEN_C_API_NOEXCEPT;
const char* standin_error_name(int error) WEILGEN_C_API_NOEXCEPT;
const char* standin_param_name(int param) WEILGEN_C_API_NOEXCEPT;
/* The machine file's default value of a parameter (mm or deg); 0 when out of range. */
double standin_param_default(int param) WEILGEN_C_API_NOEXCEPT;

#ifdef __cplusplus
}  /* extern "C" */
#endif

#endif /* WEILGEN_C_API_STANDIN_H */
