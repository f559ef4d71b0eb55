/* The body of the C API runner of one model, compiled as C99 with -Wall -Wextra -Wpedantic
 * -Werror and linked as C (the C API needs no C++ runtime). The per-model file (configured by
 * tests/CMakeLists.txt) includes the model's <name>_c.h and defines M(x) as <name>_##x and MU(x)
 * as <NAME>_##x before including this file.
 *
 *   c_api_run_<model> IN OUT
 *
 * IN: cases of axes[NUM_AXES], errors[NUM_ERRORS], params[NUM_PARAMS] (native doubles). OUT: per
 * case the results of deviation, coefficients, deviation_and_coefficients, nominal_pose,
 * nominal_jacobian and compensate (10 iterations, 1e-9 mm), then status and iterations as doubles.
 * tests/test_c_api.cpp compares them with the C++ header bit for bit. Exits 1 when an argument
 * check fails. */
#include <stdio.h>
#include <string.h>

enum { NA = MU(NUM_AXES), NE = MU(NUM_ERRORS), NP = MU(NUM_PARAMS) };

static int failures = 0;

static void expect(int ok, const char* what) {
  if (!ok) {
    fprintf(stderr, "FAILED: %s\n", what);
    ++failures;
  }
}

static int read_all(FILE* f, double* v, size_t n) {
  return n == 0 || fread(v, sizeof(double), n, f) == n;
}

int main(int argc, char** argv) {
  double axes[NA], errors[NE], params[NP + 1], position[3], orientation[3];
  double position_coeff[3 * NE], orientation_coeff[3 * NE], pose[3], rotation[9], jacobian[6 * NA];
  double both[6 + 6 * NE];
  double command[NA], status_iterations[2];
  int status = 0, iterations = 0;
  long cases = 0;
  FILE *in, *out;
  if (argc != 3) {
    fprintf(stderr, "usage: %s IN OUT\n", argv[0]);
    return 2;
  }
  memset(axes, 0, sizeof axes);
  memset(errors, 0, sizeof errors);
  memset(params, 0, sizeof params);
  /* Every function refuses missing inputs and writes nothing then. */
  expect(M(deviation)(NULL, errors, params, position, NULL) == MU(STATUS_BAD_ARGUMENT),
         "deviation: NULL axes");
  expect(M(deviation)(axes, NULL, params, position, NULL) == MU(STATUS_BAD_ARGUMENT),
         "deviation: NULL errors");
  expect(M(coefficients)(NULL, params, position_coeff, NULL) == MU(STATUS_BAD_ARGUMENT),
         "coefficients: NULL axes");
  expect(M(deviation_and_coefficients)(axes, NULL, params, position, NULL, NULL, NULL) ==
             MU(STATUS_BAD_ARGUMENT),
         "deviation_and_coefficients: NULL errors");
  expect(M(nominal_jacobian)(axes, params, NULL) == MU(STATUS_BAD_ARGUMENT),
         "nominal_jacobian: NULL output");
  command[0] = 12345.0;
  expect(M(compensate)(axes, errors, params, command, 0, 1e-9, NULL) == MU(STATUS_BAD_ARGUMENT) &&
             command[0] == 12345.0,
         "compensate: max_iterations 0");
  expect(M(compensate)(axes, errors, params, command, 10, -1.0, NULL) == MU(STATUS_BAD_ARGUMENT),
         "compensate: negative tolerance");
  expect(M(compensate)(axes, errors, params, NULL, 10, 1e-9, NULL) == MU(STATUS_BAD_ARGUMENT),
         "compensate: NULL command");
  expect(M(axis_name)(NA) == NULL && M(error_name)(-1) == NULL && M(axis_name)(0) != NULL,
         "names out of range");
  if (NP > 0)
    expect(M(deviation)(axes, errors, NULL, position, NULL) == MU(STATUS_BAD_ARGUMENT),
           "deviation: NULL params");

  in = fopen(argv[1], "rb");
  out = fopen(argv[2], "wb");
  if (in == NULL || out == NULL) {
    fprintf(stderr, "cannot open %s or %s\n", argv[1], argv[2]);
    return 2;
  }
  while (read_all(in, axes, NA) && read_all(in, errors, NE) && read_all(in, params, NP)) {
    expect(M(deviation)(axes, errors, params, position, orientation) == MU(STATUS_OK), "deviation");
    expect(M(coefficients)(axes, params, position_coeff, orientation_coeff) == MU(STATUS_OK),
           "coefficients");
    expect(M(deviation_and_coefficients)(axes, errors, params, both, both + 3, both + 6,
                                         both + 6 + 3 * NE) == MU(STATUS_OK),
           "deviation_and_coefficients");
    expect(M(nominal_pose)(axes, params, pose, rotation) == MU(STATUS_OK), "nominal_pose");
    expect(M(nominal_jacobian)(axes, params, jacobian) == MU(STATUS_OK), "nominal_jacobian");
    status = M(compensate)(axes, errors, params, command, 10, 1e-9, &iterations);
    status_iterations[0] = status;
    status_iterations[1] = iterations;
    fwrite(position, sizeof(double), 3, out);
    fwrite(orientation, sizeof(double), 3, out);
    fwrite(position_coeff, sizeof(double), 3 * NE, out);
    fwrite(orientation_coeff, sizeof(double), 3 * NE, out);
    fwrite(both, sizeof(double), 6 + 6 * NE, out);
    fwrite(pose, sizeof(double), 3, out);
    fwrite(rotation, sizeof(double), 9, out);
    fwrite(jacobian, sizeof(double), 6 * NA, out);
    fwrite(command, sizeof(double), NA, out);
    fwrite(status_iterations, sizeof(double), 2, out);
    ++cases;
  }
  fclose(in);
  if (fclose(out) != 0) return 2;
  printf("%ld cases\n", cases);
  return failures ? 1 : 0;
}
