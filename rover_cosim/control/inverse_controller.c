/* The C twin of InverseModelController (controller.py, longitudinal.py) for the native stepper
 * (rover_cosim.orchestrator.native): the same arithmetic in the same order, so that it gives the
 * Python block's outputs bit for bit (compiled with -ffp-contract=off; checked by the tests).
 *
 * Inputs (value references 0 ..): x [m], v [m/s], W[1..n] [N]. Outputs: tau[1..n] [N.m],
 * Fx_des[1..n] [N], F_all [N]. The functions follow fmi2SetReal, fmi2GetReal and fmi2DoStep
 * (status 0 ok, 3 error; the error's text from controller_message).
 *
 * Per step, as the paper's Sec. 4.1: the body's force demand M sat(kv (v_t - v) + kp (v_t t - x)),
 * shared equally (Eq. 16); per wheel the slip giving that force by the identified Fx(W, slip)
 * model, the filter of Eq. (17) advanced exactly for the held step, and the inverse of the
 * first-order tau -> slip block at the wheel's load, tau = (slip_f + T slip_f') / K. */
#include "inverse_law.h"

enum { MASS, V_TARGET, KV, KP, A_MAX, WN, STEP, FIXED_LOAD, N_SETTINGS };

typedef struct {
    int wheels;
    int ignored;                    /* inputs after the law's that are accepted and not read */
    double settings[N_SETTINGS];
    Law law;                        /* the inverse model (inverse_law.h) */
    double *in, *out;
    char message[256];
} Controller;

static int fail(Controller *c, const char *text) {
    snprintf(c->message, sizeof c->message, "%s", text);
    return ERROR;
}

/* The outputs at time t from the inputs; ``advance``: the filter moves on by h (else it starts
 * settled at the target slips). As InverseModelController._outputs. */
static int outputs(Controller *c, double t, int advance, double h) {
    const double *s = c->settings;
    double x = c->in[0], v = c->in[1];
    double acceleration = s[KV] * (s[V_TARGET] - v) + s[KP] * (s[V_TARGET] * t - x);
    double clipped = acceleration < -s[A_MAX] ? -s[A_MAX] : acceleration > s[A_MAX] ? s[A_MAX] : acceleration;
    double force_all = s[MASS] * clipped;
    double force = force_all / c->wheels;
    double ad[4], bd[2];
    law_discretisation(&c->law, advance, h, ad, bd);
    for (int i = 0; i < c->wheels; i++) {
        double load = s[FIXED_LOAD] != 0 ? s[FIXED_LOAD] : c->in[2 + i];
        if (law_torque(&c->law, i, load, force, advance, ad, bd, &c->out[i]) != OK) return ERROR;
        c->out[c->wheels + i] = force;
    }
    c->out[2 * c->wheels] = force_all;
    return OK;
}

int controller_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    Controller *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)(2 + c->wheels + c->ignored)) return fail(c, "set_real: no such input");
        if (vr[k] < (unsigned int)(2 + c->wheels)) c->in[vr[k]] = value[k];
    }
    return OK;
}

int controller_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    Controller *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)(2 * c->wheels + 1)) return fail(c, "get_real: no such output");
        value[k] = c->out[vr[k]];
    }
    return OK;
}

/* The step of ``h`` [s] whose outputs are those at ``t`` itself: what the Python block computes when
 * a block built on it steps the law from its own step (the adaptive controller's calibration), bit
 * for bit; the engine's step from t is the one at t + h. */
int controller_step_at(void *component, double t, double h) {
    Controller *c = component;
    if (law_step_allowed(c->message, h, c->settings[STEP]) != OK) return ERROR;
    return outputs(c, t, 1, h);
}

int controller_do_step(void *component, double t, double h, int no_prior_state) {
    (void)no_prior_state;
    return controller_step_at(component, t + h, h);
}

/* The filter's state (per wheel slip_f, slip_f' [1/s]) out of and into ``filter`` (2 x wheels):
 * a block that steps the law through its twin keeps its own state with it (masters that repeat a step). */
void controller_get_filter(void *component, double *filter) {
    Controller *c = component;
    memcpy(filter, c->law.filter, 2 * (size_t)c->wheels * sizeof(double));
}

void controller_set_filter(void *component, const double *filter) {
    Controller *c = component;
    memcpy(c->law.filter, filter, 2 * (size_t)c->wheels * sizeof(double));
}

/* Accept ``count`` inputs after the law's (value references 2 + wheels ..) and ignore them: the
 * inputs of a block that steps this law after a phase of its own (the adaptive controller). */
void controller_ignore_inputs(void *component, int count) { ((Controller *)component)->ignored = count > 0 ? count : 0; }

const char *controller_message(void *component) { return ((Controller *)component)->message; }

void controller_free(void *component) {
    Controller *c = component;
    if (!c) return;
    law_free(&c->law);
    free(c->in);
    free(c->out);
    free(c);
}

/* A controller for ``wheels`` wheels over tables of ``n_loads`` loads x ``n_torques`` torques
 * (both >= 2) and an Fx model of ``degree`` 1 or 2; ``settings`` as the enum above
 * (FIXED_LOAD 0: the measured loads); ``filter``: per wheel slip_f, slip_f' (the block's state
 * now; outputs start at 0 until the first step). All arrays are copied. NULL for bad sizes or
 * out of memory. */
void *controller_new(int wheels, int n_loads, int n_torques, int degree, const double *settings,
                     const double *inverse, const double *torques, const double *settled, const double *log_t,
                     const double *coefficients, const double *filter) {
    Controller *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->wheels = wheels;
    memcpy(c->settings, settings, sizeof c->settings);
    c->in = calloc(2 + (size_t)(wheels > 0 ? wheels : 0), sizeof(double));
    c->out = calloc(2 * (size_t)(wheels > 0 ? wheels : 0) + 1, sizeof(double));
    if (law_init(&c->law, wheels, n_loads, n_torques, degree, settings[WN], settings[STEP], inverse, torques, settled,
                 log_t, coefficients, filter, c->message) != 0 || !c->in || !c->out) {
        controller_free(c);
        return NULL;
    }
    return c;
}
