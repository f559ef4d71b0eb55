/* Runs the parameter-file reader of the LinuxCNC component on its own (CTest
 * hal_params_template): templates/hal_params_file.c (as standin_params_file.c) compiled as C99
 * with -Wall -Wextra -Wpedantic -Werror against the stand-in C API (two axes X, Y; errors E_X0,
 * E_XX; parameter tool_length). A good file in any key order evaluates to its closed forms, held
 * at the span's ends; every bad file is refused with its line and what is wrong. The files the
 * generator writes for the shipped machines are read by the component under halrun
 * (tests/linuxcnc/). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "standin_params_file.h"

static int failures = 0;

static void expect(int ok, const char *what) {
  if (!ok) {
    printf("FAILED: %s\n", what);
    ++failures;
  }
}

/* A file whose errors are E_X0 = 0.012 mm and E_XX = poly:2 on X in [0, 500] with
 * coefficients 1e-3, 2e-3, -5e-4 (mm), the X span 100 ... 400: keys in another order than the
 * generator writes them, unknown keys with nested values that must be skipped. */
static const char *const good =
    "{\n"
    " \"verb\": \"identify\", \"weilgen\": \"0\",\n"
    " \"errors\": [\n"
    "  {\"name\": \"E_X0\", \"unit\": \"mm\", \"basis\": \"constant\", \"value\": 0.012},\n"
    "  {\"coefficients\": [1e-3, 2E-3, -5.0e-4], \"basis\": \"poly\", \"axis\": 0,\n"
    "   \"name\": \"E_XX\", \"from\": 0, \"to\": 500.0, \"note\": {\"a\": [1, [2, {}]], \"b\": null},\n"
    "   \"flag\": true, \"other\": false, \"text\": \"a \\\"quoted\\\" \\u00b5 word\"}\n"
    " ],\n"
    " \"axes\": [{\"name\": \"X\", \"unit\": \"mm\", \"span\": [100, 400]},\n"
    "          {\"span\": [-50.5, 0], \"name\": \"Y\"}],\n"
    " \"params\": [{\"name\": \"tool_length\", \"unit\": \"mm\", \"value\": 42.5}],\n"
    " \"model_key\": \"0000000000000000\", \"machine\": \"standin\", \"weilgen_params\": 1\n"
    "}\n";

static double closed_form(double x) {
  const double held = x < 100 ? 100 : x > 400 ? 400 : x;
  const double u = (2 * held - 500) / 500;
  return 1e-3 + 2e-3 * u - 5e-4 * u * u;
}

/* `good` with the first occurrence of `from` replaced by `to`. */
static const char *edited(const char *from, const char *to) {
  static char text[4096];
  const char *at = strstr(good, from);
  size_t head;
  if (at == 0) {
    printf("FAILED: the test's edit '%s' does not apply\n", from);
    ++failures;
    return good;
  }
  head = (size_t)(at - good);
  memcpy(text, good, head);
  snprintf(text + head, sizeof text - head, "%s%s", to, at + strlen(from));
  return text;
}

static void refused(const char *text, const char *want) {
  struct standin_params_block block;
  char message[512], what[700];
  const int r = standin_params_parse(text, strlen(text), &block, message, sizeof message);
  snprintf(what, sizeof what, "refused with '%s', got %d '%s'", want, r, message);
  expect(r == -1 && strstr(message, want) != 0, what);
}

int main(void) {
  struct standin_params_block block;
  char message[512], buffer[8192];
  double axes[STANDIN_NUM_AXES], errors[STANDIN_NUM_ERRORS];
  const double xs[] = {-1e6, 0, 100, 250, 399.9, 400, 1e9};
  size_t i;
  FILE *f;
  int r = standin_params_parse(good, strlen(good), &block, message, sizeof message);
  expect(r == 0, message);
  expect(block.params[0] == 42.5, "params[0]");
  expect(block.span_min[1] == -50.5 && block.span_max[0] == 400, "spans");
  for (i = 0; i < sizeof xs / sizeof xs[0]; ++i) {
    axes[0] = xs[i];
    axes[1] = -3;
    standin_params_errors(&block, axes, errors);
    expect(errors[STANDIN_ERROR_E_X0] == 0.012, "E_X0 constant");
    expect(fabs(errors[STANDIN_ERROR_E_XX] - closed_form(xs[i])) <= 1e-18, "E_XX poly, held");
  }
  axes[0] = NAN;
  standin_params_errors(&block, axes, errors);
  expect(isnan(errors[STANDIN_ERROR_E_XX]), "a NaN position gives a NaN error");

  /* Legendre, Chebyshev and Fourier against their definitions at u = 0.3 (x = 325). */
  axes[0] = 325;
  r = standin_params_parse(edited("\"poly\"", "\"legendre\""), strlen(edited("\"poly\"", "\"legendre\"")),
                           &block, message, sizeof message);
  standin_params_errors(&block, axes, errors);
  expect(r == 0 && fabs(errors[1] - (1e-3 + 2e-3 * 0.3 - 5e-4 * (3 * 0.09 - 1) / 2)) <= 1e-18,
         "legendre");
  r = standin_params_parse(edited("\"poly\"", "\"chebyshev\""), strlen(edited("\"poly\"", "\"chebyshev\"")),
                           &block, message, sizeof message);
  standin_params_errors(&block, axes, errors);
  expect(r == 0 && fabs(errors[1] - (1e-3 + 2e-3 * 0.3 - 5e-4 * (2 * 0.09 - 1))) <= 1e-18,
         "chebyshev");
  r = standin_params_parse(edited("\"basis\": \"poly\"", "\"basis\": \"fourier\", \"period\": 200"),
                           strlen(edited("\"basis\": \"poly\"", "\"basis\": \"fourier\", \"period\": 200")),
                           &block, message, sizeof message);
  standin_params_errors(&block, axes, errors);
  expect(r == 0 && fabs(errors[1] - (1e-3 + 2e-3 * cos(2 * 3.14159265358979323846 * 325 / 200) -
                                     5e-4 * sin(2 * 3.14159265358979323846 * 325 / 200))) <= 1e-17,
         "fourier");

  /* Through a file, and the file errors. */
  f = fopen("hal_params_check.json", "wb");
  expect(f != 0 && fputs(good, f) >= 0 && fclose(f) == 0, "write the file");
  expect(standin_params_read("hal_params_check.json", buffer, sizeof buffer, &block, message,
                             sizeof message) == 0, message);
  expect(standin_params_read("hal_params_check.json", buffer, 100, &block, message,
                             sizeof message) == -1 && strstr(message, "larger than 100 bytes"),
         "a file larger than the buffer");
  expect(standin_params_read("no/such/file.json", buffer, sizeof buffer, &block, message,
                             sizeof message) == -1 && strstr(message, "no/such/file.json: cannot open"),
         "a missing file");
  remove("hal_params_check.json");

  /* Another model first, whatever the order of the keys. */
  refused(edited("0000000000000000", "5c916ea7bfaab479"),
          "line 12: model_key: '5c916ea7bfaab479' is not the model's '0000000000000000'");
  refused(edited("\"machine\": \"standin\"", "\"machine\": \"vmc_3axis\""),
          "machine: 'vmc_3axis' is not this component's model 'standin'");
  refused(edited("\"weilgen_params\": 1", "\"weilgen_params\": 2"), "format 1 expected");
  refused(edited("\"weilgen_params\": 1", "\"weilgen_paramz\": 1"), "no weilgen_params");
  refused("{\"weilgen_tolerances\": 1, \"errors\": {}}", "no weilgen_params");
  /* Names, counts, values. */
  refused(edited("\"name\": \"E_XX\"", "\"name\": \"E_YY\""),
          "line 6: errors[1] (E_XX): name 'E_YY', the model has 'E_XX' here");
  refused(edited("{\"span\": [-50.5, 0], \"name\": \"Y\"}", "{\"span\": [-50.5, 0], \"name\": \"Y\"}, {}"),
          "axes[2]: more axes than the model has");
  refused(edited("  {\"name\": \"E_X0\", \"unit\": \"mm\", \"basis\": \"constant\", \"value\": 0.012},\n", ""),
          "errors[0] (E_X0): name 'E_XX', the model has 'E_X0' here");
  refused(edited("0.012", "1e999"), "line 4: errors[0] (E_X0): a number out of range");
  refused(edited("0.012", "NaN"), "errors[0] (E_X0): expected a number");
  refused(edited("0.012", "0.01.2"), "errors[0] (E_X0): not a number");
  refused(edited("\"constant\"", "\"spline\""), "basis is constant, poly");
  refused(edited("\"axis\": 0", "\"axis\": 2"), "axis must be the index");
  refused(edited("\"axis\": 0", "\"axis\": 0.5"), "axis must be the index");
  refused(edited("\"to\": 500.0", "\"to\": -1"), "from must be less than to");
  refused(edited("[100, 400]", "[400, 100]"), "axes[0]: span min > max");
  refused(edited("[100, 400]", "[100]"), "axes[0]: span is [min, max]");
  refused(edited("\"basis\": \"poly\"", "\"basis\": \"fourier\""), "needs a period");
  refused(edited("[1e-3, 2E-3, -5.0e-4]",
                 "[1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,"
                 "29,30,31,32,33]"),
          "more coefficients than this component takes (32)");
  refused(edited("\"value\": 42.5", "\"valu\": 42.5"), "params[0]: a parameter needs its name and value");
  /* Syntax. */
  refused("", "line 1: expected '{'");
  refused(edited("\"weilgen_params\": 1\n}", "\"weilgen_params\": 1\n"), "expected ',' or '}'");
  refused(edited("\"weilgen_params\": 1\n}", "\"weilgen_params\": 1\n} x"), "text after the document");
  refused(edited("\"verb\": \"identify\"", "\"verb\" \"identify\""), "line 2: expected ':'");
  refused(edited("\"b\": null", "\"b\": nul"), "expected a value");
  refused(edited("\"b\": null", "\"b\": [[[[[[[[[[[[[[[[[[[[1]]]]]]]]]]]]]]]]]]]"), "nested too deeply");
  refused("{\"weilgen_params\": 1, \"machine\": \"standin\", \"model_key\": \"0000000000000000\"}",
          "no params");
  if (failures) {
    printf("hal_params_template: %d failure(s)\n", failures);
    return 1;
  }
  printf("hal_params_template: ok\n");
  return 0;
}
