/* A C controller's use of the generated C API (vmc_3axis_c.h, docs/controllers.md): the tool
 * point's deviation at a pose with every error at a one-micrometre / one-microradian value, the
 * same from the first-order coefficients (the order-1 model is linear in the errors), and the
 * compensated command for the pose, whose predicted pose must be the target's nominal pose.
 * Exits 1 when a check fails. Also built in the weilgen tree as CTest c_api_add_model. */
#include <math.h>
#include <stdio.h>

#include "vmc_3axis_c.h"

int main(void) {
  double axes[VMC_3AXIS_NUM_AXES], errors[VMC_3AXIS_NUM_ERRORS], params[VMC_3AXIS_NUM_PARAMS];
  double deviation[3], coeff[3 * VMC_3AXIS_NUM_ERRORS], command[VMC_3AXIS_NUM_AXES];
  double target_pose[3], command_pose[3], predicted[3], linear_miss = 0.0, miss = 0.0;
  int i, k, iterations = 0;
  axes[VMC_3AXIS_AXIS_X] = 250.0; /* mm */
  axes[VMC_3AXIS_AXIS_Y] = -200.0;
  axes[VMC_3AXIS_AXIS_Z] = -150.0;
  params[VMC_3AXIS_PARAM_TOOL_LENGTH] = vmc_3axis_param_default(VMC_3AXIS_PARAM_TOOL_LENGTH);
  for (i = 0; i < VMC_3AXIS_NUM_ERRORS; ++i) errors[i] = 1e-6; /* 1 urad for the rotations */
  errors[VMC_3AXIS_ERROR_E_XX] = 0.001;                        /* 1 um */
  errors[VMC_3AXIS_ERROR_E_YY] = 0.001;
  errors[VMC_3AXIS_ERROR_E_ZZ] = 0.001;
  if (vmc_3axis_deviation(axes, errors, params, deviation, NULL) != VMC_3AXIS_STATUS_OK ||
      vmc_3axis_coefficients(axes, params, coeff, NULL) != VMC_3AXIS_STATUS_OK)
    return 1;
  for (k = 0; k < 3; ++k) {
    double sum = 0.0;
    for (i = 0; i < VMC_3AXIS_NUM_ERRORS; ++i)
      sum += coeff[k * VMC_3AXIS_NUM_ERRORS + i] * errors[i];
    linear_miss = fmax(linear_miss, fabs(sum - deviation[k]));
  }
  if (vmc_3axis_compensate(axes, errors, params, command, 10, 1e-9, &iterations) !=
      VMC_3AXIS_STATUS_OK)
    return 1;
  vmc_3axis_nominal_pose(axes, params, target_pose, NULL);
  vmc_3axis_nominal_pose(command, params, command_pose, NULL);
  vmc_3axis_deviation(command, errors, params, predicted, NULL);
  for (k = 0; k < 3; ++k) miss = fmax(miss, fabs(command_pose[k] + predicted[k] - target_pose[k]));
  printf(
      "%s (C API): deviation at X=250 Y=-200 Z=-150: dx %.3f dy %.3f dz %.3f um "
      "(coefficients x errors: within %.1e mm)\n",
      VMC_3AXIS_MACHINE_NAME, deviation[0] * 1e3, deviation[1] * 1e3, deviation[2] * 1e3,
      linear_miss);
  printf(
      "compensated in %d iterations: X %+.4f Y %+.4f Z %+.4f um, predicted pose off by %.1e mm\n",
      iterations, (command[VMC_3AXIS_AXIS_X] - axes[VMC_3AXIS_AXIS_X]) * 1e3,
      (command[VMC_3AXIS_AXIS_Y] - axes[VMC_3AXIS_AXIS_Y]) * 1e3,
      (command[VMC_3AXIS_AXIS_Z] - axes[VMC_3AXIS_AXIS_Z]) * 1e3, miss);
  return linear_miss <= 1e-15 && miss <= 1e-9 ? 0 : 1;
}
