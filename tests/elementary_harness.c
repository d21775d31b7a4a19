/* The FMUs' elementary functions (fmubuild/runtime/elementary.c) and the C library's, applied to
 * arrays, for tests/test_elementary.py: which = 0 exp, 1 log, 2 pow, 3 sin, 4 cos, 5 tan, 6 asin,
 * 7 acos, 8 atan, 9 atan2 (y, x), 10 tanh. */
#include <math.h>
#include "elementary.h"

typedef double (*Unary)(double);
typedef double (*Binary)(double, double);

static const Unary OURS[] = {rcm_exp, rcm_log, 0, rcm_sin, rcm_cos, rcm_tan, rcm_asin, rcm_acos, rcm_atan, 0, rcm_tanh};
static const Unary LIBM[] = {exp, log, 0, sin, cos, tan, asin, acos, atan, 0, tanh};

/* ours != 0: this library's functions, else the C library's */
void apply(int which, int ours, long n, const double *x, const double *y, double *out) {
    if (which == 2 || which == 9) {
        Binary f = which == 2 ? (ours ? rcm_pow : pow) : (ours ? rcm_atan2 : atan2);
        for (long i = 0; i < n; i++) out[i] = f(x[i], y[i]);
        return;
    }
    Unary f = ours ? OURS[which] : LIBM[which];
    for (long i = 0; i < n; i++) out[i] = f(x[i]);
}
