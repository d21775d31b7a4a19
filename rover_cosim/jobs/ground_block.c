/* The C twin of the ground participant (ground.py: GroundBlock) for the native stepper
 * (rover_cosim.orchestrator.native): the law of ../terramechanics/height_map.h, so that it gives
 * the Python block's outputs bit for bit (checked by the tests).
 *
 * Inputs (value references 0 ..): x, y [m], yaw [rad], v, vy [m/s], yawRate [rad/s] of the body.
 * Outputs per hub i = 1..6: groundHeight[i] [m], then groundHeightRate[i] [m/s], then
 * groundGradientAlong[i], then groundGradientLateral[i] [1]. The functions follow fmi2SetReal,
 * fmi2GetReal and fmi2DoStep (status 0 ok, 3 error; the error's text from ground_message). */
#include <math.h>
#include "block_io.h"
#include "../terramechanics/height_map.h"

#define HUBS 6
#define N_INPUTS 6
#define N_OUTPUTS (4 * HUBS)

typedef struct {
    HeightSpline spline;
    double x_hub[HUBS], y_hub[HUBS];
    double in[N_INPUTS], out[N_OUTPUTS];
    char message[128];
} GroundBlock;

int ground_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    GroundBlock *c = component;
    return block_set(c->in, N_INPUTS, c->message, sizeof c->message, vr, n, value);
}

int ground_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    GroundBlock *c = component;
    return block_get(c->out, N_OUTPUTS, c->message, sizeof c->message, vr, n, value);
}

/* GroundBlock.ground: the outputs at the inputs now (the block has no state). */
int ground_do_step(void *component, double t, double h, int no_prior_state) {
    GroundBlock *c = component;
    (void)t;
    (void)h;
    (void)no_prior_state;
    double x = c->in[0], y = c->in[1], yaw = c->in[2], v = c->in[3], vy = c->in[4], r = c->in[5];
    double cs = cos(yaw), sn = sin(yaw);
    for (int k = 0; k < HUBS; k++) {
        double hx = x + cs * c->x_hub[k] - sn * c->y_hub[k], hy = y + sn * c->x_hub[k] + cs * c->y_hub[k];
        double ux = v - r * c->y_hub[k], uy = vy + r * c->x_hub[k];
        double height, gx, gy;
        height_at(&c->spline, hx, hy, &height, &gx, &gy);
        double along = gx * cs + gy * sn, lateral = -gx * sn + gy * cs;
        c->out[k] = height;
        c->out[HUBS + k] = along * ux + lateral * uy;
        c->out[2 * HUBS + k] = along;
        c->out[3 * HUBS + k] = lateral;
    }
    return OK;
}

const char *ground_message(void *component) { return ((GroundBlock *)component)->message; }

void ground_free(void *component) {
    GroundBlock *c = component;
    if (!c) return;
    height_spline_free(&c->spline);
    free(c);
}

/* A ground block on the spline (knots along x and y, coefficients as HeightSpline's, the grid's
 * ``extent``: x0, x1, y0, y1 [m]) with its hubs (``hubs``: x[6], then y[6] [m]) and its outputs
 * now (``start``). All arrays are copied. NULL for bad sizes or out of memory. */
void *ground_new(int n_knots_x, const double *knots_x, int n_knots_y, const double *knots_y,
                 const double *coefficients, const double *extent, const double *hubs, const double *start) {
    GroundBlock *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    if (height_spline_init(&c->spline, n_knots_x, knots_x, n_knots_y, knots_y, coefficients, extent) != 0) {
        ground_free(c);
        return NULL;
    }
    for (int k = 0; k < HUBS; k++) {
        c->x_hub[k] = hubs[k];
        c->y_hub[k] = hubs[HUBS + k];
    }
    for (int k = 0; k < N_OUTPUTS; k++) c->out[k] = start[k];
    return c;
}
