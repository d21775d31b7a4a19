/* The height map's law in C (terramechanics/terrain.py: HeightMap.height, HeightMap.gradient, the
 * cubic B-spline of its grid), for the C twins of the ground participant (jobs/ground_block.c) and
 * of the controller that feeds the map's pull forward (control/path_controller.c): the same
 * arithmetic in the same order, so that a twin gives its Python block's outputs bit for bit
 * (compiled with -ffp-contract=off).
 *
 * A point is clamped to the grid; the four cubic B-splines nonzero there along each axis come from
 * de Boor's recursion; the height and its derivatives are the sums over the 4 x 4 coefficients,
 * row by row; outside the grid the gradient is 0 (the edge's height continues flat). */
#ifndef ROVER_COSIM_HEIGHT_MAP_H
#define ROVER_COSIM_HEIGHT_MAP_H

#include <stdlib.h>
#include <string.h>

#include "grid_search.h"

typedef struct {
    int n_knots_x, n_knots_y;   /* knots along x and y (>= 8 each) */
    double *knots_x, *knots_y;
    double *coefficients;       /* c[(row along y) * (n_knots_x - 4) + column along x] */
    double x0, x1, y0, y1;      /* the grid's extent [m] */
} HeightSpline;

/* terrain._interval: l with knots[l] <= u < knots[l + 1], clipped to 3 .. n - 5. */
static int height_interval(const double *knots, int n, double u) {
    int l = grid_bisect_right(knots, n, u) - 1;
    return l < 3 ? 3 : l > n - 5 ? n - 5 : l;
}

/* terrain._cubic_basis: the four cubic B-splines nonzero at u (indices l - 3 .. l) and their slopes. */
static void height_basis(const double *knots, int n, double u, double *basis, double *slopes) {
    int l = height_interval(knots, n, u);
    double previous[4] = {1.0, 0.0, 0.0, 0.0}, current[4], quadratic[3] = {0.0, 0.0, 0.0};
    for (int degree = 1; degree <= 3; degree++) {
        for (int r = 0; r <= degree; r++) {
            int j = l - degree + r;
            double term = 0.0;
            if (r > 0) term = term + (u - knots[j]) / (knots[j + degree] - knots[j]) * previous[r - 1];
            if (r < degree)
                term = term + (knots[j + degree + 1] - u) / (knots[j + degree + 1] - knots[j + 1]) * previous[r];
            current[r] = term;
        }
        for (int r = 0; r <= degree; r++) previous[r] = current[r];
        if (degree == 2) for (int r = 0; r < 3; r++) quadratic[r] = current[r];
    }
    for (int r = 0; r < 4; r++) {
        int j = l - 3 + r;
        double slope = 0.0;
        if (r > 0) slope = slope + 3.0 * quadratic[r - 1] / (knots[j + 3] - knots[j]);
        if (r < 3) slope = slope - 3.0 * quadratic[r] / (knots[j + 4] - knots[j + 1]);
        basis[r] = previous[r];
        slopes[r] = slope;
    }
}

/* HeightMap.height and .gradient at (x, y) [m]: h [m], dh/dx, dh/dy [1]. */
static void height_at(const HeightSpline *s, double x, double y, double *h, double *dhdx, double *dhdy) {
    double cx = grid_clip(x, s->x0, s->x1), cy = grid_clip(y, s->y0, s->y1);
    double inside = (cx == x && cy == y) ? 1.0 : 0.0;
    double by[4], dby[4], bx[4], dbx[4];
    height_basis(s->knots_y, s->n_knots_y, cy, by, dby);
    height_basis(s->knots_x, s->n_knots_x, cx, bx, dbx);
    int ly = height_interval(s->knots_y, s->n_knots_y, cy) - 3, lx = height_interval(s->knots_x, s->n_knots_x, cx) - 3;
    int columns = s->n_knots_x - 4;
    double value = 0.0, along_x = 0.0, along_y = 0.0;
    for (int a = 0; a < 4; a++) {
        double row = 0.0, row_dx = 0.0;
        for (int b = 0; b < 4; b++) {
            double c = s->coefficients[(size_t)(ly + a) * (size_t)columns + (size_t)(lx + b)];
            row = row + c * bx[b];
            row_dx = row_dx + c * dbx[b];
        }
        value = value + by[a] * row;
        along_x = along_x + by[a] * row_dx;
        along_y = along_y + dby[a] * row;
    }
    *h = value;
    *dhdx = along_x * inside;
    *dhdy = along_y * inside;
}

/* A copy of the spline (the arrays copied); 0 ok, -1 bad sizes or out of memory. */
static int height_spline_init(HeightSpline *s, int n_knots_x, const double *knots_x, int n_knots_y,
                              const double *knots_y, const double *coefficients, const double *extent) {
    memset(s, 0, sizeof *s);
    if (n_knots_x < 8 || n_knots_y < 8) return -1;
    size_t n = (size_t)(n_knots_x - 4) * (size_t)(n_knots_y - 4);
    s->n_knots_x = n_knots_x;
    s->n_knots_y = n_knots_y;
    s->knots_x = malloc((size_t)n_knots_x * sizeof(double));
    s->knots_y = malloc((size_t)n_knots_y * sizeof(double));
    s->coefficients = malloc(n * sizeof(double));
    if (!s->knots_x || !s->knots_y || !s->coefficients) return -1;
    memcpy(s->knots_x, knots_x, (size_t)n_knots_x * sizeof(double));
    memcpy(s->knots_y, knots_y, (size_t)n_knots_y * sizeof(double));
    memcpy(s->coefficients, coefficients, n * sizeof(double));
    s->x0 = extent[0];
    s->x1 = extent[1];
    s->y0 = extent[2];
    s->y1 = extent[3];
    return 0;
}

static void height_spline_free(HeightSpline *s) {
    free(s->knots_x);
    free(s->knots_y);
    free(s->coefficients);
    memset(s, 0, sizeof *s);
}

#endif
