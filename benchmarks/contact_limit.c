/* The arithmetic limit of one wheel's contact evaluation (issue 49): Fx, Fz, Tx of a rigid wheel
 * at sinkage h and slip, Eqs. (1)-(13) as the FMUs' `contactForces` integrates them (Gauss-Legendre
 * in s = u^2 on each side of thetaM, the rear normal stress taken from the front node's, no grousers,
 * ruts or slip angle), written twice:
 *
 *  - contact_scalar: node by node, the C library's sin, cos and exp (gcc merges them into sincos),
 *    the shape of the FMUs' generated code;
 *  - contact_vector: stage by stage over arrays of all nodes (angles, then every sine and cosine,
 *    then the stresses, then every exp, then the sums), with sine, cosine, exp and log (the power
 *    law (r depth)^n = exp(n log(r depth)) where n is not 1) as polynomials
 *    in loops without calls or branches, which the compiler turns into vector code (SSE2 on any
 *    x86-64, AVX2 or AVX-512 where compiled for them).
 *
 * Elementary functions of contact_vector, and their stated limits (the benchmark measures the
 * error of the forces against contact_scalar): sine and cosine reduce x by the nearest multiple k
 * of pi/2 (Cody-Waite, two parts of pi/2) and take Taylor polynomials to degree 17 and 18 on
 * |r| <= pi/4, for |x| < 3 pi / 4 (the patch's angles lie in [-pi/2, pi/2]); exp reduces by the
 * nearest multiple of ln 2 and takes a Taylor polynomial to degree 13, for -700 <= x <= 0 (the
 * shear law's exp(-|j|/kx); below -700 it returns exp(-700), under 1e-304); log, see log_array.
 *
 * Parameters p[]: r, b [m], kc [N/m^(n+1)], kphi [N/m^(n+2)], n [1], c [Pa], phi [rad], kx [m],
 * a0, a1, lambda [1]. u[], w[]: Gauss-Legendre nodes and weights on [0, 1], `nodes` of them
 * (at most MAX_NODES). out[]: Fx [N], Fz [N], Tx [N m].
 *
 * Not part of the FMUs: a measurement of what they could reach (benchmarks/bench_contact_limit.py). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <time.h>

#define MAX_NODES 32
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

/* 1/k! for the Taylor polynomials */
static const double INV_FACT[19] = {
    1.0, 1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040, 1.0 / 40320, 1.0 / 362880,
    1.0 / 3628800, 1.0 / 39916800, 1.0 / 479001600, 1.0 / 6227020800.0, 1.0 / 87178291200.0,
    1.0 / 1307674368000.0, 1.0 / 20922789888000.0, 1.0 / 355687428096000.0, 1.0 / 6402373705728000.0};

static const double SHIFT = 0x1.8p52;                 /* adding it rounds to an integer */
static const double TWO_OVER_PI = 0x1.45f306dc9c883p-1;
static const double PIO2_HI = 0x1.921fb54400000p0;    /* pi/2 in two parts: k * PIO2_HI exact */
static const double PIO2_LO = 0x1.0b4611a626331p-34;
static const double INV_LN2 = 0x1.71547652b82fep0;
static const double LN2_HI = 0x1.62e42fee00000p-1;    /* ln 2 in two parts */
static const double LN2_LO = 0x1.a39ef35793c76p-33;

static void sincos_array(const double *x, double *sin_out, double *cos_out, int count) {
    for (int i = 0; i < count; i++) {
        double k = (x[i] * TWO_OVER_PI + SHIFT) - SHIFT;  /* -1, 0 or 1 for |x| < 3 pi / 4 */
        double r = (x[i] - k * PIO2_HI) - k * PIO2_LO, r2 = r * r;
        double s = INV_FACT[17];
        for (int m = 15; m >= 1; m -= 2)
            s = s * r2 + (m / 2 % 2 ? -INV_FACT[m] : INV_FACT[m]);
        s *= r;
        double c = INV_FACT[18];
        for (int m = 16; m >= 0; m -= 2)
            c = c * r2 + (m / 2 % 2 ? -INV_FACT[m] : INV_FACT[m]);
        /* the quadrant: multiplications by 0 and +-1 are exact */
        double keep = 1 - fabs(k);
        sin_out[i] = keep * s + k * c;
        cos_out[i] = keep * c - k * s;
    }
}

static void exp_array(const double *x, double *out, int count) {
    for (int i = 0; i < count; i++) {
        double v = x[i] > -700.0 ? x[i] : -700.0;
        double shifted = v * INV_LN2 + SHIFT, k = shifted - SHIFT;
        double r = (v - k * LN2_HI) - k * LN2_LO;
        double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;  /* Estrin's scheme: shorter chains than Horner's */
        double q = ((INV_FACT[0] + INV_FACT[1] * r) + (INV_FACT[2] + INV_FACT[3] * r) * r2)
                   + ((INV_FACT[4] + INV_FACT[5] * r) + (INV_FACT[6] + INV_FACT[7] * r) * r2) * r4
                   + (((INV_FACT[8] + INV_FACT[9] * r) + (INV_FACT[10] + INV_FACT[11] * r) * r2)
                      + (INV_FACT[12] + INV_FACT[13] * r) * r4) * r8;
        union { double d; uint64_t bits; } in, scale;
        in.d = shifted;                                  /* its low bits hold k + 2^51 */
        scale.bits = (in.bits + 1023) << 52;            /* 2^k */
        out[i] = q * scale.d;
    }
}

/* log x for x > 0 (normal numbers): x = m 2^e with sqrt(1/2) <= m < sqrt(2), log m = 2 atanh f,
 * f = (m - 1)/(m + 1), |f| <= 0.172, by its series to f^21; the exponent field read as a double
 * through the bits of 2^52 + e (no integer-to-double conversion, which SSE2 and AVX2 lack for
 * 64-bit integers). */
static void log_array(const double *x, double *out, int count) {
    for (int i = 0; i < count; i++) {
        union { double d; uint64_t bits; } in, mantissa, field;
        in.d = x[i];
        mantissa.bits = (in.bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;  /* in [1, 2) */
        field.bits = (in.bits >> 52) | 0x4330000000000000ULL;                        /* 2^52 + e + 1023 */
        double e = field.d - 0x1p52 - 1023;
        double m = mantissa.d;
        double big = m > 0x1.6a09e667f3bcdp0 ? 1.0 : 0.0;                         /* m >= sqrt 2 */
        m = m * (1 - 0.5 * big);
        e += big;
        double f = (m - 1) / (m + 1), f2 = f * f;
        double series = 1 + f2 * (1.0 / 3 + f2 * (1.0 / 5 + f2 * (1.0 / 7 + f2 * (1.0 / 9 + f2 * (1.0 / 11 + f2 * (
                        1.0 / 13 + f2 * (1.0 / 15 + f2 * (1.0 / 17 + f2 * (1.0 / 19 + f2 / 21)))))))));
        out[i] = e * LN2_HI + (e * LN2_LO + 2 * f * series);
    }
}

void contact_vector(const double *p, double h, double slip, const double *u, const double *w, int nodes,
                    double *out) {
    double thetaF = acos(1 - h / p[R]), thetaR = -acos(1 - p[LAMBDA] * h / p[R]);
    double thetaM = (p[A0] + p[A1] * slip) * thetaF;
    double dFront = thetaF - thetaM, dRear = thetaM - thetaR;
    double tanPhi = tan(p[PHI]), scale = p[KC] / p[B] + p[KPHI], kx = p[KX];
    double theta[2 * MAX_NODES + 1], weight[2 * MAX_NODES], sinT[2 * MAX_NODES + 1], cosT[2 * MAX_NODES + 1];
    double sigma[2 * MAX_NODES], arg[2 * MAX_NODES], ex[2 * MAX_NODES], tau[2 * MAX_NODES];
    int count = 2 * nodes;
    for (int i = 0; i < nodes; i++) {
        double s = u[i] * u[i], ds = 2 * u[i] * w[i];
        theta[i] = thetaF - dFront * s;
        theta[nodes + i] = thetaR + dRear * s;
        weight[i] = ds * dFront;
        weight[nodes + i] = ds * dRear;
    }
    theta[count] = thetaF;
    sincos_array(theta, sinT, cosT, count + 1);
    double sinF = sinT[count], cosF = cosT[count];
    for (int i = 0; i < nodes; i++) {
        double depth = cosT[i] - cosF;
        sigma[i] = scale * p[R] * (depth > 0 ? depth : 0.0);
    }
    if (p[N] != 1.0) {  /* (r depth)^n = exp(n log(r depth)), 0 where the depth is 0 */
        double base[MAX_NODES], power[MAX_NODES];
        for (int i = 0; i < nodes; i++) {
            double depth = p[R] * (cosT[i] - cosF);
            base[i] = depth > 0x1p-1000 ? depth : 0x1p-1000;
        }
        log_array(base, power, nodes);
        for (int i = 0; i < nodes; i++)
            power[i] *= p[N];
        exp_array(power, base, nodes);
        for (int i = 0; i < nodes; i++)
            sigma[i] = cosT[i] - cosF > 0 ? scale * base[i] : 0.0;
    }
    for (int i = 0; i < nodes; i++)
        sigma[nodes + i] = sigma[i];
    for (int i = 0; i < count; i++) {
        double j = p[R] * (thetaF - theta[i] - (1 - slip) * (sinF - sinT[i]));
        arg[i] = -fabs(j) / kx;
        tau[i] = j;
    }
    exp_array(arg, ex, count);
    double fx = 0, fz = 0, tx = 0;
    for (int i = 0; i < count; i++) {
        double mobilised = 1 - ex[i];
        double t = (p[C] + sigma[i] * tanPhi) * (tau[i] >= 0 ? mobilised : -mobilised);
        fz += weight[i] * (sigma[i] * cosT[i] + t * sinT[i]);
        fx += weight[i] * (t * cosT[i] - sigma[i] * sinT[i]);
        tx += weight[i] * t;
    }
    out[0] = p[R] * p[B] * fx;
    out[1] = p[R] * p[B] * fz;
    out[2] = p[R] * p[R] * p[B] * tx;
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
