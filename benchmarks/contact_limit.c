/* The arithmetic limit of one wheel's contact evaluation (issue 49): Fx, Fz, Tx of a rigid wheel
 * at sinkage h and slip, Eqs. (1)-(13) as the FMUs' `contactForces` integrates them (Gauss-Legendre
 * in s = u^2 on each side of thetaM, the rear normal stress taken from the front node's, no grousers,
 * ruts or slip angle), computed two ways:
 *
 *  - contact_scalar: node by node, the C library's sin, cos and exp (gcc merges them into sincos),
 *    the shape of CasADi's generated code;
 *  - contact_vector: fmubuild/runtime/contact.h's rc_contact_forces, what the FMUs call now: stage
 *    by stage over all nodes with polynomial sine, cosine, exp and log that the compiler vectorises
 *    (their limits are stated there).
 *
 * Parameters p[]: r, b [m], kc [N/m^(n+1)], kphi [N/m^(n+2)], n [1], c [Pa], phi [rad], kx [m],
 * a0, a1, lambda [1]. u[], w[]: Gauss-Legendre nodes and weights on [0, 1], `nodes` of them
 * (at most RC_CONTACT_MAX_NODES). out[]: Fx [N], Fz [N], Tx [N m].
 *
 * Timed by benchmarks/bench_contact_limit.py. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <time.h>

#include "contact.h"

enum { R, B, KC, KPHI, N, C, PHI, KX, A0, A1, LAMBDA };

static double pressure(const double *p, double depth) {
    double scale = p[KC] / p[B] + p[KPHI];
    return p[N] == 1.0 ? scale * p[R] * depth : scale * pow(p[R] * depth, p[N]);
}

static double shear(double strength, double j, double kx) {
    return strength * (j >= 0 ? 1 - exp(-j / kx) : exp(j / kx) - 1);
}

void contact_scalar(const double *p, double h, double slip, const double *u, const double *w, int nodes,
                    double *out) {
    double thetaF = acos(1 - h / p[R]), thetaR = -acos(1 - p[LAMBDA] * h / p[R]);
    double thetaM = (p[A0] + p[A1] * slip) * thetaF;
    double dFront = thetaF - thetaM, dRear = thetaM - thetaR;
    double cosF = cos(thetaF), sinF = sin(thetaF), tanPhi = tan(p[PHI]);
    double fx = 0, fz = 0, tx = 0;
    for (int i = 0; i < nodes; i++) {
        double s = u[i] * u[i], ds = 2 * u[i] * w[i];
        double pieces[2][2] = {{thetaF - dFront * s, dFront}, {thetaR + dRear * s, dRear}};
        double sigma = 0;
        for (int k = 0; k < 2; k++) {
            double theta = pieces[k][0], weight = ds * pieces[k][1];
            double cosT = cos(theta), sinT = sin(theta);
            if (k == 0)
                sigma = pressure(p, fmax(cosT - cosF, 0.0));
            double j = p[R] * (thetaF - theta - (1 - slip) * (sinF - sinT));
            double tau = shear(p[C] + sigma * tanPhi, j, p[KX]);
            fz += weight * (sigma * cosT + tau * sinT);
            fx += weight * (tau * cosT - sigma * sinT);
            tx += weight * tau;
        }
    }
    out[0] = p[R] * p[B] * fx;
    out[1] = p[R] * p[B] * fz;
    out[2] = p[R] * p[R] * p[B] * tx;
}

void contact_vector(const double *p, double h, double slip, const double *u, const double *w, int nodes,
                    double *out) {
    double thetaF = acos(1 - h / p[R]), thetaR = -acos(1 - p[LAMBDA] * h / p[R]);
    RcContact contact = {p[C], tan(p[PHI]), p[KC], p[KPHI], p[KX], p[A0], p[A1], p[N], p[N] == 1.0, p[R], p[B],
                         p[R], 1.0, 1.0, 0.0};
    rc_contact_forces(&contact, thetaF, thetaR, slip, nodes, u, w, 0, out);
}

typedef void (*contact_fn)(const double *, double, double, const double *, const double *, int, double *);

/* Seconds per evaluation of `which` (0 scalar, 1 vector) over `cases` (h, slip) pairs, each
 * evaluated `repeat` times; the sum of the forces in *check (so that nothing is optimised away). */
double time_contact(int which, const double *p, const double *h, const double *slip, int cases, const double *u,
                    const double *w, int nodes, int repeat, double *check) {
    contact_fn fn = which ? contact_vector : contact_scalar;
    struct timespec start, end;
    double out[3], sum = 0;
    clock_gettime(CLOCK_MONOTONIC, &start);
    for (int k = 0; k < repeat; k++)
        for (int i = 0; i < cases; i++) {
            fn(p, h[i], slip[i], u, w, nodes, out);
            sum += out[0] + out[1] + out[2];
        }
    clock_gettime(CLOCK_MONOTONIC, &end);
    *check = sum;
    return ((end.tv_sec - start.tv_sec) + 1e-9 * (end.tv_nsec - start.tv_nsec)) / ((double)repeat * cases);
}
