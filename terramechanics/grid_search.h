/* What the maps' laws in C share (height_map.h, soil_map.h): np.clip of one value and
 * np.searchsorted(..., side="right"), the way numpy computes them. */
#ifndef ROVER_COSIM_GRID_SEARCH_H
#define ROVER_COSIM_GRID_SEARCH_H

/* np.clip(value, low, high) of one value: minimum(maximum(value, low), high), NaN kept. */
static double grid_clip(double value, double low, double high) {
    value = value != value ? value : (value > low ? value : low);
    return value != value ? value : (value < high ? value : high);
}

/* np.searchsorted(a, x, side="right"): the first index whose value is > x (n for NaN). */
static int grid_bisect_right(const double *a, int n, double x) {
    int low = 0, high = n;
    while (low < high) {
        int mid = (low + high) / 2;
        if (x < a[mid]) high = mid; else low = mid + 1;
    }
    return low;
}

#endif
