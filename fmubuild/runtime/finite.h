/* rover-cosim FMU runtime: whether an array's values are all finite (instance.c checks a model's
 * outputs and derivatives with it at every evaluation a host sees). */
#ifndef ROVER_COSIM_FINITE_H
#define ROVER_COSIM_FINITE_H

/* 1 when every one of the n values is finite, else 0. v - v is 0 for a finite v and NaN for an
 * infinite or NaN one, and a NaN stays in a sum, which never overflows (it only adds zeros): four
 * independent sums without a branch per value, which the compiler turns into vector code without
 * reassociating anything (each sum keeps its order). A leg-wheel rover checks its 2033 outputs
 * every step; a test and a branch per value cost 3.5 % of its instructions (callgrind). */
static inline int rc_all_finite(const double *v, int n) {
    double sum[4] = {0.0, 0.0, 0.0, 0.0};
    int i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; k++) sum[k] += v[i + k] - v[i + k];
    for (; i < n; i++) sum[0] += v[i] - v[i];
    return (sum[0] + sum[1]) + (sum[2] + sum[3]) == 0.0;
}

#endif
