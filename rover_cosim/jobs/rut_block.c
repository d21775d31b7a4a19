/* The C twin of the rut participant (ruts.py: RutBlock, its map terramechanics/multipass.py: RutMap)
 * for the native stepper (rover_cosim.orchestrator.native): the same stamps and the same depths, so
 * that it gives the Python block's outputs bit for bit (checked by the tests).
 *
 * Inputs (value references 0 ..): x [m] (planar: x, y [m], yaw [rad]) of the body, then sinkage[i]
 * [m] of each wheel. Outputs: rutDepth[i] [m]. The map: cells of ``cell`` [m] keyed by
 * (floor(x / cell), floor(y / cell)), each holding the deepest sinkage every wheel left there, in a
 * hash table with linear probing that doubles when half full. The functions follow fmi2SetReal,
 * fmi2GetReal and fmi2DoStep (status 0 ok, 3 error; the error's text from rut_message). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "block_io.h"

typedef struct {
    long long ix, iy;
    int used;
} Key;

typedef struct {
    int wheels, planar, n_inputs;
    double cell, half_width;
    double *x_hub, *y_hub;     /* body frame [m] */
    double *in, *out, *x, *y;  /* inputs, outputs, hubs on the ground now */
    Key *keys;                 /* capacity slots */
    double *depth;             /* capacity x wheels: the deepest sinkage of each wheel [m] */
    size_t capacity, count;
    char message[160];
} RutBlock;

static size_t slot_of(long long ix, long long iy, size_t capacity) {
    unsigned long long h = (unsigned long long)ix * 0x9E3779B97F4A7C15ull ^ (unsigned long long)iy * 0xC2B2AE3D27D4EB4Full;
    h ^= h >> 29;
    return (size_t)(h & (capacity - 1));
}

/* The slot of cell (ix, iy), or where it would go (keys[slot].used == 0). */
static size_t find(const RutBlock *c, long long ix, long long iy) {
    size_t s = slot_of(ix, iy, c->capacity);
    while (c->keys[s].used && (c->keys[s].ix != ix || c->keys[s].iy != iy)) s = (s + 1) & (c->capacity - 1);
    return s;
}

static int grow(RutBlock *c) {
    size_t old_capacity = c->capacity, w = (size_t)c->wheels;
    Key *old_keys = c->keys;
    double *old_depth = c->depth;
    c->capacity = old_capacity ? 2 * old_capacity : 1024;
    c->keys = calloc(c->capacity, sizeof *c->keys);
    c->depth = calloc(c->capacity * w, sizeof *c->depth);
    if (!c->keys || !c->depth) {
        free(c->keys);
        free(c->depth);
        c->capacity = old_capacity;
        c->keys = old_keys;
        c->depth = old_depth;
        return -1;
    }
    for (size_t k = 0; k < old_capacity; k++) {
        if (!old_keys[k].used) continue;
        size_t s = find(c, old_keys[k].ix, old_keys[k].iy);
        c->keys[s] = old_keys[k];
        memcpy(c->depth + s * w, old_depth + k * w, w * sizeof *c->depth);
    }
    free(old_keys);
    free(old_depth);
    return 0;
}

/* The depths of cell (ix, iy), made (all 0) when ``make`` and absent; NULL when absent and not
 * made, or out of memory (then ``message`` says so). */
static double *cell_depths(RutBlock *c, long long ix, long long iy, int make) {
    size_t s = find(c, ix, iy);
    if (c->keys[s].used) return c->depth + s * (size_t)c->wheels;
    if (!make) return NULL;
    if (2 * (c->count + 1) > c->capacity) {
        if (grow(c) != 0) {
            snprintf(c->message, sizeof c->message, "do_step: out of memory for the ruts' %zu cells", c->count + 1);
            return NULL;
        }
        s = find(c, ix, iy);
    }
    c->keys[s].ix = ix;
    c->keys[s].iy = iy;
    c->keys[s].used = 1;
    c->count++;
    return c->depth + s * (size_t)c->wheels;
}

/* floor(v / cell) as a cell index; -1 for a value that has none (not finite, or beyond 2^62 cells). */
static int cell_index(const RutBlock *c, double v, long long *index) {
    double q = floor(v / c->cell);
    if (!isfinite(q) || fabs(q) > 4.6e18) return -1;
    *index = (long long)q;
    return 0;
}

int rut_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    RutBlock *c = component;
    return block_set(c->in, (unsigned int)c->n_inputs, c->message, sizeof c->message, vr, n, value);
}

int rut_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    RutBlock *c = component;
    return block_get(c->out, (unsigned int)c->wheels, c->message, sizeof c->message, vr, n, value);
}

/* A step marks the ruts with the sinkages at the hubs' positions now, then gives each wheel the
 * deepest rut another wheel left in the cell under its hub (RutBlock._advance). */
int rut_do_step(void *component, double t, double h, int no_prior_state) {
    RutBlock *c = component;
    (void)t;
    (void)h;
    (void)no_prior_state;
    int w = c->wheels, pose = c->planar ? 3 : 1;
    if (c->planar) {
        double x = c->in[0], y = c->in[1], co = cos(c->in[2]), si = sin(c->in[2]);
        for (int i = 0; i < w; i++) {
            c->x[i] = x + co * c->x_hub[i] - si * c->y_hub[i];
            c->y[i] = y + si * c->x_hub[i] + co * c->y_hub[i];
        }
    } else {
        for (int i = 0; i < w; i++) {
            c->x[i] = c->in[0] + c->x_hub[i];
            c->y[i] = c->y_hub[i];
        }
    }
    long long ix[64], iy[64];
    for (int i = 0; i < w; i++) {
        if (cell_index(c, c->x[i], &ix[i]) != 0 || cell_index(c, c->y[i], &iy[i]) != 0) {
            snprintf(c->message, sizeof c->message, "do_step: wheel %d's hub at (%g, %g) m is on no cell of the ruts",
                     i + 1, c->x[i], c->y[i]);
            return ERROR;
        }
    }
    double ratio = c->half_width / c->cell;
    long long across = (long long)ceil(ratio);
    if (across < 1) across = 1;
    for (int i = 0; i < w; i++) {
        double depth = c->in[pose + i];
        if (!(depth > 0)) continue;
        for (long long j = iy[i] - across + 1; j < iy[i] + across; j++) {
            double *cell = cell_depths(c, ix[i], j, 1);
            if (!cell) return ERROR;
            if (depth > cell[i]) cell[i] = depth;
        }
    }
    for (int i = 0; i < w; i++) {
        const double *cell = cell_depths(c, ix[i], iy[i], 0);
        double deepest = 0.0;
        if (cell) {
            for (int k = 0; k < w; k++)
                if (k != i && cell[k] > deepest) deepest = cell[k];
        }
        c->out[i] = deepest;
    }
    return OK;
}

const char *rut_message(void *component) { return ((RutBlock *)component)->message; }

void rut_free(void *component) {
    RutBlock *c = component;
    if (!c) return;
    free(c->x_hub);
    free(c->keys);
    free(c->depth);
    free(c);
}

/* A rut block of ``wheels`` wheels (1..64) at ``hubs`` (x[wheels], then y[wheels] [m], body frame),
 * ``planar`` (inputs x, y, yaw) or not (x), on cells of ``cell`` [m], wheels ``half_width`` [m];
 * the map it starts from: ``n_cells`` cells ``keys`` (ix, iy of each) with their ``depths``
 * (wheels per cell [m]); its outputs now ``start``. All arrays are copied. NULL for bad sizes or
 * out of memory. */
void *rut_new(int wheels, int planar, double cell, double half_width, const double *hubs, int n_cells,
              const long long *keys, const double *depths, const double *start) {
    if (wheels < 1 || wheels > 64 || !(cell > 0) || !(half_width > 0) || n_cells < 0) return NULL;
    RutBlock *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->wheels = wheels;
    c->planar = planar != 0;
    c->n_inputs = (c->planar ? 3 : 1) + wheels;
    c->cell = cell;
    c->half_width = half_width;
    /* one block for the per-wheel arrays: hubs (2 w), inputs, outputs, hubs now (2 w) */
    c->x_hub = calloc((size_t)(4 * wheels + c->n_inputs + wheels), sizeof(double));
    if (!c->x_hub) {
        rut_free(c);
        return NULL;
    }
    c->y_hub = c->x_hub + wheels;
    c->x = c->y_hub + wheels;
    c->y = c->x + wheels;
    c->in = c->y + wheels;
    c->out = c->in + c->n_inputs;
    memcpy(c->x_hub, hubs, 2 * (size_t)wheels * sizeof(double));
    memcpy(c->out, start, (size_t)wheels * sizeof(double));
    while (2 * (size_t)n_cells >= c->capacity) {
        if (grow(c) != 0) {
            rut_free(c);
            return NULL;
        }
    }
    for (int k = 0; k < n_cells; k++) {
        double *cell_of = cell_depths(c, keys[2 * k], keys[2 * k + 1], 1);
        if (!cell_of) {
            rut_free(c);
            return NULL;
        }
        memcpy(cell_of, depths + (size_t)k * (size_t)wheels, (size_t)wheels * sizeof(double));
    }
    return c;
}
