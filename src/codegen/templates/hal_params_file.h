/* The identified-parameters file of a LinuxCNC component (`weilgen identify --emit-params-json`),
 * read outside the servo thread: the header `weilgen linuxcnc` writes as <model>_params_file.h,
 * as a real C file. The generator (src/codegen/emit_hal.cpp) emits everything after the marker
 * line with the stand-in names replaced by the model's. Compiled and run on its own as C99
 * against the stand-in C API by CTest hal_params_template (templates/hal_params_check.c).
 */
/* clang-format off: the text below is emitted byte for byte. */
/* ---- weilgen template: emitted from the next line ---- */
/* Identified parameters of the model standin read from a JSON file at run time
 * (docs/controllers.md, "Parameters from a file"). standin_params_read reads and checks a file
 * (machine, model key, every axis, error and parameter by name and in order, finite numbers,
 * bases the evaluator knows) into a block; standin_params_errors evaluates a block at a pose.
 * Neither allocates: the file goes into the caller's buffer, the block is fixed-size. */
#ifndef WEILGEN_PARAMS_FILE_STANDIN_H
#define WEILGEN_PARAMS_FILE_STANDIN_H

#include <stddef.h>

#include "standin_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most basis terms of one error (poly:31, fourier:15) and the largest file read. */
#define STANDIN_PARAMS_MAX_TERMS 32
#define STANDIN_PARAMS_MAX_FILE (1 << 20)

enum standin_basis {
  STANDIN_BASIS_CONSTANT = 0,
  STANDIN_BASIS_POLY = 1,
  STANDIN_BASIS_LEGENDRE = 2,
  STANDIN_BASIS_CHEBYSHEV = 3,
  STANDIN_BASIS_FOURIER = 4
};

/* One file's parameters. Errors in base units (mm, rad); a PDGE is a basis sum in its axis'
 * position held within the axis' identified span [span_min, span_max] (axis units, mm or deg),
 * u = (2 x - from - to) / (to - from) for the polynomial kinds, w = omega x for Fourier. */
struct standin_params_block {
  double params[STANDIN_NUM_PARAMS + 1]; /* + 1: C has no empty arrays */
  double span_min[STANDIN_NUM_AXES], span_max[STANDIN_NUM_AXES];
  int kind[STANDIN_NUM_ERRORS], axis[STANDIN_NUM_ERRORS], terms[STANDIN_NUM_ERRORS];
  double from[STANDIN_NUM_ERRORS], to[STANDIN_NUM_ERRORS], omega[STANDIN_NUM_ERRORS];
  double coeff[STANDIN_NUM_ERRORS][STANDIN_PARAMS_MAX_TERMS]; /* a constant: coeff[k][0] */
};

/* Parses text[0 .. size) into *block. Returns 0, or -1 with "line N: what" in message (always
 * terminated; *block may be partly written then). */
int standin_params_parse(const char *text, size_t size, struct standin_params_block *block,
                         char *message, size_t message_size);

/* Reads the file `path` into buffer[0 .. buffer_size) and parses it. Returns 0, or -1 with a
 * message naming the file (cannot be read, larger than the buffer, or what parse says). */
int standin_params_read(const char *path, char *buffer, size_t buffer_size,
                        struct standin_params_block *block, char *message, size_t message_size);

/* Every error of the model at a pose (axes in the model's order and units): bounded by
 * STANDIN_NUM_ERRORS * STANDIN_PARAMS_MAX_TERMS terms, no allocation. */
void standin_params_errors(const struct standin_params_block *block, const double *axes,
                           double *errors);

#ifdef __cplusplus
}
#endif

#endif
