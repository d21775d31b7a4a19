/* The C twin of the soil participants (ground.py: SoilBlock, LimbSoilBlock) for the native stepper
 * (rover_cosim.orchestrator.native): the law of ../terramechanics/soil_map.h, so that it gives the
 * Python block's outputs bit for bit (checked by the tests).
 *
 * Inputs (value references 0 ..): x, y [m], yaw [rad] of the body; a LimbSoilBlock's (soil_new_limbs)
 * also hubX[1..6], hubY[1..6] [m] (the hubs in the body frame, where the rover says they are).
 * Outputs: soilShare[1..6] [1]. The functions follow fmi2SetReal, fmi2GetReal and fmi2DoStep
 * (status 0 ok, 3 error; the error's text from soil_message). */
#include "block_io.h"
#include "../terramechanics/soil_map.h"

#define HUBS 6
#define BODY_INPUTS 3

typedef struct {
    SoilGrid grid;
    int limbs;                          /* the hubs are inputs (LimbSoilBlock), not x_hub, y_hub */
    double x_hub[HUBS], y_hub[HUBS];
    double in[BODY_INPUTS + 2 * HUBS], out[HUBS];
    char message[128];
} SoilBlock;

int soil_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    SoilBlock *c = component;
    return block_set(c->in, c->limbs ? BODY_INPUTS + 2 * HUBS : BODY_INPUTS, c->message, sizeof c->message, vr, n,
                     value);
}

int soil_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    SoilBlock *c = component;
    return block_get(c->out, HUBS, c->message, sizeof c->message, vr, n, value);
}

/* The outputs are the shares under the hubs at the inputs now (the block has no state). */
int soil_do_step(void *component, double t, double h, int no_prior_state) {
    SoilBlock *c = component;
    (void)t;
    (void)h;
    (void)no_prior_state;
    const double *x_hub = c->limbs ? c->in + BODY_INPUTS : c->x_hub;
    const double *y_hub = c->limbs ? c->in + BODY_INPUTS + HUBS : c->y_hub;
    soil_shares(&c->grid, c->in[0], c->in[1], c->in[2], x_hub, y_hub, HUBS, c->out);
    return OK;
}

const char *soil_message(void *component) { return ((SoilBlock *)component)->message; }

void soil_free(void *component) {
    SoilBlock *c = component;
    if (!c) return;
    soil_grid_free(&c->grid);
    free(c);
}

/* A soil block on the grid of ``nx`` x ``ny`` points (``x``, ``y`` [m], ``share``: row by row
 * along x, one row per y) with its hubs (``hubs``: x[6], then y[6] [m]) and its outputs now
 * (``start``: the shares at the start). All arrays are copied. NULL for bad sizes or out of
 * memory. */
void *soil_new(int nx, int ny, const double *x, const double *y, const double *share, const double *hubs,
               const double *start) {
    SoilBlock *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    if (soil_grid_init(&c->grid, nx, ny, x, y, share) != 0) {
        soil_free(c);
        return NULL;
    }
    for (int k = 0; k < HUBS; k++) {
        c->x_hub[k] = hubs[k];
        c->y_hub[k] = hubs[HUBS + k];
        c->out[k] = start[k];
    }
    return c;
}

/* A LimbSoilBlock's twin: as soil_new, the hubs inputs (``hubs``: their values now, x[6] then y[6] [m]). */
void *soil_new_limbs(int nx, int ny, const double *x, const double *y, const double *share, const double *hubs,
                     const double *start) {
    SoilBlock *c = soil_new(nx, ny, x, y, share, hubs, start);
    if (!c) return NULL;
    c->limbs = 1;
    for (int k = 0; k < 2 * HUBS; k++) c->in[BODY_INPUTS + k] = hubs[k];
    return c;
}
