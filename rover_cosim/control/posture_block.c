/* The C twin of PostureController (posture.py) for the native stepper
 * (rover_cosim.orchestrator.native): the part that runs every step, with the same arithmetic in
 * the same order, so that it gives the Python block's outputs bit for bit (compiled with
 * -ffp-contract=off; checked by the tests).
 *
 * Every step: the 36 set-points moving linearly from the last update's joints to the new ones over
 * a period (the first-order hold), the path follower's steering on the ankle steer joints, the
 * commanded posture, and with the step-over manoeuvre the motors' torques passed through with a
 * lifted wheel's held at 0. Every ``period`` [s] (with control) the slow loops run: the twin calls
 * ``update(now, inputs)``, the block's own update in Python (its inverse kinematics, Newton on a
 * tilted body, is no step's work), which writes the new joints, commands and lifted limb into the
 * twin's ``shared`` array before it returns 0 (else it has set the message with posture_fail).
 *
 * Inputs (value references 0 ..): z [m], roll, pitch, yaw [rad], W[1..n] [N], steer[1..n] [rad],
 * with step-over also sinkage[1..n] [m] and tau_cmd[1..n] [N.m]. Outputs: for each joint
 * (hipYaw, hipPitch, kneePitch, anklePitch, ankleSteer, ankleRoll) its n set-points [rad], then
 * height_cmd, shift_x, shift_y [m], roll_cmd, pitch_cmd [rad], with step-over tau[1..n] [N.m], then for
 * each joint its n set-points' rates [rad/s]: the slope of the ramp over the step that ends at t + h
 * (taken before an update there starts the next one).
 * The functions follow fmi2SetReal, fmi2GetReal and fmi2DoStep (status 0 ok, 3 error; the error's
 * text from posture_message). */
#include <stdio.h>
#include <stdlib.h>

enum { OK = 0, ERROR = 3 };
enum { JOINTS = 6, STEER = 4, COMMANDS = 5, BODY_INPUTS = 4 };

/* The slow loops' update at ``now`` [s] from the inputs; 0 on success. */
typedef int (*PostureUpdate)(double now, const double *inputs);

typedef struct {
    int limbs, stepping, control;
    double period, next_update;       /* s */
    /* written by the update: previous[limbs * 6], joints[limbs * 6] (row per limb) [rad],
     * commands[5] (m, m, m, rad, rad), the lifted limb (0-based; < 0: none) */
    double *shared;
    PostureUpdate update;
    int n_inputs, n_outputs;
    double *in, *out;
    char message[512];
} Posture;

static int fail(Posture *c, const char *text) {
    snprintf(c->message, sizeof c->message, "%s", text);
    return ERROR;
}

int posture_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    Posture *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)c->n_inputs) return fail(c, "set_real: no such input");
        c->in[vr[k]] = value[k];
    }
    return OK;
}

int posture_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    Posture *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)c->n_outputs) return fail(c, "get_real: no such output");
        value[k] = c->out[vr[k]];
    }
    return OK;
}

/* The set-points at ``now`` [s], as PostureController._outputs. */
static void outputs(Posture *c, double now) {
    int n = c->limbs;
    const double *previous = c->shared, *joints = c->shared + n * JOINTS, *commands = c->shared + 2 * n * JOINTS;
    const double *steer = c->in + BODY_INPUTS + n;
    double fraction = (now - (c->next_update - c->period)) / c->period;
    if (fraction < 0.0) fraction = 0.0;
    if (fraction > 1.0) fraction = 1.0;
    for (int i = 0; i < n; i++) {
        for (int k = 0; k < JOINTS; k++) {
            double a = previous[i * JOINTS + k];
            double value = a + fraction * (joints[i * JOINTS + k] - a);
            if (k == STEER) value = value - steer[i];  /* a heading change of d is -d on the steer joint */
            c->out[k * n + i] = value;
        }
    }
    for (int k = 0; k < COMMANDS; k++) c->out[JOINTS * n + k] = commands[k];
    if (c->stepping) {
        const double *torques = c->in + BODY_INPUTS + 3 * n;
        int lifted = (int)commands[COMMANDS];
        for (int i = 0; i < n; i++) c->out[JOINTS * n + COMMANDS + i] = i == lifted ? 0.0 : torques[i];
    }
}

/* The set-points' rates [rad/s], as PostureController._rates: the slope of the ramp from the last
 * update's joints to the new ones. */
static void rates(Posture *c) {
    int n = c->limbs;
    const double *previous = c->shared, *joints = c->shared + n * JOINTS;
    double *rate = c->out + JOINTS * n + COMMANDS + (c->stepping ? n : 0);
    for (int i = 0; i < n; i++)
        for (int k = 0; k < JOINTS; k++)
            rate[k * n + i] = (joints[i * JOINTS + k] - previous[i * JOINTS + k]) / c->period;
}

int posture_do_step(void *component, double t, double h, int no_prior_state) {
    Posture *c = component;
    double now = t + h;
    (void)no_prior_state;
    rates(c); /* the slopes over this step, before an update at its end */
    if (c->control && now >= c->next_update - 1e-12) {
        if (c->update(now, c->in) != 0) {
            if (!c->message[0]) snprintf(c->message, sizeof c->message, "the posture update at t = %.17g failed", now);
            return ERROR;
        }
        c->next_update += c->period;
    }
    outputs(c, now);
    return OK;
}

/* The update's error (it returned non-zero), for posture_message. */
void posture_fail(void *component, const char *text) { fail(component, text); }

const char *posture_message(void *component) { return ((Posture *)component)->message; }

void posture_free(void *component) {
    Posture *c = component;
    if (!c) return;
    free(c->in);
    free(c->out);
    free(c);
}

/* A twin of ``limbs`` limbs (step-over: ``stepping``; slow loops: ``control``, every ``period`` [s],
 * the next at ``next_update`` [s]) on ``shared`` (the caller's, kept alive with the twin) with its
 * inputs and outputs now (``inputs``, ``outputs``: copied). NULL for bad sizes or out of memory. */
void *posture_new(int limbs, int stepping, int control, double period, double next_update, double *shared,
                  PostureUpdate update, const double *inputs, const double *outputs_now) {
    if (limbs < 1 || !(period > 0) || !shared || (control && !update)) return NULL;
    Posture *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->limbs = limbs;
    c->stepping = stepping != 0;
    c->control = control != 0;
    c->period = period;
    c->next_update = next_update;
    c->shared = shared;
    c->update = update;
    c->n_inputs = BODY_INPUTS + (c->stepping ? 4 : 2) * limbs;
    c->n_outputs = (2 * JOINTS + (c->stepping ? 1 : 0)) * limbs + COMMANDS;
    c->in = calloc((size_t)c->n_inputs, sizeof *c->in);
    c->out = calloc((size_t)c->n_outputs, sizeof *c->out);
    if (!c->in || !c->out) {
        posture_free(c);
        return NULL;
    }
    for (int k = 0; k < c->n_inputs; k++) c->in[k] = inputs[k];
    for (int k = 0; k < c->n_outputs; k++) c->out[k] = outputs_now[k];
    return c;
}
