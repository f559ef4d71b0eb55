/* The LinuxCNC HAL component that `weilgen linuxcnc` writes (<component>.c), as a real C file:
 * the generator (src/codegen/emit_hal.cpp) emits everything after the marker line with the
 * stand-in names replaced by the model's (standin -> vmc_3axis, STANDIN -> VMC_3AXIS) and the
 * block between the names markers replaced by the component's name, pin names and default
 * values. Compiled on its own against LinuxCNC's hal.h and the stand-in C API by the build
 * (target hal_component_template_check, when hal.h is installed); the generated components are
 * loaded and run under halrun by CTest linuxcnc_component (tests/linuxcnc/). docs/controllers.md.
 */
/* clang-format off: the text below is emitted byte for byte. */
/* ---- weilgen template: emitted from the next line ---- */
/* Real-time geometric compensation with the weilgen model standin (docs/controllers.md).
 *
 * Every servo period the function <component>.compensate reads the commanded axis positions
 * (<component>.<axis>.pos-cmd, the model's axis units: mm, deg), finds the command whose
 * predicted pose is the nominal pose at the commanded one (standin_compensate_at: the model's
 * Compensate, at most MAX_ITERATIONS iterations) and writes it to <component>.<axis>.pos-comp
 * (feed these to the drives) with <component>.<axis>.correction = pos-comp - pos-cmd. The
 * function <component>.feedback maps drive feedback back: <axis>.pos-fb = <axis>.pos-fb-in -
 * <axis>.correction, so that motion sees the uncompensated position (no following error).
 *
 * The errors at a pose are the identified errors built in from `weilgen identify --emit-params`
 * (zero without) plus the parameters <component>.error.<name> (base units mm, rad; defaults
 * built in from a JSON of errors, else 0; set them at start-up with setp). The model's
 * parameters are the input pins <component>.param.<name> (mm, deg), starting at the values the
 * errors were identified with (the machine file's defaults without): set them, or net a signal
 * such as the tool length to them.
 *
 * Status: <component>.enable (in) switches compensation on; <component>.active (out) is true
 * when the last period's command was compensated; <component>.status (out) is the iterations
 * used (>= 1), 0 when disabled, -1 when not compensated (singular, not finite, not converged:
 * pos-comp = pos-cmd then); <component>.failures counts the periods with -1, <component>.cycles
 * every period. The functions allocate nothing (pins and parameters live in HAL memory from
 * start-up) and every loop is bounded by the model's sizes and MAX_ITERATIONS. */
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "hal.h"

#include "standin_c.h"

MODULE_AUTHOR("weilgen");
MODULE_DESCRIPTION("Geometric error compensation with the weilgen model standin");
MODULE_LICENSE("GPL");

/* The Compensate solver's bound and tolerance (the C++ defaults). */
#define MAX_ITERATIONS 10
#define TOLERANCE_MM 1e-9

/* ---- weilgen template: names begin ---- */
#define COMPONENT "weilgen_standin"
static const char *const axis_pins[STANDIN_NUM_AXES] = {"x", "y"};
static const double error_defaults[STANDIN_NUM_ERRORS] = {0.0, 0.0};
/* ---- weilgen template: names end ---- */

/* Built in from the identified parameters (<component>_errors.cpp): the errors at a pose (mm,
 * rad; zero without identified parameters) and the model parameters they were identified with
 * (the machine file's defaults without). */
void standin_identified_errors(const double *axes, double *errors);
void standin_identified_params(double *params);

struct axis_data {
  hal_float_t *pos_cmd, *pos_comp, *correction, *pos_fb_in, *pos_fb;
};

struct component_data {
  struct axis_data axis[STANDIN_NUM_AXES];
  hal_bit_t *enable, *active;
  hal_s32_t *status;
  hal_u32_t *failures, *cycles;
  hal_float_t *param[STANDIN_NUM_PARAMS + 1]; /* + 1: C has no empty arrays */
  hal_float_t error[STANDIN_NUM_ERRORS];
};

static int comp_id;

/* The errors at `axes`: the identified ones plus the error parameters. */
static void errors_at(const double *axes, double *errors, void *context) {
  const struct component_data *d = (const struct component_data *)context;
  int i;
  standin_identified_errors(axes, errors);
  for (i = 0; i < STANDIN_NUM_ERRORS; ++i) errors[i] += d->error[i];
}

static void compensate(void *arg, long period) {
  struct component_data *d = (struct component_data *)arg;
  double target[STANDIN_NUM_AXES], command[STANDIN_NUM_AXES], params[STANDIN_NUM_PARAMS + 1];
  int i, iterations = 0, status = STANDIN_STATUS_NOT_COMPENSATED;
  const int enabled = *d->enable ? 1 : 0;
  (void)period;
  for (i = 0; i < STANDIN_NUM_AXES; ++i) target[i] = *d->axis[i].pos_cmd;
  for (i = 0; i < STANDIN_NUM_PARAMS; ++i) params[i] = *d->param[i];
  params[STANDIN_NUM_PARAMS] = 0.0;
  if (enabled)
    status = standin_compensate_at(target, errors_at, d, params, command, MAX_ITERATIONS,
                                   TOLERANCE_MM, &iterations);
  for (i = 0; i < STANDIN_NUM_AXES; ++i) {
    const double out = status == STANDIN_STATUS_OK ? command[i] : target[i];
    *d->axis[i].pos_comp = out;
    *d->axis[i].correction = status == STANDIN_STATUS_OK ? out - target[i] : 0.0;
  }
  *d->active = status == STANDIN_STATUS_OK;
  *d->status = !enabled ? 0 : status == STANDIN_STATUS_OK ? iterations : -1;
  if (enabled && status != STANDIN_STATUS_OK) *d->failures += 1;
  *d->cycles += 1;
}

static void feedback(void *arg, long period) {
  struct component_data *d = (struct component_data *)arg;
  int i;
  (void)period;
  for (i = 0; i < STANDIN_NUM_AXES; ++i)
    *d->axis[i].pos_fb = *d->axis[i].pos_fb_in - *d->axis[i].correction;
}

static int make_pins(struct component_data *d) {
  double params[STANDIN_NUM_PARAMS + 1];
  int i, r = 0;
  for (i = 0; i < STANDIN_NUM_AXES && r == 0; ++i) {
    struct axis_data *a = &d->axis[i];
    r = hal_pin_float_newf(HAL_IN, &a->pos_cmd, comp_id, "%s.%s.pos-cmd", COMPONENT, axis_pins[i]);
    if (r == 0)
      r = hal_pin_float_newf(HAL_OUT, &a->pos_comp, comp_id, "%s.%s.pos-comp", COMPONENT,
                             axis_pins[i]);
    if (r == 0)
      r = hal_pin_float_newf(HAL_OUT, &a->correction, comp_id, "%s.%s.correction", COMPONENT,
                             axis_pins[i]);
    if (r == 0)
      r = hal_pin_float_newf(HAL_IN, &a->pos_fb_in, comp_id, "%s.%s.pos-fb-in", COMPONENT,
                             axis_pins[i]);
    if (r == 0)
      r = hal_pin_float_newf(HAL_OUT, &a->pos_fb, comp_id, "%s.%s.pos-fb", COMPONENT, axis_pins[i]);
  }
  if (r == 0) r = hal_pin_bit_newf(HAL_IN, &d->enable, comp_id, "%s.enable", COMPONENT);
  if (r == 0) r = hal_pin_bit_newf(HAL_OUT, &d->active, comp_id, "%s.active", COMPONENT);
  if (r == 0) r = hal_pin_s32_newf(HAL_OUT, &d->status, comp_id, "%s.status", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->failures, comp_id, "%s.failures", COMPONENT);
  if (r == 0) r = hal_pin_u32_newf(HAL_OUT, &d->cycles, comp_id, "%s.cycles", COMPONENT);
  for (i = 0; i < STANDIN_NUM_ERRORS && r == 0; ++i) {
    r = hal_param_float_newf(HAL_RW, &d->error[i], comp_id, "%s.error.%s", COMPONENT,
                             standin_error_name(i));
    d->error[i] = error_defaults[i];
  }
  standin_identified_params(params);
  for (i = 0; i < STANDIN_NUM_PARAMS && r == 0; ++i) {
    r = hal_pin_float_newf(HAL_IN, &d->param[i], comp_id, "%s.param.%s", COMPONENT,
                           standin_param_name(i));
    if (r == 0) *d->param[i] = params[i]; /* the value while no signal is connected */
  }
  return r;
}

int rtapi_app_main(void) {
  struct component_data *d;
  char name[HAL_NAME_LEN + 1];
  int r;
  comp_id = hal_init(COMPONENT);
  if (comp_id < 0) return comp_id;
  d = (struct component_data *)hal_malloc(sizeof(struct component_data));
  r = d == 0 ? -1 : make_pins(d);
  if (r == 0) {
    rtapi_snprintf(name, sizeof name, "%s.compensate", COMPONENT);
    r = hal_export_funct(name, compensate, d, 1, 0, comp_id);
  }
  if (r == 0) {
    rtapi_snprintf(name, sizeof name, "%s.feedback", COMPONENT);
    r = hal_export_funct(name, feedback, d, 1, 0, comp_id);
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

void rtapi_app_exit(void) { hal_exit(comp_id); }
