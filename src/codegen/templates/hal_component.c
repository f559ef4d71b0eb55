/* The LinuxCNC HAL component that `weilgen linuxcnc` writes (<component>_hal.c), as a real C file:
 * the generator (src/codegen/emit_hal.cpp) emits everything after the marker line with the
 * stand-in names replaced by the model's (standin -> vmc_3axis, STANDIN -> VMC_3AXIS) and the
 * block between the names markers replaced by the component's name, pin names, the LinuxCNC
 * joint mapping and the default limits. Compiled on its own against LinuxCNC's hal.h and the
 * stand-in C API by the build (target hal_component_template_check, when hal.h is installed);
 * the generated components are loaded and run under halrun by CTests linuxcnc_component,
 * linuxcnc_configs and linuxcnc_closed_loop (tests/linuxcnc/). docs/controllers.md.
 */
/* clang-format off: the text below is emitted byte for byte. */
/* ---- weilgen template: emitted from the next line ---- */
/* Real-time geometric compensation with the weilgen model standin (docs/controllers.md).
 *
 * Coordinates. LinuxCNC's joint positions are the tool's position relative to the workpiece in
 * the configuration's units; the model's axis coordinates are the positions of the axes' own
 * bodies in the model's units (mm, deg). For each axis, model = offset + sign * scale * joint
 * (the parameters <axis>.sign, .scale, .offset, from the machine file: an axis that carries the
 * workpiece has sign -1). The component evaluates the model at <axis>.pos-cmd (net
 * joint.N.pos-cmd, the joint position before LinuxCNC's home offset and backlash or screw
 * compensation), maps the correction back to joint units and adds it to <axis>.motor-pos-cmd
 * (net joint.N.motor-pos-cmd): <axis>.pos-comp = motor-pos-cmd + correction goes to the drive,
 * and <component>.feedback gives motion <axis>.pos-fb = pos-fb-in - correction.
 *
 * Every servo period <component>.compensate, when enable and homed are both true: the target
 * pose (model units) from pos-cmd; the errors at the command (the identified errors, held at
 * their identified span's ends, plus the input pins <component>.error.<E>, base units mm and
 * rad); the model's Compensate (at most MAX_ITERATIONS iterations); the correction in joint
 * units. The applied correction <axis>.correction moves toward it by at most <axis>.max-step per
 * period: it ramps in and out on enable, homing, error changes and faults, never steps.
 *
 * Safety (all per period, latched in <component>.fault until a rising fault-reset, the cause in
 * fault-code, counted in pins):
 *   1  a pos-cmd, error or param input is NaN or infinite: the correction ramps to 0;
 *      a motor-pos-cmd that is not finite: pos-comp keeps its last value (NaN never reaches a
 *      drive)                                                                    (nan-inputs)
 *   2  Compensate fails (singular, not converged): the correction ramps to 0     (failures)
 *   4  |correction| > <axis>.max-correction on some axis: the correction ramps to 0 (limit-hits)
 *   8  the commanded pose lies outside the model's travel: errors held at the ends of their
 *      identified span, compensation goes on (bounded by max-correction)          (range-hits)
 *  16  a reload of the parameter file failed: the previous parameters stay (reload-failures)
 *  32  a max-correction or max-step parameter is not a finite number > 0 (max-correction >= 0):
 *      that axis' correction ramps to 0 at the default step
 *
 * Identified errors: from the file named by the module parameter params_file (weilgen identify
 * --emit-params-json; read when the module loads, a bad file refuses the load), else compiled in
 * (weilgen linuxcnc --params <machine>_params.hpp), else none. A rising edge on <component>.reload
 * reads the file again in the component's own non-realtime thread into the unused one of two
 * parameter blocks and publishes it with one atomic store; the servo function takes the block
 * index once per period and does no file I/O. The functions allocate nothing (pins and
 * parameters live in HAL memory, the blocks in the module) and every loop is bounded by the
 * model's sizes, STANDIN_PARAMS_MAX_TERMS and MAX_ITERATIONS. uspace only (POSIX threads). */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "rtapi_math.h"
#include "hal.h"

#include <pthread.h>
#include <string.h>
#include <time.h>

#include "standin_c.h"
#include "standin_params_file.h"

MODULE_AUTHOR("weilgen");
MODULE_DESCRIPTION("Geometric error compensation with the weilgen model standin");
MODULE_LICENSE("GPL");

static char *params_file = 0;
RTAPI_MP_STRING(params_file, "identified parameters: the JSON of weilgen identify --emit-params-json");

/* The Compensate solver's bound and tolerance (the C++ defaults). */
#define MAX_ITERATIONS 10
#define TOLERANCE_MM 1e-9

/* ---- weilgen template: names begin ---- */
#define COMPONENT "weilgen_standin"
static const char *const axis_pins[STANDIN_NUM_AXES] = {"x", "y"};
static const double error_defaults[STANDIN_NUM_ERRORS] = {0.0, 0.0};
/* model = offset + sign * scale * joint; travel in model units; limits in joint units. */
static const double axis_sign[STANDIN_NUM_AXES] = {-1.0, 1.0};
static const double axis_scale[STANDIN_NUM_AXES] = {1.0, 1.0};
static const double axis_offset[STANDIN_NUM_AXES] = {0.0, 0.0};
static const double travel_min[STANDIN_NUM_AXES] = {0.0, 0.0};
static const double travel_max[STANDIN_NUM_AXES] = {500.0, 400.0};
static const double default_max_correction[STANDIN_NUM_AXES] = {0.1, 0.1};
static const double default_max_step[STANDIN_NUM_AXES] = {0.001, 0.001};
#define IDENTIFIED_BUILT_IN 0
/* ---- weilgen template: names end ---- */

enum fault_cause {
  FAULT_NAN_INPUT = 1,
  FAULT_NOT_COMPENSATED = 2,
  FAULT_OVER_LIMIT = 4,
  FAULT_OUT_OF_TRAVEL = 8,
  FAULT_RELOAD = 16,
  FAULT_BAD_LIMIT = 32
};

/* The loader thread's state; the servo function posts REQUESTED and takes DONE_*. */
enum loader_state { LOADER_IDLE, LOADER_REQUESTED, LOADER_BUSY, LOADER_DONE_OK, LOADER_DONE_FAILED };

/* Built in from the identified parameters (<component>_errors.cpp): the errors at a pose (mm,
 * rad; zero without identified parameters) and the model parameters they were identified with
 * (the machine file's defaults without). */
void standin_identified_errors(const double *axes, double *errors);
void standin_identified_params(double *params);

struct axis_data {
  hal_float_t *pos_cmd, *motor_pos_cmd, *pos_comp, *correction, *pos_fb_in, *pos_fb;
  hal_float_t max_correction, max_step, sign, scale, offset, travel_min, travel_max;
  double applied; /* the correction applied, joint units */
};

struct component_data {
  struct axis_data axis[STANDIN_NUM_AXES];
  hal_bit_t *enable, *homed, *fault_reset, *reload, *active, *ramping, *fault;
  hal_s32_t *status, *params_source;
  hal_u32_t *fault_code, *failures, *nan_inputs, *limit_hits, *range_hits, *cycles, *reloads,
      *reload_failures;
  hal_float_t *param[STANDIN_NUM_PARAMS + 1]; /* + 1: C has no empty arrays */
  hal_float_t *error[STANDIN_NUM_ERRORS];
  hal_bit_t last_reset, last_reload;
};

static int comp_id;

/* Two parameter blocks: the servo function reads blocks[active_block] (-1: none loaded), the
 * loader writes the other one and publishes it. */
static struct standin_params_block blocks[2];
static int active_block = -1;
static int loader_state = LOADER_IDLE;
static int loader_quit = 0;
static int loader_running = 0;
static pthread_t loader_thread;
static char file_buffer[STANDIN_PARAMS_MAX_FILE];
static char loader_message[768];

struct errors_context {
  const struct component_data *d;
  const struct standin_params_block *block;
};

/* The errors at `axes`: the identified ones (held at their span's ends) plus the error pins. */
static void errors_at(const double *axes, double *errors, void *context) {
  const struct errors_context *c = (const struct errors_context *)context;
  int i;
  if (c->block) standin_params_errors(c->block, axes, errors);
  else standin_identified_errors(axes, errors);
  for (i = 0; i < STANDIN_NUM_ERRORS; ++i) errors[i] += *c->d->error[i];
}

static int is_finite_value(double v) { return v - v == 0.0; }

/* Reads params_file into the block that is not active and publishes it. Returns 0 or -1. */
static int load_params(void) {
  const int current = __atomic_load_n(&active_block, __ATOMIC_ACQUIRE);
  const int next = current == 0 ? 1 : 0;
  if (standin_params_read(params_file, file_buffer, sizeof file_buffer, &blocks[next],
                          loader_message, sizeof loader_message) != 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, "%s: params_file %s\n", COMPONENT, loader_message);
    return -1;
  }
  __atomic_store_n(&active_block, next, __ATOMIC_RELEASE);
  return 0;
}

/* The loader thread: not realtime; polls for a request every 10 ms. */
static void *loader_main(void *unused) {
  const struct timespec pause = {0, 10000000};
  (void)unused;
  while (!__atomic_load_n(&loader_quit, __ATOMIC_ACQUIRE)) {
    if (__atomic_load_n(&loader_state, __ATOMIC_ACQUIRE) == LOADER_REQUESTED) {
      int ok;
      __atomic_store_n(&loader_state, LOADER_BUSY, __ATOMIC_RELEASE);
      ok = load_params() == 0;
      if (ok) rtapi_print_msg(RTAPI_MSG_INFO, "%s: reloaded %s\n", COMPONENT, params_file);
      __atomic_store_n(&loader_state, ok ? LOADER_DONE_OK : LOADER_DONE_FAILED, __ATOMIC_RELEASE);
    }
    nanosleep(&pause, 0);
  }
  return 0;
}

/* Requests, acknowledgements and resets; returns the fault causes of this period so far. */
static unsigned handshake(struct component_data *d) {
  unsigned cause = 0;
  const int state = __atomic_load_n(&loader_state, __ATOMIC_ACQUIRE);
  if (*d->fault_reset && !d->last_reset) {
    *d->fault = 0;
    *d->fault_code = 0;
  }
  d->last_reset = *d->fault_reset;
  if (state == LOADER_DONE_OK || state == LOADER_DONE_FAILED) {
    if (state == LOADER_DONE_OK) {
      *d->reloads += 1;
      *d->params_source = 2;
    } else {
      *d->reload_failures += 1;
      cause |= FAULT_RELOAD;
    }
    __atomic_store_n(&loader_state, LOADER_IDLE, __ATOMIC_RELEASE);
  }
  if (*d->reload && !d->last_reload) {
    if (!loader_running) {
      *d->reload_failures += 1; /* no params_file to read */
      cause |= FAULT_RELOAD;
    } else if (__atomic_load_n(&loader_state, __ATOMIC_ACQUIRE) == LOADER_IDLE) {
      __atomic_store_n(&loader_state, LOADER_REQUESTED, __ATOMIC_RELEASE);
    }
  }
  d->last_reload = *d->reload;
  return cause;
}

static void compensate(void *arg, long period) {
  struct component_data *d = (struct component_data *)arg;
  double target[STANDIN_NUM_AXES], command[STANDIN_NUM_AXES], params[STANDIN_NUM_PARAMS + 1];
  double wanted[STANDIN_NUM_AXES];
  struct errors_context context;
  int i, iterations = 0, computed = 0, ramping = 0;
  unsigned cause = handshake(d);
  const int block = __atomic_load_n(&active_block, __ATOMIC_ACQUIRE);
  const int on = *d->enable && *d->homed;
  (void)period;
  context.d = d;
  context.block = block >= 0 ? &blocks[block] : 0;
  for (i = 0; i < STANDIN_NUM_AXES; ++i) wanted[i] = 0.0;
  if (on) {
    int bad = 0;
    for (i = 0; i < STANDIN_NUM_AXES; ++i) bad |= !is_finite_value(*d->axis[i].pos_cmd);
    for (i = 0; i < STANDIN_NUM_ERRORS; ++i) bad |= !is_finite_value(*d->error[i]);
    for (i = 0; i < STANDIN_NUM_PARAMS; ++i) bad |= !is_finite_value(params[i] = *d->param[i]);
    params[STANDIN_NUM_PARAMS] = 0.0;
    if (bad) {
      cause |= FAULT_NAN_INPUT;
      *d->nan_inputs += 1;
    } else {
      int status, outside = 0;
      for (i = 0; i < STANDIN_NUM_AXES; ++i) {
        const struct axis_data *a = &d->axis[i];
        target[i] = axis_offset[i] + axis_sign[i] * axis_scale[i] * *a->pos_cmd;
        outside |= !(target[i] >= travel_min[i] && target[i] <= travel_max[i]);
      }
      if (outside) {
        cause |= FAULT_OUT_OF_TRAVEL;
        *d->range_hits += 1;
      }
      status = standin_compensate_at(target, errors_at, &context, params, command,
                                     MAX_ITERATIONS, TOLERANCE_MM, &iterations);
      if (status != STANDIN_STATUS_OK) {
        cause |= FAULT_NOT_COMPENSATED;
        *d->failures += 1;
      } else {
        int over = 0;
        for (i = 0; i < STANDIN_NUM_AXES; ++i) {
          wanted[i] = axis_sign[i] * (command[i] - target[i]) / axis_scale[i];
          over |= !(fabs(wanted[i]) <= d->axis[i].max_correction);
        }
        if (over) {
          cause |= FAULT_OVER_LIMIT;
          *d->limit_hits += 1;
          for (i = 0; i < STANDIN_NUM_AXES; ++i) wanted[i] = 0.0;
        } else {
          computed = 1;
        }
      }
    }
  }
  for (i = 0; i < STANDIN_NUM_AXES; ++i) {
    struct axis_data *a = &d->axis[i];
    double step = a->max_step, change;
    if (!(is_finite_value(step) && step > 0.0) || !(a->max_correction >= 0.0)) {
      cause |= FAULT_BAD_LIMIT;
      step = default_max_step[i];
      wanted[i] = 0.0;
    }
    change = wanted[i] - a->applied;
    if (change > step) change = step;
    else if (change < -step) change = -step;
    a->applied += change;
    ramping |= a->applied != wanted[i];
    *a->correction = a->applied;
    if (is_finite_value(*a->motor_pos_cmd)) {
      *a->pos_comp = *a->motor_pos_cmd + a->applied;
    } else if (!(cause & FAULT_NAN_INPUT)) {
      cause |= FAULT_NAN_INPUT; /* pos-comp keeps its last value */
      *d->nan_inputs += 1;
    }
  }
  *d->active = computed;
  *d->ramping = ramping;
  *d->status = !on ? 0 : computed ? iterations : -1;
  if (cause) {
    *d->fault = 1;
    *d->fault_code |= cause;
  }
  *d->cycles += 1;
}

static void feedback(void *arg, long period) {
  struct component_data *d = (struct component_data *)arg;
  int i;
  (void)period;
  for (i = 0; i < STANDIN_NUM_AXES; ++i)
    *d->axis[i].pos_fb = *d->axis[i].pos_fb_in - d->axis[i].applied;
}

static int float_pin(hal_pin_dir_t dir, hal_float_t **p, const char *axis, const char *name) {
  return hal_pin_float_newf(dir, p, comp_id, "%s.%s.%s", COMPONENT, axis, name);
}

static int axis_param(hal_param_dir_t dir, hal_float_t *p, const char *axis, const char *name,
                      double value) {
  const int r = hal_param_float_newf(dir, p, comp_id, "%s.%s.%s", COMPONENT, axis, name);
  if (r == 0) *p = value;
  return r;
}

static int make_pins(struct component_data *d, const double *params) {
  int i, r = 0;
  for (i = 0; i < STANDIN_NUM_AXES && r == 0; ++i) {
    struct axis_data *a = &d->axis[i];
    const char *n = axis_pins[i];
    a->applied = 0.0;
    r = float_pin(HAL_IN, &a->pos_cmd, n, "pos-cmd");
    if (r == 0) r = float_pin(HAL_IN, &a->motor_pos_cmd, n, "motor-pos-cmd");
    if (r == 0) r = float_pin(HAL_OUT, &a->pos_comp, n, "pos-comp");
    if (r == 0) r = float_pin(HAL_OUT, &a->correction, n, "correction");
    if (r == 0) r = float_pin(HAL_IN, &a->pos_fb_in, n, "pos-fb-in");
    if (r == 0) r = float_pin(HAL_OUT, &a->pos_fb, n, "pos-fb");
    if (r == 0) r = axis_param(HAL_RW, &a->max_correction, n, "max-correction", default_max_correction[i]);
    if (r == 0) r = axis_param(HAL_RW, &a->max_step, n, "max-step", default_max_step[i]);
    if (r == 0) r = axis_param(HAL_RO, &a->sign, n, "sign", axis_sign[i]);
    if (r == 0) r = axis_param(HAL_RO, &a->scale, n, "scale", axis_scale[i]);
    if (r == 0) r = axis_param(HAL_RO, &a->offset, n, "offset", axis_offset[i]);
    if (r == 0) r = axis_param(HAL_RO, &a->travel_min, n, "travel-min", travel_min[i]);
    if (r == 0) r = axis_param(HAL_RO, &a->travel_max, n, "travel-max", travel_max[i]);
  }
  if (r == 0) r = hal_pin_bit_newf(HAL_IN, &d->enable, comp_id, "%s.enable", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_IN, &d->homed, comp_id, "%s.homed", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_IN, &d->fault_reset, comp_id, "%s.fault-reset", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_IN, &d->reload, comp_id, "%s.reload", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_OUT, &d->active, comp_id, "%s.active", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_OUT, &d->ramping, comp_id, "%s.ramping", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_OUT, &d->fault, comp_id, "%s.fault", COMPONENT);
  if (r == 0) r = hal_pin_s32_newf(HAL_OUT, &d->status, comp_id, "%s.status", COMPONENT);
  if (r == 0) r = hal_pin_s32_newf(HAL_OUT, &d->params_source, comp_id, "%s.params-source", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->fault_code, comp_id, "%s.fault-code", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->failures, comp_id, "%s.failures", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->nan_inputs, comp_id, "%s.nan-inputs", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->limit_hits, comp_id, "%s.limit-hits", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->range_hits, comp_id, "%s.range-hits", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->cycles, comp_id, "%s.cycles", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->reloads, comp_id, "%s.reloads", COMPONENT);
  if (r == 0)
    r = hal_pin_u32_newf(HAL_OUT, &d->reload_failures, comp_id, "%s.reload-failures", COMPONENT);
  for (i = 0; i < STANDIN_NUM_ERRORS && r == 0; ++i) {
    r = hal_pin_float_newf(HAL_IN, &d->error[i], comp_id, "%s.error.%s", COMPONENT,
                           standin_error_name(i));
    if (r == 0) *d->error[i] = error_defaults[i]; /* the value while no signal is connected */
  }
  for (i = 0; i < STANDIN_NUM_PARAMS && r == 0; ++i) {
    r = hal_pin_float_newf(HAL_IN, &d->param[i], comp_id, "%s.param.%s", COMPONENT,
                           standin_param_name(i));
    if (r == 0) *d->param[i] = params[i];
  }
  if (r == 0) *d->params_source = active_block >= 0 ? 2 : IDENTIFIED_BUILT_IN;
  return r;
}

static void stop_loader(void) {
  if (!loader_running) return;
  __atomic_store_n(&loader_quit, 1, __ATOMIC_RELEASE);
  pthread_join(loader_thread, 0);
  loader_running = 0;
}

/* The loader thread, at normal (not realtime) priority whatever the caller's. */
static int start_loader(void) {
  pthread_attr_t attr;
  struct sched_param normal;
  int r = pthread_attr_init(&attr);
  memset(&normal, 0, sizeof normal);
  if (r == 0) r = pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
  if (r == 0) r = pthread_attr_setschedpolicy(&attr, SCHED_OTHER);
  if (r == 0) r = pthread_attr_setschedparam(&attr, &normal);
  if (r == 0) r = pthread_create(&loader_thread, &attr, loader_main, 0);
  pthread_attr_destroy(&attr);
  if (r == 0) loader_running = 1;
  return r;
}

int rtapi_app_main(void) {
  struct component_data *d;
  char name[HAL_NAME_LEN + 1];
  double params[STANDIN_NUM_PARAMS + 1];
  int r, i;
  standin_identified_params(params);
  if (params_file && params_file[0]) {
    /* A file that cannot be read, or holds another model's parameters, refuses the load. */
    if (load_params() != 0) return -1;
    for (i = 0; i < STANDIN_NUM_PARAMS; ++i) params[i] = blocks[active_block].params[i];
  }
  comp_id = hal_init(COMPONENT);
  if (comp_id < 0) return comp_id;
  d = (struct component_data *)hal_malloc(sizeof(struct component_data));
  r = d == 0 ? -1 : make_pins(d, params);
  if (r == 0) {
    rtapi_snprintf(name, sizeof name, "%s.compensate", COMPONENT);
    r = hal_export_funct(name, compensate, d, 1, 0, comp_id);
  }
  if (r == 0) {
    rtapi_snprintf(name, sizeof name, "%s.feedback", COMPONENT);
    r = hal_export_funct(name, feedback, d, 1, 0, comp_id);
  }
  if (r == 0 && params_file && params_file[0] && start_loader() != 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, "%s: cannot start the parameter loader thread\n", COMPONENT);
    r = -1;
  }
  if (r != 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, "%s: could not create its pins, parameters or functions\n",
                    COMPONENT);
    hal_exit(comp_id);
    return r;
  }
  hal_ready(comp_id);
  return 0;
}

void rtapi_app_exit(void) {
  stop_loader();
  hal_exit(comp_id);
}
