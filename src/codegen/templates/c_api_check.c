/* Compiles the C API templates on their own: templates/c_api.h (as standin_c.h) as C99 with
 * -Wall -Wextra -Wpedantic -Werror, linked with templates/c_api.cpp over the stand-in model
 * templates/standin.hpp, and checks every function against the stand-in's closed form
 * (position deviation E_X0 + E_XX * X along x) and every argument check. CTest c_api_template;
 * the generated C APIs of the shipped machines are tested in tests/test_c_api.cpp. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "standin_c.h"

static int failures = 0;

static void expect(int ok, const char* what) {
  if (!ok) {
    printf("FAILED: %s\n", what);
    ++failures;
  }
}

static void errors_at(const double* axes, double* errors, void* context) {
  const double* fixed = (const double*)context;
  (void)axes;
  errors[STANDIN_ERROR_E_X0] = fixed[0];
  errors[STANDIN_ERROR_E_XX] = fixed[1];
}

int main(void) {
  const double axes[STANDIN_NUM_AXES] = {250.0, -40.0};
  double errors[STANDIN_NUM_ERRORS];
  const double params[STANDIN_NUM_PARAMS] = {0.0};
  double position[3], orientation[3], coeff[3 * STANDIN_NUM_ERRORS], command[STANDIN_NUM_AXES];
  double pose[3], rotation[9], jacobian[6 * STANDIN_NUM_AXES], expected;
  int iterations = -5, status;

  errors[STANDIN_ERROR_E_X0] = 0.012; /* 12 um */
  errors[STANDIN_ERROR_E_XX] = 2e-5;  /* 20 um/m */
  status = standin_deviation(axes, errors, params, position, orientation);
  expect(status == STANDIN_STATUS_OK && position[0] == 0.012 + 2e-5 * 250.0 && position[1] == 0.0 &&
             orientation[2] == 0.0,
         "deviation");
  expect(standin_deviation(axes, errors, params, position, NULL) == STANDIN_STATUS_OK,
         "deviation without orientation");
  expect(standin_deviation(NULL, errors, params, position, NULL) == STANDIN_STATUS_BAD_ARGUMENT,
         "deviation: NULL axes");
  expect(standin_deviation(axes, errors, NULL, position, NULL) == STANDIN_STATUS_BAD_ARGUMENT,
         "deviation: NULL params");

  status = standin_coefficients(axes, params, coeff, NULL);
  expect(status == STANDIN_STATUS_OK && coeff[0] == 1.0 && coeff[1] == 250.0, "coefficients");

  memset(position, 0, sizeof position);
  memset(coeff, 0, sizeof coeff);
  status = standin_deviation_and_coefficients(axes, errors, params, position, NULL, coeff, NULL);
  expect(status == STANDIN_STATUS_OK && position[0] == 0.012 + 2e-5 * 250.0 && coeff[0] == 1.0 &&
             coeff[1] == 250.0,
         "deviation and coefficients");
  expect(standin_deviation_and_coefficients(axes, errors, params, NULL, NULL, NULL, NULL) ==
             STANDIN_STATUS_OK,
         "deviation and coefficients: every output NULL");
  expect(standin_deviation_and_coefficients(axes, NULL, params, position, NULL, coeff, NULL) ==
             STANDIN_STATUS_BAD_ARGUMENT,
         "deviation and coefficients: NULL errors");

  status = standin_nominal_pose(axes, params, pose, rotation);
  expect(status == STANDIN_STATUS_OK && pose[0] == 250.0 && rotation[8] == 1.0, "nominal pose");
  status = standin_nominal_jacobian(axes, params, jacobian);
  expect(status == STANDIN_STATUS_OK && jacobian[0] == 1.0 && jacobian[STANDIN_NUM_AXES + 1] == 1.0,
         "nominal jacobian");
  expect(standin_nominal_jacobian(axes, params, NULL) == STANDIN_STATUS_BAD_ARGUMENT,
         "nominal jacobian: NULL output");

  /* q0 + e0 + e1 q0 = t0: q0 = (t0 - e0) / (1 + e1); q1 = t1. */
  expected = (axes[0] - 0.012) / (1 + 2e-5);
  status = standin_compensate(axes, errors, params, command, 10, 1e-9, &iterations);
  expect(status == STANDIN_STATUS_OK && iterations >= 1 && fabs(command[0] - expected) < 1e-9 &&
             command[1] == axes[1],
         "compensate");
  status = standin_compensate_at(axes, errors_at, errors, params, command, 10, 1e-9, &iterations);
  expect(status == STANDIN_STATUS_OK && fabs(command[0] - expected) < 1e-9, "compensate_at");
  command[0] = -1.0;
  expect(standin_compensate(axes, errors, params, command, 0, 1e-9, NULL) ==
                 STANDIN_STATUS_BAD_ARGUMENT &&
             command[0] == -1.0,
         "compensate: max_iterations 0 is refused, nothing written");
  expect(standin_compensate(axes, errors, params, command, STANDIN_MAX_ITERATIONS + 1, 1e-9,
                            NULL) == STANDIN_STATUS_BAD_ARGUMENT,
         "compensate: max_iterations above the bound");
  expect(standin_compensate(axes, errors, params, command, 10, 0.0, NULL) ==
             STANDIN_STATUS_BAD_ARGUMENT,
         "compensate: tolerance 0");
  expect(standin_compensate_at(axes, NULL, NULL, params, command, 10, 1e-9, NULL) ==
             STANDIN_STATUS_BAD_ARGUMENT,
         "compensate_at: NULL callback");
  errors[STANDIN_ERROR_E_X0] = NAN;
  status = standin_compensate(axes, errors, params, command, 10, 1e-9, &iterations);
  expect(status == STANDIN_STATUS_NOT_COMPENSATED && iterations == 0 && command[0] == axes[0],
         "compensate: NaN errors leave the target");

  expect(strcmp(standin_axis_name(STANDIN_AXIS_Y), "Y") == 0 && standin_axis_name(2) == NULL &&
             standin_axis_name(-1) == NULL && strcmp(standin_axis_unit(STANDIN_AXIS_X), "mm") == 0,
         "axis names");
  expect(strcmp(standin_error_name(STANDIN_ERROR_E_XX), "E_XX") == 0 &&
             standin_error_name(STANDIN_NUM_ERRORS) == NULL,
         "error names");
  expect(strcmp(standin_param_name(STANDIN_PARAM_TOOL_LENGTH), "tool_length") == 0 &&
             standin_param_default(0) == 0.0 && standin_param_name(1) == NULL,
         "param names");
  expect(strcmp(STANDIN_MACHINE_NAME, "standin") == 0, "machine name");

  printf("C API template: %s\n", failures ? "FAILED" : "ok");
  return failures ? 1 : 0;
}
