/* The inverse of the identified longitudinal model (longitudinal.py, LongitudinalInverse), shared
 * by the controllers' C twins (inverse_controller.c, path_controller.c): Fx_des -> slip by the
 * Fx(W, slip) block, the filter of Eq. (17) on that slip, and the inverse of the first-order
 * tau -> slip block at the wheel's load, tau = (slip_f + T slip_f') / K; the same arithmetic in the
 * same order as the Python law, so that the twins give its results bit for bit (compiled with
 * -ffp-contract=off). Included once per twin: its functions are static. */
#ifndef INVERSE_LAW_H
#define INVERSE_LAW_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { OK = 0, ERROR = 3 };

typedef struct {
    int n_loads, n_torques, degree;
    double wn, step;                /* the filter's frequency [rad/s], the step it is discretised for [s] */
    double ad[4], bd[2];            /* the filter discretised for that step */
    double *inverse;                /* 1/W of the table's loads [1/N], decreasing */
    double *negated_inverse;        /* -1/W, increasing (the Python twin bisects it) */
    double *torques;                /* the table's torques [N.m], increasing */
    double *settled, *log_t;        /* per load: settled slip K tau, log T [log s] (n_loads x n_torques) */
    double *coefficients;           /* (degree + 1) x 3: c_k(W) = row[0] + row[1] W + row[2] W^2 */
    double *filter;                 /* per wheel: slip_f, slip_f' [1/s] */
    double *row, *row_t;            /* scratch: one interpolated row of each table */
    char *message;                  /* where errors are written (the twin's, 256 bytes) */
} Law;

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

/* The tables' lightest load [N]: a wheel under it is read there (LongitudinalInverse's light-load rule). */
static double lightest_load(const Law *c) { return 1.0 / c->inverse[0]; }

/* _slip_for_force: the slip at which the Fx(W, slip) model gives ``force`` (the quadratic's root
 * nearest the linear solution; a force beyond its extremum: the extremum's slip). */
static int slip_for_force(Law *c, double load, double force, double *slip) {
    double k[3] = {0.0, 0.0, 0.0}, lightest = lightest_load(c);
    if (load > 0 && load < lightest) load = lightest; /* a light wheel: the model at the lightest load */
    for (int i = 0; i <= c->degree && i < 3; i++) {
        const double *row = c->coefficients + 3 * i;
        k[i] = row[0] + row[1] * load + row[2] * load * load;
    }
    double linear = (force - k[0]) / k[1];
    if (c->degree == 1) { *slip = linear; return OK; }
    double discriminant = k[1] * k[1] - 4.0 * k[2] * (k[0] - force);
    if (k[2] == 0) { *slip = linear; return OK; }
    if (discriminant < 0) { *slip = -k[1] / (2.0 * k[2]); return OK; }
    double root = sqrt(discriminant);
    double plus = (-k[1] + root) / (2.0 * k[2]), minus = (-k[1] - root) / (2.0 * k[2]);
    *slip = fabs(plus - linear) <= fabs(minus - linear) ? plus : minus;
    return OK;
}

/* _rows: the settled-slip and log T rows at ``load``, interpolated in 1/W. */
static int rows_at(Law *c, double load) {
    if (!(load > 0)) {
        snprintf(c->message, 256, "loads = %.15g N: expected > 0", load);
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
static double torque_for(const Law *c, double slip) {
    const double *row = c->row, *torques = c->torques;
    int j = clamp(bisect_left(row, c->n_torques, slip), 1, c->n_torques - 1);
    return torques[j - 1] + (slip - row[j - 1]) * (torques[j] - torques[j - 1]) / (row[j] - row[j - 1]);
}

/* _time_constant: T [s] at ``torque``, linear in T between the table's torques, held beyond. */
static double time_constant(const Law *c, double torque) {
    const double *torques = c->torques;
    int m = c->n_torques;
    if (torque <= torques[0]) return exp(c->row_t[0]);
    if (torque >= torques[m - 1]) return exp(c->row_t[m - 1]);
    int j = bisect_right(torques, m, torque);
    double low = exp(c->row_t[j - 1]), high = exp(c->row_t[j]);
    return low + (torque - torques[j - 1]) * (high - low) / (torques[j] - torques[j - 1]);
}

/* A wheel under this load [N] or less is off the ground: no torque, its filter at rest
 * (LongitudinalInverse.NO_LOAD); between it and the tables' lightest load the torque for its target
 * slip is read at the lightest load and scaled by W / W_lightest. */
#define LAW_NO_LOAD 1.0

/* The torque of wheel ``i`` for ``force`` at ``load``; ``advance``: the filter moves on by a
 * step whose discretisation is ad, bd (else it starts settled at the target slip). As
 * LongitudinalInverse.torques for one wheel. */
static int law_torque(Law *c, int i, double load, double force, int advance, const double *ad, const double *bd,
                      double *torque) {
    double target, slip, rate;
    if (load > 0 && load <= LAW_NO_LOAD) {
        c->filter[2 * i] = 0.0;
        c->filter[2 * i + 1] = 0.0;
        *torque = 0.0;
        return OK;
    }
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
    double share = 1.0, lightest = lightest_load(c), table_load = load;
    if (load > 0 && load < lightest) { /* a light wheel: the torque read at the lightest load, scaled */
        share = load / lightest;
        table_load = lightest;
    }
    if (rows_at(c, table_load) != OK) return ERROR;
    double constant = time_constant(c, torque_for(c, slip));
    *torque = share * torque_for(c, slip + constant * rate);
    return OK;
}

/* A twin's communication step h [s] against the step it was made for: at most that (a shorter
 * last step is fine); ERROR with the message in ``message`` (256 bytes) otherwise. */
static int law_step_allowed(char *message, double h, double step) {
    if (0 < h && h <= step * (1 + 1e-9)) return OK;
    snprintf(message, 256, "communication step %.15g s: expected at most its step = %.15g s (a shorter last step is fine)",
             h, step);
    return ERROR;
}

/* The filter's discretisation for a step of h [s] (the law's own unless h differs from it). */
static void law_discretisation(const Law *c, int advance, double h, double *ad, double *bd) {
    memcpy(ad, c->ad, 4 * sizeof *ad);
    memcpy(bd, c->bd, 2 * sizeof *bd);
    if (advance && fabs(h - c->step) > 1e-12) discretise(c->wn, h, ad, bd);
}

static double *law_copy(const double *values, size_t n) {
    double *copy = malloc((n ? n : 1) * sizeof *copy);
    if (copy && n) memcpy(copy, values, n * sizeof *copy);
    return copy;
}

static void law_free(Law *c) {
    double *arrays[] = {c->inverse, c->negated_inverse, c->torques, c->settled, c->log_t, c->coefficients,
                        c->filter, c->row, c->row_t};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++) free(arrays[k]);
}

/* The law over tables of n_loads loads x n_torques torques (both >= 2), an Fx model of degree 1
 * or 2, for ``wheels`` wheels with their filter state (slip_f, slip_f' each); arrays copied.
 * -1 for bad sizes or out of memory (law_free frees what was made). */
static int law_init(Law *c, int wheels, int n_loads, int n_torques, int degree, double wn, double step,
                    const double *inverse, const double *torques, const double *settled, const double *log_t,
                    const double *coefficients, const double *filter, char *message) {
    memset(c, 0, sizeof *c);
    if (wheels < 1 || n_loads < 2 || n_torques < 2 || degree < 1 || degree > 2) return -1;
    size_t n = (size_t)n_loads, m = (size_t)n_torques, w = (size_t)wheels;
    c->n_loads = n_loads; c->n_torques = n_torques; c->degree = degree; c->wn = wn; c->step = step;
    c->message = message;
    c->inverse = law_copy(inverse, n);
    c->negated_inverse = malloc(n * sizeof(double));
    c->torques = law_copy(torques, m);
    c->settled = law_copy(settled, n * m);
    c->log_t = law_copy(log_t, n * m);
    c->coefficients = law_copy(coefficients, 3 * (size_t)(degree + 1));
    c->filter = law_copy(filter, 2 * w);
    c->row = calloc(m, sizeof(double));
    c->row_t = calloc(m, sizeof(double));
    if (!c->inverse || !c->negated_inverse || !c->torques || !c->settled || !c->log_t || !c->coefficients
        || !c->filter || !c->row || !c->row_t)
        return -1;
    for (size_t i = 0; i < n; i++) c->negated_inverse[i] = -c->inverse[i];
    discretise(wn, step, c->ad, c->bd);
    return 0;
}

#endif
