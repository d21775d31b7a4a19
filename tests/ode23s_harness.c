/* Test harness of the FMUs' integrator (fmubuild/runtime/ode23s.c), compiled with it by
 * tests/test_integrator.py: a stiff scalar ODE x' = -lambda (x - u) whose input u is held over each
 * communication step and jumps at every communication point, as a wheel's spin under the torque a
 * controller sets every step. Its exact solution is known, so the error of every communication
 * point is too. */
#include <math.h>
#include <stdlib.h>

#include "ode23s.h"

typedef struct {
    double lambda, u;
} Problem;

static int rhs(void *ctx, double t, const double *x, double *xdot) {
    const Problem *p = ctx;
    (void)t;
    xdot[0] = -p->lambda * (x[0] - p->u);
    return 0;
}

static int jacobian(void *ctx, double t, const double *x, double *dfdx, double *dfdt) {
    const Problem *p = ctx;
    (void)t;
    (void)x;
    dfdx[0] = -p->lambda;
    dfdt[0] = 0.0;
    return 0;
}

/* The input of communication step k: 1 and jumps of `jump` around it. */
static double input(int k, double jump) { return 1.0 + jump * (sin(0.7 * k) + 0.5 * cos(1.9 * k)); }

/* Integrate `calls` communication steps, the input jumping by about `jump` at each, of `step` [s] at tolerance `rtol` (atol the same), from
 * x = 0. counts: accepted steps, rejected steps, Jacobians, derivative evaluations; worst: the
 * largest |x - exact| over the communication points, divided by atol + rtol |exact|; fewest: the
 * fewest accepted steps of a communication step after the first hundred (the start, where the step size
 * grows from its first guess), most: the most. Returns 0,
 * or -1 where the integrator failed. */
int run(double lambda, double jump, int calls, double step, double rtol, long counts[4], double *worst, long *fewest,
        long *most) {
    Ode23s s = {0};
    Problem p = {lambda, 0.0};
    if (ode23s_alloc(&s, 1, calloc) != 0) return -1;
    s.rhs = rhs;
    s.jacobian = jacobian;
    s.ctx = &p;
    s.rtol = rtol;
    s.atol = rtol;
    s.max_step = 0.0;
    s.max_steps = 1000000;
    double t = 0.0, x = 0.0, exact = 0.0;
    char message[256];
    *worst = 0.0;
    *fewest = 1L << 40;
    *most = 0;
    for (int k = 0; k < calls; k++) {
        p.u = input(k, jump);
        s.f0_valid = 0; /* the input changed: so did the derivative at the current point */
        long before = s.steps;
        if (ode23s_integrate(&s, &t, &x, (k + 1) * step, message, sizeof message) != 0) {
            ode23s_free(&s, free);
            return -1;
        }
        exact = p.u + (exact - p.u) * exp(-lambda * step);
        *worst = fmax(*worst, fabs(x - exact) / (rtol + rtol * fabs(exact)));
        if (k >= 100) {
            long taken = s.steps - before;
            if (taken < *fewest) *fewest = taken;
            if (taken > *most) *most = taken;
        }
    }
    counts[0] = s.steps;
    counts[1] = s.rejected;
    counts[2] = s.jacobians;
    counts[3] = s.rhs_calls;
    ode23s_free(&s, free);
    return 0;
}
