/* The reader and evaluator of identified-parameter files of a LinuxCNC component, as a real C
 * file: `weilgen linuxcnc` writes it as <model>_params_file.c with the stand-in names replaced by
 * the model's (src/codegen/emit_hal.cpp). Compiled and run on its own as C99 against the stand-in
 * C API by CTest hal_params_template (templates/hal_params_check.c), which feeds it good and bad
 * files.
 */
/* clang-format off: the text below is emitted byte for byte. */
/* ---- weilgen template: emitted from the next line ---- */
/* Reads the JSON that `weilgen identify --emit-params-json` writes (docs/controllers.md) into a
 * fixed-size block and evaluates it. The reader runs outside the servo thread (at module load
 * and in the component's loader thread); it is a small JSON parser with bounded nesting that
 * allocates nothing and checks everything the evaluator relies on. C99 and libc only. */
#include "standin_params_file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PARAMS_MAX_DEPTH 16 /* nesting skipped in keys this reader does not know */
#define PARAMS_MAX_TEXT 64  /* the longest string value compared (names, keys, bases) */

struct params_reader {
  const char *start, *p, *end;
  char *message;
  size_t message_size;
  int failed;
  int quiet; /* the first pass: its syntax errors are left to the second, which names them */
};

static int params_line(const struct params_reader *r) {
  const char *c;
  int line = 1;
  for (c = r->start; c < r->p && c < r->end; ++c) line += *c == '\n';
  return line;
}

/* Records the first failure, "line N: <context><what>". Returns -1. */
static int params_fail(struct params_reader *r, const char *context, const char *what) {
  if (!r->failed && !r->quiet)
    snprintf(r->message, r->message_size, "line %d: %s%s", params_line(r), context, what);
  r->failed = 1;
  return -1;
}

static int params_peek(struct params_reader *r) {
  while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\n' || *r->p == '\r')) ++r->p;
  return r->p < r->end ? (unsigned char)*r->p : -1;
}

static int params_expect(struct params_reader *r, char c, const char *context) {
  char what[32];
  if (params_peek(r) != c) {
    snprintf(what, sizeof what, "expected '%c'", c);
    return params_fail(r, context, what);
  }
  ++r->p;
  return 0;
}

/* A string into out (at most PARAMS_MAX_TEXT - 1 characters; out may be NULL to skip it). */
static int params_string(struct params_reader *r, char *out, const char *context) {
  size_t n = 0;
  if (params_expect(r, '"', context)) return -1;
  while (r->p < r->end && *r->p != '"') {
    char c = *r->p++;
    if ((unsigned char)c < 0x20) return params_fail(r, context, "a control character in a string");
    if (c == '\\') {
      if (r->p >= r->end) break;
      c = *r->p++;
      if (c == 'u') {
        if (out) return params_fail(r, context, "\\u escapes are not expected in names");
        continue; /* a skipped string: its four hex digits are ordinary characters */
      }
      if (c == 'b') c = '\b';
      else if (c == 'f') c = '\f';
      else if (c == 'n') c = '\n';
      else if (c == 'r') c = '\r';
      else if (c == 't') c = '\t';
      else if (c != '"' && c != '\\' && c != '/') return params_fail(r, context, "a bad escape");
    }
    if (out) {
      if (n + 1 >= PARAMS_MAX_TEXT) return params_fail(r, context, "a string too long for a name");
      out[n] = c;
    }
    ++n;
  }
  if (r->p >= r->end) return params_fail(r, context, "a string without its closing quote");
  ++r->p;
  if (out) out[n] = '\0';
  return 0;
}

/* A finite number (JSON's grammar; strtod reads it, in the C locale's notation). */
static int params_number(struct params_reader *r, double *value, const char *context) {
  char token[64], *end = 0;
  size_t n = 0;
  if (params_peek(r) < 0) return params_fail(r, context, "expected a number");
  while (r->p + n < r->end && strchr("+-0123456789.eE", r->p[n]) && r->p[n] != '\0') {
    if (n + 1 >= sizeof token) return params_fail(r, context, "a number too long");
    token[n] = r->p[n];
    ++n;
  }
  token[n] = '\0';
  if (n == 0) return params_fail(r, context, "expected a number");
  errno = 0;
  *value = strtod(token, &end);
  if (end != token + n) return params_fail(r, context, "not a number");
  if (errno == ERANGE || !isfinite(*value)) return params_fail(r, context, "a number out of range");
  r->p += n;
  return 0;
}

static int params_literal(struct params_reader *r, const char *word, const char *context) {
  const size_t n = strlen(word);
  if ((size_t)(r->end - r->p) < n || strncmp(r->p, word, n) != 0)
    return params_fail(r, context, "expected a value");
  r->p += n;
  return 0;
}

/* The next member of an object ("key": read, ':' consumed): 1, or 0 at its end, -1 on an error.
 * *first is 1 before the object's '{'. */
static int params_member(struct params_reader *r, int *first, char *key, const char *context) {
  int c;
  if (*first) {
    if (params_expect(r, '{', context)) return -1;
    *first = 0;
    if (params_peek(r) == '}') {
      ++r->p;
      return 0;
    }
  } else {
    c = params_peek(r);
    if (c == '}') {
      ++r->p;
      return 0;
    }
    if (c != ',') return params_fail(r, context, "expected ',' or '}'");
    ++r->p;
  }
  if (params_peek(r) != '"') return params_fail(r, context, "expected a key");
  if (params_string(r, key, context)) return -1;
  return params_expect(r, ':', context) ? -1 : 1;
}

/* The next item of an array: 1, or 0 at its end, -1 on an error; *first as above. */
static int params_item(struct params_reader *r, int *first, const char *context) {
  int c;
  if (*first) {
    if (params_expect(r, '[', context)) return -1;
    *first = 0;
    if (params_peek(r) == ']') {
      ++r->p;
      return 0;
    }
    return 1;
  }
  c = params_peek(r);
  if (c == ']') {
    ++r->p;
    return 0;
  }
  if (c != ',') return params_fail(r, context, "expected ',' or ']'");
  ++r->p;
  return 1;
}

static int params_skip(struct params_reader *r, int depth, const char *context) {
  char key[PARAMS_MAX_TEXT];
  int first = 1, more;
  double ignored;
  const int c = params_peek(r);
  if (depth > PARAMS_MAX_DEPTH) return params_fail(r, context, "nested too deeply");
  if (c == '{') {
    while ((more = params_member(r, &first, key, context)) == 1)
      if (params_skip(r, depth + 1, context)) return -1;
    return more;
  }
  if (c == '[') {
    while ((more = params_item(r, &first, context)) == 1)
      if (params_skip(r, depth + 1, context)) return -1;
    return more;
  }
  if (c == '"') return params_string(r, 0, context);
  if (c == 't') return params_literal(r, "true", context);
  if (c == 'f') return params_literal(r, "false", context);
  if (c == 'n') return params_literal(r, "null", context);
  return params_number(r, &ignored, context);
}

/* A name that must be `want`. */
static int params_name(struct params_reader *r, const char *want, const char *context) {
  char got[PARAMS_MAX_TEXT], what[2 * PARAMS_MAX_TEXT + 64];
  if (params_string(r, got, context)) return -1;
  if (want && strcmp(got, want) == 0) return 0;
  snprintf(what, sizeof what, "name '%s', the model has '%s' here", got, want ? want : "(none)");
  return params_fail(r, context, what);
}

/* A failure the first pass reports itself: not this model's parameters. */
static int params_mismatch(struct params_reader *r, const char *context, const char *what) {
  r->quiet = 0;
  return params_fail(r, context, what);
}

/* The first pass: the format, the machine and the model key, before anything else is read, so
 * that parameters of another model are named as such. */
static int params_identity(struct params_reader *r) {
  char key[PARAMS_MAX_TEXT], text[PARAMS_MAX_TEXT], what[4 * PARAMS_MAX_TEXT + 200];
  int first = 1, more, seen = 0;
  double format = 0;
  while ((more = params_member(r, &first, key, "")) == 1) {
    if (strcmp(key, "weilgen_params") == 0) {
      if (params_number(r, &format, "weilgen_params: ")) return -1;
      if (format != 1) return params_mismatch(r, "weilgen_params: ", "format 1 expected");
      seen |= 1;
    } else if (strcmp(key, "machine") == 0) {
      if (params_string(r, text, "machine: ")) return -1;
      if (strcmp(text, STANDIN_MACHINE_NAME) != 0) {
        snprintf(what, sizeof what, "'%s' is not this component's model '%s'", text,
                 STANDIN_MACHINE_NAME);
        return params_mismatch(r, "machine: ", what);
      }
      seen |= 2;
    } else if (strcmp(key, "model_key") == 0) {
      if (params_string(r, text, "model_key: ")) return -1;
      if (strcmp(text, STANDIN_MODEL_KEY) != 0) {
        snprintf(what, sizeof what,
                 "'%s' is not the model's '%s': the parameters were identified with another "
                 "machine file, order or weilgen version (identify again)", text, STANDIN_MODEL_KEY);
        return params_mismatch(r, "model_key: ", what);
      }
      seen |= 4;
    } else if (params_skip(r, 0, "")) {
      return -1;
    }
  }
  if (more < 0) return -1;
  if (params_peek(r) >= 0) return params_fail(r, "", "text after the document");
  if (!(seen & 1))
    return params_mismatch(r, "", "no weilgen_params: not a file of weilgen identify --emit-params-json");
  if (!(seen & 2)) return params_mismatch(r, "", "no machine");
  if (!(seen & 4)) return params_mismatch(r, "", "no model_key");
  return 0;
}

static int params_params(struct params_reader *r, struct standin_params_block *b) {
  char key[PARAMS_MAX_TEXT], context[PARAMS_MAX_TEXT + 32];
  int first = 1, more, i = 0;
  while ((more = params_item(r, &first, "params: ")) == 1) {
    int member = 1, seen = 0, m;
    snprintf(context, sizeof context, "params[%d]: ", i);
    if (i >= STANDIN_NUM_PARAMS) return params_fail(r, context, "more parameters than the model has");
    while ((m = params_member(r, &member, key, context)) == 1) {
      if (strcmp(key, "name") == 0) {
        if (params_name(r, standin_param_name(i), context)) return -1;
        seen |= 1;
      } else if (strcmp(key, "value") == 0) {
        if (params_number(r, &b->params[i], context)) return -1;
        seen |= 2;
      } else if (params_skip(r, 0, context)) {
        return -1;
      }
    }
    if (m < 0) return -1;
    if (seen != 3) return params_fail(r, context, "a parameter needs its name and value");
    ++i;
  }
  if (more < 0) return -1;
  if (i != STANDIN_NUM_PARAMS) return params_fail(r, "params: ", "fewer parameters than the model has");
  b->params[STANDIN_NUM_PARAMS] = 0.0;
  return 0;
}

static int params_axes(struct params_reader *r, struct standin_params_block *b) {
  char key[PARAMS_MAX_TEXT], context[PARAMS_MAX_TEXT + 32];
  int first = 1, more, i = 0;
  while ((more = params_item(r, &first, "axes: ")) == 1) {
    int member = 1, seen = 0, m;
    snprintf(context, sizeof context, "axes[%d]: ", i);
    if (i >= STANDIN_NUM_AXES) return params_fail(r, context, "more axes than the model has");
    while ((m = params_member(r, &member, key, context)) == 1) {
      if (strcmp(key, "name") == 0) {
        if (params_name(r, standin_axis_name(i), context)) return -1;
        seen |= 1;
      } else if (strcmp(key, "span") == 0) {
        int item = 1;
        if (params_item(r, &item, context) != 1 || params_number(r, &b->span_min[i], context) ||
            params_item(r, &item, context) != 1 || params_number(r, &b->span_max[i], context) ||
            params_item(r, &item, context) != 0)
          return params_fail(r, context, "span is [min, max]");
        if (!(b->span_min[i] <= b->span_max[i])) return params_fail(r, context, "span min > max");
        seen |= 2;
      } else if (params_skip(r, 0, context)) {
        return -1;
      }
    }
    if (m < 0) return -1;
    if (seen != 3) return params_fail(r, context, "an axis needs its name and span");
    ++i;
  }
  if (more < 0) return -1;
  if (i != STANDIN_NUM_AXES) return params_fail(r, "axes: ", "fewer axes than the model has");
  return 0;
}

static int params_error(struct params_reader *r, struct standin_params_block *b, int k,
                        const char *context) {
  char key[PARAMS_MAX_TEXT], basis[PARAMS_MAX_TEXT] = "";
  int member = 1, m, seen = 0, n = 0;
  double axis = -1, period = 0, value = 0;
  b->from[k] = b->to[k] = b->omega[k] = 0.0;
  while ((m = params_member(r, &member, key, context)) == 1) {
    if (strcmp(key, "name") == 0) {
      if (params_name(r, standin_error_name(k), context)) return -1;
      seen |= 1;
    } else if (strcmp(key, "basis") == 0) {
      if (params_string(r, basis, context)) return -1;
    } else if (strcmp(key, "value") == 0) {
      if (params_number(r, &value, context)) return -1;
      seen |= 2;
    } else if (strcmp(key, "axis") == 0) {
      if (params_number(r, &axis, context)) return -1;
    } else if (strcmp(key, "from") == 0) {
      if (params_number(r, &b->from[k], context)) return -1;
      seen |= 4;
    } else if (strcmp(key, "to") == 0) {
      if (params_number(r, &b->to[k], context)) return -1;
      seen |= 8;
    } else if (strcmp(key, "period") == 0) {
      if (params_number(r, &period, context)) return -1;
    } else if (strcmp(key, "coefficients") == 0) {
      int item = 1, more;
      while ((more = params_item(r, &item, context)) == 1) {
        if (n >= STANDIN_PARAMS_MAX_TERMS)
          return params_fail(r, context, "more coefficients than this component takes (32)");
        if (params_number(r, &b->coeff[k][n], context)) return -1;
        ++n;
      }
      if (more < 0) return -1;
      seen |= 16;
    } else if (params_skip(r, 0, context)) {
      return -1;
    }
  }
  if (m < 0) return -1;
  if (!(seen & 1)) return params_fail(r, context, "an error needs its name");
  b->terms[k] = n;
  b->axis[k] = 0;
  if (strcmp(basis, "constant") == 0) {
    if (!(seen & 2)) return params_fail(r, context, "a constant needs its value");
    b->kind[k] = STANDIN_BASIS_CONSTANT;
    b->coeff[k][0] = value;
    b->terms[k] = 1;
    return 0;
  }
  if (strcmp(basis, "poly") == 0) b->kind[k] = STANDIN_BASIS_POLY;
  else if (strcmp(basis, "legendre") == 0) b->kind[k] = STANDIN_BASIS_LEGENDRE;
  else if (strcmp(basis, "chebyshev") == 0) b->kind[k] = STANDIN_BASIS_CHEBYSHEV;
  else if (strcmp(basis, "fourier") == 0) b->kind[k] = STANDIN_BASIS_FOURIER;
  else return params_fail(r, context, "basis is constant, poly, legendre, chebyshev or fourier");
  if (!(axis >= 0 && axis < STANDIN_NUM_AXES && axis == floor(axis)))
    return params_fail(r, context, "axis must be the index of one of the model's axes");
  if ((seen & 28) != 28 || n < 1) return params_fail(r, context, "a basis needs from, to and coefficients");
  if (!(b->from[k] < b->to[k])) return params_fail(r, context, "from must be less than to");
  b->axis[k] = (int)axis;
  if (b->kind[k] == STANDIN_BASIS_FOURIER) {
    if (!(period > 0)) return params_fail(r, context, "a Fourier basis needs a period > 0");
    if (n % 2 == 0) return params_fail(r, context, "a Fourier basis has 1 + 2 N coefficients");
    b->omega[k] = 2.0 * 3.14159265358979323846 / period;
  }
  return 0;
}

static int params_errors(struct params_reader *r, struct standin_params_block *b) {
  char context[PARAMS_MAX_TEXT + 32];
  int first = 1, more, k = 0;
  while ((more = params_item(r, &first, "errors: ")) == 1) {
    snprintf(context, sizeof context, "errors[%d] (%s): ", k,
             k < STANDIN_NUM_ERRORS ? standin_error_name(k) : "-");
    if (k >= STANDIN_NUM_ERRORS) return params_fail(r, context, "more errors than the model has");
    if (params_error(r, b, k, context)) return -1;
    ++k;
  }
  if (more < 0) return -1;
  if (k != STANDIN_NUM_ERRORS) return params_fail(r, "errors: ", "fewer errors than the model has");
  return 0;
}

int standin_params_parse(const char *text, size_t size, struct standin_params_block *block,
                         char *message, size_t message_size) {
  struct params_reader r;
  char key[PARAMS_MAX_TEXT];
  int first = 1, more, seen = 0;
  if (message_size > 0) message[0] = '\0';
  if (text == 0 || block == 0 || message == 0 || message_size == 0) return -1;
  if (strtod("0.5", 0) != 0.5) {
    snprintf(message, message_size, "the C library does not read '0.5' as 0.5 (a locale with a "
             "decimal comma): parameters cannot be read");
    return -1;
  }
  memset(block, 0, sizeof *block);
  r.start = r.p = text;
  r.end = text + size;
  r.message = message;
  r.message_size = message_size;
  r.failed = 0;
  r.quiet = 1;
  if (params_identity(&r) && !r.quiet) return -1;
  r.p = text;
  r.failed = r.quiet = 0;
  while ((more = params_member(&r, &first, key, "")) == 1) {
    if (strcmp(key, "params") == 0) {
      if (params_params(&r, block)) return -1;
      seen |= 1;
    } else if (strcmp(key, "axes") == 0) {
      if (params_axes(&r, block)) return -1;
      seen |= 2;
    } else if (strcmp(key, "errors") == 0) {
      if (params_errors(&r, block)) return -1;
      seen |= 4;
    } else if (params_skip(&r, 0, "")) {
      return -1;
    }
  }
  if (more < 0) return -1;
  if (params_peek(&r) >= 0) return params_fail(&r, "", "text after the document");
  if ((seen & 1) == 0 && STANDIN_NUM_PARAMS > 0) return params_fail(&r, "", "no params");
  if ((seen & 2) == 0) return params_fail(&r, "", "no axes");
  if ((seen & 4) == 0) return params_fail(&r, "", "no errors");
  return 0;
}

int standin_params_read(const char *path, char *buffer, size_t buffer_size,
                        struct standin_params_block *block, char *message, size_t message_size) {
  FILE *f;
  size_t n;
  int extra, r;
  if (message == 0 || message_size == 0) return -1;
  if (path == 0 || path[0] == '\0') {
    snprintf(message, message_size, "no file name given");
    return -1;
  }
  f = fopen(path, "rb");
  if (f == 0) {
    snprintf(message, message_size, "%s: cannot open: %s", path, strerror(errno));
    return -1;
  }
  n = fread(buffer, 1, buffer_size, f);
  extra = n == buffer_size ? fgetc(f) : EOF;
  r = ferror(f);
  fclose(f);
  if (r) {
    snprintf(message, message_size, "%s: read error", path);
    return -1;
  }
  if (extra != EOF) {
    snprintf(message, message_size, "%s: larger than %lu bytes", path, (unsigned long)buffer_size);
    return -1;
  }
  if (standin_params_parse(buffer, n, block, message, message_size) == 0) return 0;
  {
    char detail[512];
    snprintf(detail, sizeof detail, "%s", message);
    snprintf(message, message_size, "%s: %s", path, detail);
  }
  return -1;
}

static double params_held(double x, double lo, double hi) { return x < lo ? lo : x > hi ? hi : x; }

void standin_params_errors(const struct standin_params_block *block, const double *axes,
                           double *errors) {
  int k, j;
  for (k = 0; k < STANDIN_NUM_ERRORS; ++k) {
    const double *c = block->coeff[k];
    const int n = block->terms[k], a = block->axis[k];
    const double x = params_held(axes[a], block->span_min[a], block->span_max[a]);
    const double u = (2.0 * x - (block->from[k] + block->to[k])) / (block->to[k] - block->from[k]);
    double s = c[0];
    switch (block->kind[k]) {
      case STANDIN_BASIS_POLY:
        s = c[n - 1];
        for (j = n - 1; j-- > 0;) s = s * u + c[j];
        break;
      case STANDIN_BASIS_LEGENDRE: {
        double p0 = 1.0, p1 = u, p2;
        s = c[0] * p0;
        if (n > 1) s += c[1] * p1;
        for (j = 1; j + 1 < n; ++j) {
          p2 = ((2.0 * (double)j + 1) * u * p1 - (double)j * p0) / ((double)j + 1.0);
          s += c[j + 1] * p2;
          p0 = p1;
          p1 = p2;
        }
        break;
      }
      case STANDIN_BASIS_CHEBYSHEV: {
        double t0 = 1.0, t1 = u, t2;
        s = c[0] * t0;
        if (n > 1) s += c[1] * t1;
        for (j = 1; j + 1 < n; ++j) {
          t2 = 2.0 * u * t1 - t0;
          s += c[j + 1] * t2;
          t0 = t1;
          t1 = t2;
        }
        break;
      }
      case STANDIN_BASIS_FOURIER: {
        const double w = block->omega[k] * x;
        s = c[0];
        for (j = 1; 2 * j < n; ++j)
          s += c[2 * j - 1] * cos((double)j * w) + c[2 * j] * sin((double)j * w);
        break;
      }
      default:
        break;
    }
    errors[k] = s;
  }
}
