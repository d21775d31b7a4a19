/* The wheel contact's quadrature as vector code: Fx, Fz and Tx of RoverTerramechanics.Functions.
 * contactForces (with grousers, slip-sinkage, a rut, at a slip angle or not),
 * computed stage by stage over all nodes (angles, every sine and cosine, the normal stresses, every
 * exp, the sums) with sine, cosine, exp and log as polynomials in loops without calls or branches,
 * which the compiler turns into vector code. The generated model code calls it in place of
 * CasADi's node-by-node code of contactResidual (fmubuild/contact.py; CasADi's code stays for
 * arguments out of its range); the derivatives stay CasADi's.
 *
 * With the lateral terms of a wheel at a slip angle (lateralShear and the sidewall's pile).
 * The same quadrature and the same order of every operation and sum as contactForces (front and
 * rear node of each pair in turn); only sine, cosine, exp and the power law's (r depth)^n =
 * exp(n log(r depth)) (n != 1) are computed otherwise than by the C library. Their limits:
 * sine and cosine reduce x by the nearest multiple k of pi/2 (Cody-Waite, two parts of pi/2) and
 * take Taylor polynomials to degree 17 and 18 on |r| <= pi/4, for |x| < 3 pi / 4 (the patch's
 * angles lie in [-pi/2, pi/2]); exp reduces by the nearest multiple of ln 2 and takes a Taylor
 * polynomial to degree 13 (Estrin's scheme), for x <= 0 (the shear law's exp(-|j|/kx); below -700
 * it returns exp(-700), under 1e-304); log of a normal number x = m 2^e, sqrt(1/2) <= m < sqrt 2,
 * is e ln 2 + 2 atanh((m - 1)/(m + 1)) by its series to the 21st power. Measured against the
 * C library's code of contactForces (tests/test_contact_kernel.py, the library's soils, sinkages
 * 1 um - 1.2 r, slips -1...1, slip angles, grousers, slip-sinkage, ruts): forces within 1.5e-14 of
 * the largest force from 1 mm of sinkage on, 3.3e-13 below (where cos(theta) - cos(thetaF) cancels
 * and either code's rounding of a cosine shows); benchmarks/bench_contact_limit.py times it.
 *
 * Header only, every function static (two FMUs compiled into one program share no name), no call
 * of the C library: the --elementary choice does not touch it, and it gives the same bits on every
 * host that rounds each operation as x86-64 does (no fused multiply-add: the zig builds pass
 * -ffp-contract=off). GCC compiles it at -O3 without trapping math (the FMUs never enable traps):
 * what its vectoriser needs; the region ends with the header. */
#ifndef ROVER_COSIM_CONTACT_H
#define ROVER_COSIM_CONTACT_H

#include <stdint.h>

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize ("O3", "no-trapping-math")
/* gcc cannot see that a stage fills the nodes the next one reads (their count is a run-time value) */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

/* Nodes per piece the kernel takes (contactForces' nNodes) */
#define RC_CONTACT_MAX_NODES 32

/* 1/k! */
static const double RC_INV_FACT[19] = {
    1.0, 1.0, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 720, 1.0 / 5040, 1.0 / 40320, 1.0 / 362880,
    1.0 / 3628800, 1.0 / 39916800, 1.0 / 479001600, 1.0 / 6227020800.0, 1.0 / 87178291200.0,
    1.0 / 1307674368000.0, 1.0 / 20922789888000.0, 1.0 / 355687428096000.0, 1.0 / 6402373705728000.0};
static const double RC_SHIFT = 0x1.8p52;                 /* adding it rounds to an integer */
static const double RC_TWO_OVER_PI = 0x1.45f306dc9c883p-1;
static const double RC_PIO2_HI = 0x1.921fb54400000p0;    /* pi/2 in two parts: k * RC_PIO2_HI exact */
static const double RC_PIO2_LO = 0x1.0b4611a626331p-34;
static const double RC_INV_LN2 = 0x1.71547652b82fep0;
static const double RC_LN2_HI = 0x1.62e42fee00000p-1;    /* ln 2 in two parts */
static const double RC_LN2_LO = 0x1.a39ef35793c76p-33;

/* sin and cos of x[0..count), |x| < 3 pi / 4 */
static void rc_sincos_array(const double *x, double *sin_out, double *cos_out, int count) {
    for (int i = 0; i < count; i++) {
        double k = (x[i] * RC_TWO_OVER_PI + RC_SHIFT) - RC_SHIFT;  /* -1, 0 or 1 */
        double r = (x[i] - k * RC_PIO2_HI) - k * RC_PIO2_LO, r2 = r * r;
        double s = RC_INV_FACT[17];
        for (int m = 15; m >= 1; m -= 2)
            s = s * r2 + (m / 2 % 2 ? -RC_INV_FACT[m] : RC_INV_FACT[m]);
        s *= r;
        double c = RC_INV_FACT[18];
        for (int m = 16; m >= 0; m -= 2)
            c = c * r2 + (m / 2 % 2 ? -RC_INV_FACT[m] : RC_INV_FACT[m]);
        double keep = 1 - (k < 0 ? -k : k);  /* the quadrant: products with 0 and +-1 are exact */
        sin_out[i] = keep * s + k * c;
        cos_out[i] = keep * c - k * s;
    }
}

/* exp of x[0..count), x <= 0 */
static void rc_exp_array(const double *x, double *out, int count) {
    for (int i = 0; i < count; i++) {
        double v = x[i] > -700.0 ? x[i] : -700.0;
        double shifted = v * RC_INV_LN2 + RC_SHIFT, k = shifted - RC_SHIFT;
        double r = (v - k * RC_LN2_HI) - k * RC_LN2_LO;
        double r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
        const double *f = RC_INV_FACT;
        double q = ((f[0] + f[1] * r) + (f[2] + f[3] * r) * r2) + ((f[4] + f[5] * r) + (f[6] + f[7] * r) * r2) * r4
                   + (((f[8] + f[9] * r) + (f[10] + f[11] * r) * r2) + (f[12] + f[13] * r) * r4) * r8;
        union { double d; uint64_t bits; } in, scale;
        in.d = shifted;                        /* its low bits hold k + 2^51 */
        scale.bits = (in.bits + 1023) << 52;  /* 2^k */
        out[i] = q * scale.d;
    }
}

/* log of x[0..count), each a positive normal number; the exponent field read as a double through
 * the bits of 2^52 + e (SSE2 and AVX2 have no 64-bit integer-to-double conversion) */
static void rc_log_array(const double *x, double *out, int count) {
    for (int i = 0; i < count; i++) {
        union { double d; uint64_t bits; } in, mantissa, field;
        in.d = x[i];
        mantissa.bits = (in.bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;  /* m in [1, 2) */
        field.bits = (in.bits >> 52) | 0x4330000000000000ULL;                        /* 2^52 + e + 1023 */
        double e = field.d - 0x1p52 - 1023;
        double big = mantissa.d > 0x1.6a09e667f3bcdp0 ? 1.0 : 0.0;                  /* m > sqrt 2 */
        double m = mantissa.d * (1 - 0.5 * big);
        e += big;
        double f = (m - 1) / (m + 1), f2 = f * f;
        double series = 1 + f2 * (1.0 / 3 + f2 * (1.0 / 5 + f2 * (1.0 / 7 + f2 * (1.0 / 9 + f2 * (1.0 / 11 + f2 * (
                        1.0 / 13 + f2 * (1.0 / 15 + f2 * (1.0 / 17 + f2 * (1.0 / 19 + f2 / 21)))))))));
        out[i] = e * RC_LN2_HI + (e * RC_LN2_LO + 2 * f * series);
    }
}

/* The lateral terms of contactForces at a slip angle (Ishigami et al. 2007): tan of the slip angle,
 * the lateral shear modulus ky [m] at it, Hegedus' D1 and D2, the soil's density rho [kg/m^3] and
 * gravity [m/s^2]; the sums sumFy [Pa] and sumPile [N/m] come back in it. */
typedef struct {
    double tanBeta, ky, d1, d2, rho, gravity;
    double sumFy, sumPile;
} RcLateral;

/* What contactForces computes once per call from the soil, the wheel, the slip and the slip angle. */
typedef struct {
    double c, tanPhi, kc, kphi, kx, a0, a1;  /* soil: c [Pa], tan(phi), kc [N/m^(n+1)], kphi [N/m^(n+2)],
                                                kx [m] at the slip angle, a0, a1 */
    double exponent;                         /* sinkage exponent at this slip: n + nSlip |slip| */
    int product;                             /* the power law as the product r depth (n = 1, no slip-sinkage) */
    double r, b;                             /* wheel radius and width [m] */
    double radius, scaleForce, ratio;        /* grousers: shear radius [m] and the shear's weights (r, 1, 1 without) */
    double rutOverR;                         /* depth of the rut under the wheel over r (0 without) */
} RcContact;

/* Fx, Fz, Tx [N, N, N m] (out[0..2]) of contactForces for `k` at the entry and exit angles thetaF =
 * acos(1 - h/r), thetaR = -acos(1 - lambda h/r) [rad] the caller computed (with its elementary
 * functions) for the clamped sinkage, at slip ratio `slip`; `nodes` (<= RC_CONTACT_MAX_NODES)
 * Gauss-Legendre nodes u and weights w on [0, 1]; `lateral`: NULL where contactForces skips the
 * lateral terms (tan beta = 0), else they are summed into it. */
static void rc_contact_forces(const RcContact *k, double thetaF, double thetaR, double slip, int nodes,
                              const double *u, const double *w, RcLateral *lateral, double *out) {
    double r = k->r, c = k->c, tanPhi = k->tanPhi, scaleForce = k->scaleForce;
    double thetaM = (k->a0 + k->a1 * slip) * thetaF;
    double dFront = thetaF - thetaM, dRear = thetaM - thetaR;
    double theta[2 * RC_CONTACT_MAX_NODES + 1], weight[2 * RC_CONTACT_MAX_NODES];
    double sinT[2 * RC_CONTACT_MAX_NODES + 1], cosT[2 * RC_CONTACT_MAX_NODES + 1];
    double sigma[2 * RC_CONTACT_MAX_NODES], arg[2 * RC_CONTACT_MAX_NODES], ex[2 * RC_CONTACT_MAX_NODES];
    double j[2 * RC_CONTACT_MAX_NODES], base[RC_CONTACT_MAX_NODES], power[RC_CONTACT_MAX_NODES];
    double logs[RC_CONTACT_MAX_NODES];
    int count = 2 * nodes;
    for (int i = 0; i < nodes; i++) {  /* even: the front node of pair i, odd: the rear one */
        double s = u[i] * u[i], ds = 2 * u[i] * w[i];
        theta[2 * i] = thetaF - dFront * s;
        theta[2 * i + 1] = thetaR + dRear * s;
        weight[2 * i] = ds * dFront;
        weight[2 * i + 1] = ds * dRear;
    }
    theta[count] = thetaF;
    rc_sincos_array(theta, sinT, cosT, count + 1);
    double sinF = sinT[count], cosF = cosT[count], scale = k->kc / k->b + k->kphi;
    for (int i = 0; i < nodes; i++) {  /* Eq. (5) at the front node; Eq. (6)'s rear node has the same */
        double depth = cosT[2 * i] - cosF;
        base[i] = k->rutOverR + (depth > 0 ? depth : 0.0);
    }
    if (k->product) {
        for (int i = 0; i < nodes; i++)
            sigma[2 * i] = scale * (r * base[i]);
    } else {  /* r^n depth^n = exp(n log(r depth)); 0 where the depth is 0 */
        for (int i = 0; i < nodes; i++) {
            double rd = r * base[i];
            power[i] = rd > 0x1p-1000 ? rd : 0x1p-1000;
        }
        rc_log_array(power, logs, nodes);
        for (int i = 0; i < nodes; i++)
            logs[i] *= k->exponent;
        rc_exp_array(logs, power, nodes);
        for (int i = 0; i < nodes; i++)
            sigma[2 * i] = base[i] > 0 ? scale * power[i] : 0.0;
    }
    for (int i = 0; i < nodes; i++)
        sigma[2 * i + 1] = sigma[2 * i];
    for (int i = 0; i < count; i++) {  /* Eq. (10) at the shear radius and the argument of Eqs. (8)-(9)'s exp */
        j[i] = k->radius * (thetaF - theta[i] - (1 - slip) * (sinF - sinT[i]));
        arg[i] = (j[i] >= 0 ? -j[i] : j[i]) / k->kx;
    }
    rc_exp_array(arg, ex, count);
    double fx = 0, fz = 0, tx = 0;
    for (int i = 0; i < count; i++) {  /* Eqs. (11)-(13), in contactForces' order */
        double tau = (c + sigma[i] * tanPhi) * (j[i] >= 0 ? 1 - ex[i] : ex[i] - 1);
        fz = fz + weight[i] * (sigma[i] * cosT[i] + tau * scaleForce * sinT[i]);
        fx = fx + weight[i] * (tau * scaleForce * cosT[i] - sigma[i] * sinT[i]);
        tx = tx + weight[i] * (tau * scaleForce * k->ratio);
    }
    double b = k->b;
    out[0] = r * b * fx;
    out[1] = r * b * fz;
    out[2] = r * r * b * tx;
    if (!lateral)
        return;
    {   /* lateralShear and the sidewall's pile, in contactForces' order */
        double tanBeta = lateral->tanBeta, ky = lateral->ky, sumFy = 0, sumPile = 0;
        for (int i = 0; i < count; i++) {
            j[i] = r * (1 - slip) * (thetaF - theta[i]) * tanBeta;
            arg[i] = (j[i] >= 0 ? -j[i] : j[i]) / ky;
        }
        rc_exp_array(arg, ex, count);
        for (int i = 0; i < count; i++) {
            double tauY = (c + sigma[i] * tanPhi) * (j[i] >= 0 ? 1 - ex[i] : ex[i] - 1);
            double depth = r * (cosT[i] - cosF);
            depth = depth > 0 ? depth : 0.0;
            sumFy = sumFy + weight[i] * tauY;
            double pile = c * depth + lateral->d2 * lateral->rho * lateral->gravity * (depth * depth) / 2;
            sumPile = sumPile + weight[i] * lateral->d1 * pile * (r - depth * cosT[i]);
        }
        lateral->sumFy = sumFy;
        lateral->sumPile = sumPile;
    }
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#pragma GCC pop_options
#endif

#endif
