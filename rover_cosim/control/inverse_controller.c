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
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { OK = 0, ERROR = 3 };
enum { MASS, V_TARGET, KV, KP, A_MAX, WN, STEP, FIXED_LOAD, N_SETTINGS };

typedef struct {
    int wheels, n_loads, n_torques, degree;
    double settings[N_SETTINGS];
    double ad[4], bd[2];            /* the filter discretised for the nominal step */
    double *inverse;                /* 1/W of the table's loads [1/N], decreasing */
    double *negated_inverse;        /* -1/W, increasing (the Python twin bisects it) */
    double *torques;                /* the table's torques [N.m], increasing */
    double *settled, *log_t;        /* per load: settled slip K tau, log T [log s] (n_loads x n_torques) */
    double *coefficients;           /* (degree + 1) x 3: c_k(W) = row[0] + row[1] W + row[2] W^2 */
    double *filter;                 /* per wheel: slip_f, slip_f' [1/s] */
    double *row, *row_t;            /* scratch: one interpolated row of each table */
    double *in, *out;
    char message[256];
} Controller;

/* Eq. (17), wn^2 / (s^2 + 2 wn s + wn^2), as x' = A x + b u with x = (slip_f, slip_f'):
 * critically damped, so exp(A h) = e^(-wn h) [[1 + wn h, h], [-wn^2 h, 1 - wn h]] and the input
 * held over h enters with b_d = (1 - e^(-wn h) (1 + wn h), wn^2 h e^(-wn h)). As
 * LongitudinalInverse.discretised. */
static void discretise(double wn, double h, double *ad, double *bd) {
    double decay = exp(-wn * h), wh = wn * h, wn2 = wn * wn;
    ad[0] = decay * (1.0 + wh);
    ad[1] = decay * h;
    ad[2] = decay * (-wn2 * h);
    ad[3] = decay * (1.0 - wh);
    bd[0] = 1.0 - decay * (1.0 + wh);
    bd[1] = wn2 * h * decay;
}

/* Python's bisect.bisect_left / bisect_right on an increasing array. */
static int bisect_left(const double *a, int n, double x) {
    int lo = 0, hi = n;
    while (lo < hi) { int mid = (lo + hi) / 2; if (a[mid] < x) lo = mid + 1; else hi = mid; }
    return lo;
}

static int bisect_right(const double *a, int n, double x) {
    int lo = 0, hi = n;
    while (lo < hi) { int mid = (lo + hi) / 2; if (x < a[mid]) hi = mid; else lo = mid + 1; }
    return lo;
}

static int clamp(int j, int low, int high) { return j < low ? low : j > high ? high : j; }

static int fail(Controller *c, const char *text) {
    snprintf(c->message, sizeof c->message, "%s", text);
    return ERROR;
}

/* _slip_for_force: the slip at which the Fx(W, slip) model gives ``force`` (the quadratic's root
 * nearest the linear solution). */
static int slip_for_force(Controller *c, double load, double force, double *slip) {
    double k[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i <= c->degree && i < 3; i++) {
        const double *row = c->coefficients + 3 * i;
        k[i] = row[0] + row[1] * load + row[2] * load * load;
    }
    double linear = (force - k[0]) / k[1];
    if (c->degree == 1) { *slip = linear; return OK; }
    double discriminant = k[1] * k[1] - 4.0 * k[2] * (k[0] - force);
    if (k[2] == 0 || discriminant < 0) { *slip = linear; return OK; }
    double root = sqrt(discriminant);
    double plus = (-k[1] + root) / (2.0 * k[2]), minus = (-k[1] - root) / (2.0 * k[2]);
    *slip = fabs(plus - linear) <= fabs(minus - linear) ? plus : minus;
    return OK;
}

/* _rows: the settled-slip and log T rows at ``load``, interpolated in 1/W. */
static int rows_at(Controller *c, double load) {
    if (!(load > 0)) {
        snprintf(c->message, sizeof c->message, "loads = %.15g N: expected > 0", load);
        return ERROR;
    }
    int n = c->n_loads, m = c->n_torques;
    double x = 1.0 / load;
    int j = clamp(bisect_left(c->negated_inverse, n, -x), 1, n - 1);
    double weight = (x - c->inverse[j - 1]) / (c->inverse[j] - c->inverse[j - 1]);
    for (int i = 0; i < m; i++) {
        c->row[i] = (1 - weight) * c->settled[(j - 1) * m + i] + weight * c->settled[j * m + i];
        c->row_t[i] = (1 - weight) * c->log_t[(j - 1) * m + i] + weight * c->log_t[j * m + i];
    }
    return OK;
}

/* _torque_for: the torque whose settled slip is ``slip`` (linear between the table's torques,
 * extended linearly beyond them). */
static double torque_for(const Controller *c, double slip) {
    const double *row = c->row, *torques = c->torques;
    int j = clamp(bisect_left(row, c->n_torques, slip), 1, c->n_torques - 1);
    return torques[j - 1] + (slip - row[j - 1]) * (torques[j] - torques[j - 1]) / (row[j] - row[j - 1]);
}

/* _time_constant: T [s] at ``torque``, linear in T between the table's torques, held beyond. */
static double time_constant(const Controller *c, double torque) {
    const double *torques = c->torques;
    int m = c->n_torques;
    if (torque <= torques[0]) return exp(c->row_t[0]);
    if (torque >= torques[m - 1]) return exp(c->row_t[m - 1]);
    int j = bisect_right(torques, m, torque);
    double low = exp(c->row_t[j - 1]), high = exp(c->row_t[j]);
    return low + (torque - torques[j - 1]) * (high - low) / (torques[j] - torques[j - 1]);
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
    memcpy(ad, c->ad, sizeof ad);
    memcpy(bd, c->bd, sizeof bd);
    if (advance && fabs(h - s[STEP]) > 1e-12) discretise(s[WN], h, ad, bd);
    for (int i = 0; i < c->wheels; i++) {
        double load = s[FIXED_LOAD] != 0 ? s[FIXED_LOAD] : c->in[2 + i];
        double target, slip, rate;
        if (slip_for_force(c, load, force, &target) != OK) return ERROR;
        if (advance) {
            double slip_f = c->filter[2 * i], rate_f = c->filter[2 * i + 1];
            slip = ad[0] * slip_f + ad[1] * rate_f + bd[0] * target;
            rate = ad[2] * slip_f + ad[3] * rate_f + bd[1] * target;
        } else {
            slip = target;
            rate = 0.0;
        }
        c->filter[2 * i] = slip;
        c->filter[2 * i + 1] = rate;
        if (rows_at(c, load) != OK) return ERROR;
        double constant = time_constant(c, torque_for(c, slip));
        c->out[i] = torque_for(c, slip + constant * rate);
        c->out[c->wheels + i] = force;
    }
    c->out[2 * c->wheels] = force_all;
    return OK;
}

int controller_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    Controller *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)(2 + c->wheels)) return fail(c, "set_real: no such input");
        c->in[vr[k]] = value[k];
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

int controller_do_step(void *component, double t, double h, int no_prior_state) {
    Controller *c = component;
    (void)no_prior_state;
    double step = c->settings[STEP];
    if (!(0 < h && h <= step * (1 + 1e-9))) {
        snprintf(c->message, sizeof c->message,
                 "communication step %.15g s: expected at most its step = %.15g s (a shorter last step is fine)",
                 h, step);
        return ERROR;
    }
    return outputs(c, t + h, 1, h);
}

const char *controller_message(void *component) { return ((Controller *)component)->message; }

void controller_free(void *component) {
    Controller *c = component;
    if (!c) return;
    double *arrays[] = {c->inverse, c->negated_inverse, c->torques, c->settled, c->log_t, c->coefficients,
                        c->filter, c->row, c->row_t, c->in, c->out};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++) free(arrays[k]);
    free(c);
}

static double *copy_of(const double *values, size_t n) {
    double *copy = malloc((n ? n : 1) * sizeof *copy);
    if (copy && n) memcpy(copy, values, n * sizeof *copy);
    return copy;
}

/* A controller for ``wheels`` wheels over tables of ``n_loads`` loads x ``n_torques`` torques
 * (both >= 2) and an Fx model of ``degree`` 1 or 2; ``settings`` as the enum above
 * (FIXED_LOAD 0: the measured loads); ``filter``: per wheel slip_f, slip_f' (the block's state
 * now; outputs start at 0 until the first step). All arrays are copied. NULL for bad sizes or
 * out of memory. */
void *controller_new(int wheels, int n_loads, int n_torques, int degree, const double *settings,
                     const double *inverse, const double *torques, const double *settled, const double *log_t,
                     const double *coefficients, const double *filter) {
    if (wheels < 1 || n_loads < 2 || n_torques < 2 || degree < 1 || degree > 2) return NULL;
    Controller *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    size_t n = (size_t)n_loads, m = (size_t)n_torques, w = (size_t)wheels;
    c->wheels = wheels; c->n_loads = n_loads; c->n_torques = n_torques; c->degree = degree;
    memcpy(c->settings, settings, sizeof c->settings);
    c->inverse = copy_of(inverse, n);
    c->negated_inverse = malloc(n * sizeof(double));
    c->torques = copy_of(torques, m);
    c->settled = copy_of(settled, n * m);
    c->log_t = copy_of(log_t, n * m);
    c->coefficients = copy_of(coefficients, 3 * (size_t)(degree + 1));
    c->filter = copy_of(filter, 2 * w);
    c->row = calloc(m, sizeof(double));
    c->row_t = calloc(m, sizeof(double));
    c->in = calloc(2 + w, sizeof(double));
    c->out = calloc(2 * w + 1, sizeof(double));
    if (!c->inverse || !c->negated_inverse || !c->torques || !c->settled || !c->log_t || !c->coefficients
        || !c->filter || !c->row || !c->row_t || !c->in || !c->out) {
        controller_free(c);
        return NULL;
    }
    for (size_t i = 0; i < n; i++) c->negated_inverse[i] = -c->inverse[i];
    discretise(c->settings[WN], c->settings[STEP], c->ad, c->bd);
    return c;
}
