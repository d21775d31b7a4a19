/* The soil map's law in C (terramechanics/terrain.py: SoilMap.share, hub_positions), for the C
 * twins of the soil participant (jobs/soil_block.c) and of the controller that believes a soil
 * map (control/path_controller.c): the same arithmetic in the same order, so that a twin gives
 * its Python block's outputs bit for bit (compiled with -ffp-contract=off).
 *
 * The share [1] of the second soil at (x, y) [m]: the point clipped to the grid, the cell by
 * bisection, the bilinear blend of its four shares, clipped to [0, 1], and within SOIL_SNAP of 0
 * or 1 made 0 or 1. */
#ifndef ROVER_COSIM_SOIL_MAP_H
#define ROVER_COSIM_SOIL_MAP_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grid_search.h"

#define SOIL_SNAP 1e-12

typedef struct {
    int nx, ny;          /* grid points along x and y (>= 2 each) */
    double *x, *y;       /* strictly increasing [m] */
    double *share;       /* share[j * nx + i] at (x[i], y[j]) [1] */
} SoilGrid;

static int soil_cell(const double *axis, int n, double value) {
    int k = grid_bisect_right(axis, n, value) - 1;
    return k < 0 ? 0 : k > n - 2 ? n - 2 : k;
}

/* SoilMap.share at one point. */
static double soil_share(const SoilGrid *g, double x, double y) {
    double cx = grid_clip(x, g->x[0], g->x[g->nx - 1]), cy = grid_clip(y, g->y[0], g->y[g->ny - 1]);
    int i = soil_cell(g->x, g->nx, cx), j = soil_cell(g->y, g->ny, cy);
    double tx = (cx - g->x[i]) / (g->x[i + 1] - g->x[i]), ty = (cy - g->y[j]) / (g->y[j + 1] - g->y[j]);
    const double *low = g->share + (size_t)j * (size_t)g->nx, *high = low + g->nx;
    double share = (1.0 - ty) * ((1.0 - tx) * low[i] + tx * low[i + 1])
                   + ty * ((1.0 - tx) * high[i] + tx * high[i + 1]);
    share = grid_clip(share, 0.0, 1.0);
    return share < SOIL_SNAP ? 0.0 : share > 1.0 - SOIL_SNAP ? 1.0 : share;
}

/* SoilMap.hub_shares (hub_positions, then SoilMap.share): the shares under ``hubs`` hubs at (x_hub, y_hub) [m] in the
 * body frame, the body at (x, y) [m] heading yaw [rad]. */
static void soil_shares(const SoilGrid *g, double x, double y, double yaw, const double *x_hub, const double *y_hub,
                        int hubs, double *shares) {
    double cs = cos(yaw), sn = sin(yaw);
    for (int k = 0; k < hubs; k++)
        shares[k] = soil_share(g, x + cs * x_hub[k] - sn * y_hub[k], y + sn * x_hub[k] + cs * y_hub[k]);
}

/* A copy of the grid (the arrays copied); 0 ok, -1 bad sizes or out of memory. */
static int soil_grid_init(SoilGrid *g, int nx, int ny, const double *x, const double *y, const double *share) {
    memset(g, 0, sizeof *g);
    if (nx < 2 || ny < 2) return -1;
    g->nx = nx;
    g->ny = ny;
    g->x = malloc((size_t)nx * sizeof *g->x);
    g->y = malloc((size_t)ny * sizeof *g->y);
    g->share = malloc((size_t)nx * (size_t)ny * sizeof *g->share);
    if (!g->x || !g->y || !g->share) return -1;
    memcpy(g->x, x, (size_t)nx * sizeof *g->x);
    memcpy(g->y, y, (size_t)ny * sizeof *g->y);
    memcpy(g->share, share, (size_t)nx * (size_t)ny * sizeof *g->share);
    return 0;
}

static void soil_grid_free(SoilGrid *g) {
    free(g->x);
    free(g->y);
    free(g->share);
    memset(g, 0, sizeof *g);
}

#endif
