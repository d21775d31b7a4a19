/* Rosenbrock 2(3) (Shampine & Reichelt 1997), see ode23s.h. */
#include <math.h>
#include <stdio.h>
#include <stddef.h>
#include "ode23s.h"

#define D_GAMMA 0.29289321881345248  /* 1 / (2 + sqrt(2)) */
#define E32 7.4142135623730951        /* 6 + sqrt(2) */

int ode23s_alloc(Ode23s *s, int n, void *(*alloc)(size_t, size_t)) {
    size_t m = n > 0 ? (size_t)n : 1;
    s->n = n;
    s->J = alloc(m * m, sizeof(double));
    s->W = alloc(m * m, sizeof(double));
    s->T = alloc(m, sizeof(double));
    s->F0 = alloc(m, sizeof(double));
    s->F1 = alloc(m, sizeof(double));
    s->F2 = alloc(m, sizeof(double));
    s->k1 = alloc(m, sizeof(double));
    s->k2 = alloc(m, sizeof(double));
    s->k3 = alloc(m, sizeof(double));
    s->xn = alloc(m, sizeof(double));
    s->tmp = alloc(m, sizeof(double));
    s->pivot = alloc(m, sizeof(int));
    s->h = 0.0;
    s->h_entry = 0.0;
    s->f0_valid = 0;
    s->jac_valid = s->jac_current = s->jac_age = 0;
    s->w_valid = 0;
    s->w_h = 0.0;
    s->jacobian_max_age = 100;
    s->steps = s->rejected = s->jacobians = s->rhs_calls = 0;
    return (s->J && s->W && s->T && s->F0 && s->F1 && s->F2 && s->k1 && s->k2 && s->k3 && s->xn &&
            s->tmp && s->pivot) ? 0 : -1;
}

void ode23s_free(Ode23s *s, void (*release)(void *)) {
    double **arrays[] = {&s->J, &s->W, &s->T, &s->F0, &s->F1, &s->F2, &s->k1, &s->k2, &s->k3, &s->xn, &s->tmp};
    for (size_t i = 0; i < sizeof(arrays) / sizeof(arrays[0]); i++) {
        if (*arrays[i]) release(*arrays[i]);
        *arrays[i] = NULL;
    }
    if (s->pivot) release(s->pivot);
    s->pivot = NULL;
}

/* LU factorisation with partial pivoting of the n x n column-major matrix A, in place. */
static int lu_factor(double *A, int n, int *pivot) {
    for (int k = 0; k < n; k++) {
        int p = k;
        double big = fabs(A[k + k * n]);
        for (int i = k + 1; i < n; i++) {
            if (fabs(A[i + k * n]) > big) { big = fabs(A[i + k * n]); p = i; }
        }
        if (big == 0.0 || !isfinite(big)) return -1;
        pivot[k] = p;
        if (p != k) {
            for (int j = 0; j < n; j++) { double t = A[k + j * n]; A[k + j * n] = A[p + j * n]; A[p + j * n] = t; }
        }
        for (int i = k + 1; i < n; i++) {
            double l = A[i + k * n] / A[k + k * n];
            A[i + k * n] = l;
            for (int j = k + 1; j < n; j++) A[i + j * n] -= l * A[k + j * n];
        }
    }
    return 0;
}

static void lu_solve(const double *LU, int n, const int *pivot, double *b) {
    /* The row interchanges were applied to whole rows (multipliers included): apply them all
     * to b first, then solve L y = P b and U x = y. */
    for (int k = 0; k < n; k++) {
        if (pivot[k] != k) { double t = b[k]; b[k] = b[pivot[k]]; b[pivot[k]] = t; }
    }
    for (int k = 0; k < n; k++) {
        for (int i = k + 1; i < n; i++) b[i] -= LU[i + k * n] * b[k];
    }
    for (int k = n - 1; k >= 0; k--) {
        for (int j = k + 1; j < n; j++) b[k] -= LU[k + j * n] * b[j];
        b[k] /= LU[k + k * n];
    }
}

static int all_finite(const double *v, int n) {
    for (int i = 0; i < n; i++) if (!isfinite(v[i])) return 0;
    return 1;
}

int ode23s_integrate(Ode23s *s, double *t, double *x, double t_end, char *msg, size_t msg_len) {
    const int n = s->n;
    const double span = t_end - *t;
    if (n == 0 || span <= 0.0) { *t = t_end; return 0; }
    if (s->max_step > 0.0 && span / s->max_step > (double)s->max_steps) {
        snprintf(msg, msg_len, "a largest step of %.3g s would need more than %ld steps to reach t = %.17g",
                 s->max_step, s->max_steps, t_end);
        return -1;
    }
    const double h_min = 16.0 * 2.220446049250313e-16 * fmax(fabs(*t), fabs(t_end));
    double h_max = s->max_step > 0.0 ? fmin(s->max_step, span) : span;
    double h = s->h > 0.0 ? fmin(s->h, h_max) : fmin(h_max, 1e-3 * span + 0.0);
    if (s->h_entry > 0.0) h = fmin(h, s->h_entry); /* the transient at the last call's start */
    long attempts = 0;
    int first = 1;

    if (!s->f0_valid) {
        if (s->rhs(s->ctx, *t, x, s->F0) || !all_finite(s->F0, n)) {
            snprintf(msg, msg_len, "the derivatives are not finite at t = %.17g", *t);
            return -1;
        }
        s->rhs_calls++;
        s->f0_valid = 1;
    }
    if (s->h <= 0.0) {
        /* First step: from the size of the derivatives relative to the tolerance. */
        double norm = 0.0;
        for (int i = 0; i < n; i++) {
            double sc = s->atol + s->rtol * fabs(x[i]);
            norm = fmax(norm, fabs(s->F0[i]) / sc);
        }
        double guess = norm > 0.0 ? 0.8 * pow(s->rtol, 1.0 / 3.0) / norm * (s->atol / s->rtol + 1.0) : h_max;
        h = fmin(h_max, fmax(guess, 1e-6 * span));
    }

    while (*t < t_end) {
        if (!s->jac_valid || s->jac_age >= s->jacobian_max_age) {
            if (s->jacobian(s->ctx, *t, x, s->J, s->T) || !all_finite(s->J, n * n) || !all_finite(s->T, n)) {
                snprintf(msg, msg_len, "the Jacobian is not finite at t = %.17g", *t);
                return -1;
            }
            s->jacobians++;
            s->jac_valid = s->jac_current = 1;
            s->jac_age = 0;
            s->w_valid = 0;
        }
        double remaining = t_end - *t;
        double h_try = h;
        if (h >= remaining || remaining - h < h_min) {
            h = remaining;
        } else { /* equal steps to t_end, none longer than h */
            double k = ceil(remaining / h * (1.0 - 1e-9));
            h = k <= 1.0 ? remaining : remaining / k;
        }
        /* The last stage lands on t_end exactly: the model evaluated there is the one the
         * outputs after the step ask for. */
        const double t_new = (h == remaining) ? t_end : *t + h;
        if (++attempts > s->max_steps) {
            snprintf(msg, msg_len, "more than %ld steps between t = %.17g and %.17g (last step size %.3g s)",
                     s->max_steps, *t, t_end, h);
            return -1;
        }
        /* W = I - h d J, factored again only when h or J changed (steps of one size, one Jacobian:
         * the same factors, bit for bit) */
        if (!s->w_valid || s->w_h != h) {
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) s->W[i + j * n] = (i == j ? 1.0 : 0.0) - h * D_GAMMA * s->J[i + j * n];
            s->w_valid = lu_factor(s->W, n, s->pivot) == 0;
            s->w_h = h;
        }
        int ok = s->w_valid;
        double err = INFINITY;
        if (ok) {
            for (int i = 0; i < n; i++) s->k1[i] = s->F0[i] + h * D_GAMMA * s->T[i];
            lu_solve(s->W, n, s->pivot, s->k1);
            for (int i = 0; i < n; i++) s->tmp[i] = x[i] + 0.5 * h * s->k1[i];
            ok = s->rhs(s->ctx, *t + 0.5 * h, s->tmp, s->F1) == 0 && all_finite(s->F1, n);
            s->rhs_calls++;
        }
        if (ok) {
            for (int i = 0; i < n; i++) s->k2[i] = s->F1[i] - s->k1[i];
            lu_solve(s->W, n, s->pivot, s->k2);
            for (int i = 0; i < n; i++) { s->k2[i] += s->k1[i]; s->xn[i] = x[i] + h * s->k2[i]; }
            ok = s->rhs(s->ctx, t_new, s->xn, s->F2) == 0 && all_finite(s->F2, n);
            s->rhs_calls++;
        }
        if (ok) {
            for (int i = 0; i < n; i++)
                s->k3[i] = s->F2[i] - E32 * (s->k2[i] - s->F1[i]) - 2.0 * (s->k1[i] - s->F0[i]) + h * D_GAMMA * s->T[i];
            lu_solve(s->W, n, s->pivot, s->k3);
            err = 0.0;
            for (int i = 0; i < n; i++) {
                double e = h / 6.0 * (s->k1[i] - 2.0 * s->k2[i] + s->k3[i]);
                double sc = s->atol + s->rtol * fmax(fabs(x[i]), fabs(s->xn[i]));
                err = fmax(err, fabs(e) / sc);
            }
            if (!isfinite(err)) err = INFINITY;
        }
        if (err <= 1.0) {
            *t = t_new;
            for (int i = 0; i < n; i++) { x[i] = s->xn[i]; s->F0[i] = s->F2[i]; }
            s->steps++;
            double grow = err > 0.0 ? fmin(5.0, 0.8 * pow(err, -1.0 / 3.0)) : 5.0;
            /* A step shortened to land on t_end with a small error says little about the next one:
             * it keeps the proposal; one whose error asks for shorter steps proposes its own. */
            s->h = h < h_try && grow >= 1.0 ? fmax(h_try, h * grow) : h * grow;
            if (first) s->h_entry = s->h;
            first = 0;
            if (s->max_step > 0.0) s->h = fmin(s->h, s->max_step);
            h = fmin(s->h, h_max);
            s->jac_current = 0;
            s->jac_age++;
        } else {
            s->rejected++;
            double shrink = isfinite(err) ? fmax(0.1, 0.8 * pow(err, -1.0 / 3.0)) : 0.25;
            h *= shrink;
            s->h = h;
            if (h < h_min) {
                snprintf(msg, msg_len, "step size %.3g s below the minimum at t = %.17g (error estimate %.3g)",
                         h, *t, err);
                return -1;
            }
            if (!s->jac_current) s->jac_valid = 0;  /* re-linearise at the current point */
        }
    }
    return 0;
}
