/* The C twin of PathFollowingController (path_controller.py, path.py, allocation.py,
 * identification/lateral.py, longitudinal.py) for the native stepper
 * (rover_cosim.orchestrator.native): the same arithmetic in the same order, so that it gives the
 * Python block's outputs bit for bit (compiled with -ffp-contract=off; checked by the tests).
 *
 * Inputs (value references 0 ..): x, y [m], yaw [rad], v, vy [m/s], yawRate [rad/s], W[1..N] [N],
 * slipAngle[1..N] [rad] (N wheels: path_new's ``wheels``, six on the paper's rover). Outputs: tau[1..N]
 * [N.m], steer[1..N] [rad], Fx_des[1..N], Fy_des[1..N]
 * [N], s, s_ref, cross_track [m], heading_error [rad]. The functions follow fmi2SetReal,
 * fmi2GetReal and fmi2DoStep (status 0 ok, 3 error; the error's text from path_message).
 *
 * Per step: the nearest point of the path (Path.locate), the body's force and yaw-moment demand
 * in the heading frame (_tracking; with PULL, less gravity's pull on a ground plane as
 * TerrainPathController feeds it forward), and per wheel either the steering and wheel-frame forces by
 * the identified lateral and longitudinal models (allocation, then Newton on the steering,
 * _inverse_steering) or the kinematic ablation (_kinematic_steering); the torques by the inverse
 * longitudinal law (inverse_law.h).
 *
 * Believing a soil map (terrain_controller.py, path_believe): the shares of the second soil under
 * the hubs (../terramechanics/soil_map.h), and per wheel on a share s > 0 the lateral law and the
 * torque blended with those of the second soil's models, (1 - s) first + s second. Over a height
 * map (path_ground_map, ../terramechanics/height_map.h): the pull of the loads on the map's local
 * slopes under the hubs fed forward too (TerrainPathController.ground_pull). */
#include "inverse_law.h"
#include "../terramechanics/height_map.h"
#include "../terramechanics/soil_map.h"

#define MAX_WHEELS 16
#define N_INPUTS (6 + 2 * c->wheels)
#define N_OUTPUTS (4 * c->wheels + 4)
#define NEWTON_STEPS 2

enum { MASS, YAW_INERTIA, V_TARGET, KV, KP, A_MAX, K_E, K_DE, A_N_MAX, K_PSI, K_R, ALPHA_MAX, STEP, WN, KINEMATIC,
       MAX_STEER, MAX_SLIP_ANGLE, SPACING, LENGTH, WINDOW, PULL, SLOPE, DOWNHILL, GRAVITY, N_SETTINGS };
enum { RATIONAL, EXPONENTIAL, POLYNOMIAL };

/* A lateral model (identification/lateral.py LateralModel): its basis, the shape of its
 * coefficients c[i][k][j] (terms x slip powers x load powers) and the basis' scales [rad]. */
typedef struct {
    int basis, terms, n_slip, n_load;
    double *scales;                 /* beta_i [rad] */
    double *coefficients;           /* c[i][k][j] */
} Lateral;

typedef struct {
    double settings[N_SETTINGS];
    int wheels;                     /* N, at most MAX_WHEELS */
    Law law;
    int n_path;                     /* samples of the path */
    double *arc, *px, *py, *heading, *curvature;   /* per sample: s [m], x, y [m], heading [rad], curvature [1/m] */
    int hint;                       /* the last nearest sample, -1: none yet */
    int ignored;                    /* inputs after the law's that are accepted and not read */
    Lateral lateral;
    int believes;                   /* 1: a soil map is believed (the second soil's models below) */
    Law law_b;
    Lateral lateral_b;
    SoilGrid grid;
    double shares[MAX_WHEELS];
    int has_map;                    /* 1: a height map's pull is fed forward (the spline below) */
    HeightSpline spline;          /* the second soil's share under each hub this step [1] */
    double x_hub[MAX_WHEELS], y_hub[MAX_WHEELS];
    double rows[3][2 * MAX_WHEELS]; /* the allocation matrix */
    double steer[MAX_WHEELS];       /* the last steering [rad] */
    double in[6 + 2 * MAX_WHEELS], out[4 * MAX_WHEELS + 4];
    char message[256];
} PathController;

/* _clip: min(max(value, low), high), NaN kept. */
static double clip(double value, double low, double high) {
    value = low > value ? low : value;
    return value > high ? high : value;
}

/* path.interpolate: np.interp at one point. */
static double interpolate(const double *xp, const double *fp, int n, double x) {
    if (!(x > xp[0])) return x == x ? fp[0] : x;
    if (x >= xp[n - 1]) return fp[n - 1];
    int j = bisect_right(xp, n, x) - 1;
    if (xp[j] == x) return fp[j];
    return (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j];
}

typedef struct { double s, cross_track, heading, curvature; } Location;

/* Path.locate: the nearest point of the path to (x, y), searched within the window around the hint. */
static Location locate(PathController *c, double x, double y) {
    const double *s = c->settings;
    int n = c->n_path, low = 0, high = n;
    if (c->hint >= 0) {
        int reach = (int)(s[WINDOW] / s[SPACING]) + 1;
        low = c->hint - reach > 0 ? c->hint - reach : 0;
        high = c->hint + reach + 1 < n ? c->hint + reach + 1 : n;
    }
    int i = low;
    double best = 0.0;
    for (int k = low; k < high; k++) {  /* np.argmin: the first smallest, or the first NaN */
        double dx = c->px[k] - x, dy = c->py[k] - y, distance = dx * dx + dy * dy;
        if (distance != distance) { i = k; break; }
        if (k == low || distance < best) { best = distance; i = k; }
    }
    c->hint = i;
    int j = i + 1 < n ? i + 1 : i - 1;
    double dx = c->px[j] - c->px[i], dy = c->py[j] - c->py[i];
    double norm = sqrt(dx * dx + dy * dy);
    double along = ((x - c->px[i]) * (dx / norm) + (y - c->py[i]) * (dy / norm)) * (j > i ? 1.0 : -1.0);
    double at = c->arc[i] + clip(along, -s[SPACING], s[SPACING]);
    at = clip(at, 0.0, s[LENGTH]);
    Location where;
    where.s = at;
    double px = interpolate(c->arc, c->px, n, at), py = interpolate(c->arc, c->py, n, at);
    where.heading = interpolate(c->arc, c->heading, n, at);
    where.curvature = interpolate(c->arc, c->curvature, n, at);
    where.cross_track = -sin(where.heading) * (x - px) + cos(where.heading) * (y - py);
    return where;
}

/* allocation.solve3: Gaussian elimination with partial pivoting; ERROR for a singular matrix. */
static int solve3(double a[3][4], double *z) {
    for (int k = 0; k < 3; k++) {
        int p = k;
        for (int i = k + 1; i < 3; i++)
            if (fabs(a[i][k]) > fabs(a[p][k])) p = i;
        if (a[p][k] == 0.0) return ERROR;
        for (int j = 0; j < 4; j++) { double t = a[k][j]; a[k][j] = a[p][j]; a[p][j] = t; }
        for (int i = k + 1; i < 3; i++) {
            double factor = a[i][k] / a[k][k];
            for (int j = k; j < 4; j++) a[i][j] -= factor * a[k][j];
        }
    }
    z[2] = a[2][3] / a[2][2];
    z[1] = (a[1][3] - a[1][2] * z[2]) / a[1][1];
    z[0] = (a[0][3] - a[0][1] * z[1] - a[0][2] * z[2]) / a[0][0];
    return OK;
}

/* allocation.share: each wheel's (f_x, f_y) in the heading frame for the demand. */
static int share(PathController *c, const double *demand, const double *loads, double *fx, double *fy) {
    double d[2 * MAX_WHEELS], scaled[3][2 * MAX_WHEELS], a[3][4], z[3];
    const int n_wheels = c->wheels;
    int carrying = 0;
    for (int i = 0; i < n_wheels; i++) {
        double w = 0.0 > loads[i] ? 0.0 : loads[i];
        d[i] = d[n_wheels + i] = w;
        carrying += w != 0.0;
    }
    if (carrying < 2) {
        snprintf(c->message, sizeof c->message, "loads: at least two wheels must carry load to allocate a yaw moment");
        return ERROR;
    }
    for (int p = 0; p < 3; p++)
        for (int k = 0; k < 2 * n_wheels; k++) scaled[p][k] = c->rows[p][k] * d[k];
    for (int p = 0; p < 3; p++) {
        for (int q = 0; q < 3; q++) {
            double total = 0.0;
            for (int k = 0; k < 2 * n_wheels; k++) total += scaled[p][k] * c->rows[q][k];
            a[p][q] = total;
        }
        a[p][3] = demand[p];
    }
    if (solve3(a, z) != OK) {
        snprintf(c->message, sizeof c->message, "the allocation's matrix is singular");
        return ERROR;
    }
    for (int k = 0; k < 2 * n_wheels; k++) {
        double force = scaled[0][k] * z[0] + scaled[1][k] * z[1] + scaled[2][k] * z[2];
        if (k < n_wheels) fx[k] = force; else fy[k - n_wheels] = force;
    }
    return OK;
}

/* LateralModel.angle_coefficients_at: a_i(W, slip) = sum_k sum_j c[i][k][j] slip^k W^j. */
static void angle_coefficients(const Lateral *c, double load, double slip, double *a) {
    for (int i = 0; i < c->terms; i++) {
        double total = 0.0;
        for (int k = 0; k < c->n_slip; k++)
            for (int j = 0; j < c->n_load; j++)
                total += c->coefficients[(i * c->n_slip + k) * c->n_load + j] * pow(slip, (double)k)
                         * pow(load, (double)j);
        a[i] = total;
    }
}

/* LateralModel.fy_and_slope_at (LateralForm.angle_terms): Fy [N] and dFy/dbeta [N/rad]. */
static void fy_and_slope(const Lateral *c, const double *a, double beta, double *fy, double *slope) {
    double magnitude = fabs(beta);
    double sign = beta > 0 ? 1.0 : beta < 0 ? -1.0 : beta;
    *fy = 0.0;
    *slope = 0.0;
    for (int i = 0; i < c->terms; i++) {
        double s = c->scales[i], phi, dphi;
        if (c->basis == POLYNOMIAL) {
            phi = pow(beta, (double)(2 * i + 1));
            dphi = (double)(2 * i + 1) * pow(beta, (double)(2 * i));
        } else if (c->basis == RATIONAL) {
            phi = beta / (magnitude + s);
            dphi = s / ((magnitude + s) * (magnitude + s));
        } else {
            phi = sign * -expm1(-magnitude / s);
            dphi = exp(-magnitude / s) / s;
        }
        *fy += a[i] * phi;
        *slope += a[i] * dphi;
    }
}

/* The outputs at time t from the inputs; ``advance``: the filter moves on by h. As
 * PathFollowingController._outputs. */
static int outputs(PathController *c, double t, int advance, double h) {
    const double *g = c->settings;
    const int n_wheels = c->wheels;
    double loads[MAX_WHEELS], steer[MAX_WHEELS], fx_des[MAX_WHEELS], fy_des[MAX_WHEELS];
    for (int i = 0; i < n_wheels; i++) loads[i] = 1.0 > c->in[6 + i] ? 1.0 : c->in[6 + i];
    /* 1. tracking */
    double x = c->in[0], y = c->in[1], yaw = c->in[2], v = c->in[3], vy = c->in[4], r = c->in[5];
    if (c->believes) soil_shares(&c->grid, x, y, yaw, c->x_hub, c->y_hub, n_wheels, c->shares);
    Location where = locate(c, x, y);
    double offset = yaw - where.heading;
    double cs = cos(offset), sn = sin(offset);
    double along = v * cs - vy * sn, across = v * sn + vy * cs;
    double s_ref = g[V_TARGET] * t;
    double a_t = clip(g[KV] * (g[V_TARGET] - along) + g[KP] * (s_ref - where.s), -g[A_MAX], g[A_MAX]);
    double a_n = clip(along * along * where.curvature - g[K_E] * where.cross_track - g[K_DE] * across, -g[A_N_MAX],
                      g[A_N_MAX]);
    double alpha = clip(g[K_PSI] * -offset + g[K_R] * (along * where.curvature - r), -g[ALPHA_MAX], g[ALPHA_MAX]);
    double demand[3] = {g[MASS] * (a_t * cs + a_n * sn), g[MASS] * (-a_t * sn + a_n * cs), g[YAW_INERTIA] * alpha};
    if (g[PULL] != 0 || c->has_map) { /* terrain_controller.py ground_pull: held by the wheels */
        double pull_x = 0.0, pull_y = 0.0, pull_z = 0.0;
        if (g[PULL] != 0) { /* gravity's pull on a ground plane */
            double tangential = g[GRAVITY] * sin(g[SLOPE]);
            double along_g = tangential * cos(g[DOWNHILL] - yaw), lateral_g = tangential * sin(g[DOWNHILL] - yaw);
            pull_x = g[MASS] * along_g;
            pull_y = g[MASS] * lateral_g;
        }
        if (c->has_map) { /* the loads' pull on the map's slopes under the hubs */
            double cm = cos(yaw), sm = sin(yaw), sum_x = 0.0, sum_y = 0.0;
            for (int i = 0; i < n_wheels; i++) {
                double height, slope_x, slope_y, w = c->in[6 + i];
                height_at(&c->spline, x + cm * c->x_hub[i] - sm * c->y_hub[i], y + sm * c->x_hub[i] + cm * c->y_hub[i],
                          &height, &slope_x, &slope_y);
                double load = w > 1.0 ? w : 1.0;
                double hub_x = -load * (slope_x * cm + slope_y * sm), hub_y = -load * (-slope_x * sm + slope_y * cm);
                sum_x += hub_x;
                sum_y += hub_y;
                pull_z += c->x_hub[i] * hub_y - c->y_hub[i] * hub_x;
            }
            pull_x = pull_x + sum_x;
            pull_y = pull_y + sum_y;
        }
        demand[0] = demand[0] - pull_x;
        demand[1] = demand[1] - pull_y;
        demand[2] = demand[2] - pull_z;
    }
    if (g[KINEMATIC] != 0) {
        double rate = along * where.curvature - g[K_PSI] / g[K_R] * offset - g[K_E] / g[K_DE] * where.cross_track;
        double speed = 1e-3 > along ? 1e-3 : along;
        double total = 0.0;
        for (int i = 0; i < n_wheels; i++) total += loads[i];
        for (int i = 0; i < n_wheels; i++) {
            steer[i] = clip(atan2(rate * c->x_hub[i], speed - rate * c->y_hub[i]), -g[MAX_STEER], g[MAX_STEER]);
            fx_des[i] = demand[0] * loads[i] / total;
            fy_des[i] = 0.0;
        }
    } else {
        double fx[MAX_WHEELS], fy[MAX_WHEELS], coefficients[16], coefficients_b[16];
        if (c->lateral.terms > 16 || (c->believes && c->lateral_b.terms > 16)) return ERROR;
        if (share(c, demand, loads, fx, fy) != OK) return ERROR;
        for (int i = 0; i < n_wheels; i++) {
            double delta = c->steer[i], angle = c->in[6 + n_wheels + i] + c->steer[i], slip;
            double force = fx[i] * cos(delta) + fy[i] * sin(delta), s = c->believes ? c->shares[i] : 0.0;
            if (slip_for_force(&c->law, loads[i], force, &slip) != OK) return ERROR;
            angle_coefficients(&c->lateral, loads[i], slip, coefficients);
            if (s != 0.0) { /* the second soil's lateral law at its own slip for the force */
                if (slip_for_force(&c->law_b, loads[i], force, &slip) != OK) return ERROR;
                angle_coefficients(&c->lateral_b, loads[i], slip, coefficients_b);
            }
            double low = clip(angle - g[MAX_SLIP_ANGLE], -g[MAX_STEER], INFINITY);
            double high = clip(angle + g[MAX_SLIP_ANGLE], -INFINITY, g[MAX_STEER]);
            for (int k = 0; k < NEWTON_STEPS; k++) {
                double cd = cos(delta), sd = sin(delta), model_fy, slope;
                fy_and_slope(&c->lateral, coefficients, angle - delta, &model_fy, &slope);
                if (s != 0.0) {
                    double fy_b, slope_b;
                    fy_and_slope(&c->lateral_b, coefficients_b, angle - delta, &fy_b, &slope_b);
                    model_fy = (1.0 - s) * model_fy + s * fy_b;
                    slope = (1.0 - s) * slope + s * slope_b;
                }
                double residual = model_fy - (fy[i] * cd - fx[i] * sd);
                double derivative = -slope + fx[i] * cd + fy[i] * sd;
                delta = clip(delta - residual / (fabs(derivative) > 1e-9 ? derivative : 1e-9), low, high);
            }
            double cd = cos(delta), sd = sin(delta);
            steer[i] = delta;
            fx_des[i] = fx[i] * cd + fy[i] * sd;
            fy_des[i] = fy[i] * cd - fx[i] * sd;
        }
    }
    double ad[4], bd[2], ad_b[4], bd_b[2];
    law_discretisation(&c->law, advance, h, ad, bd);
    if (c->believes) law_discretisation(&c->law_b, advance, h, ad_b, bd_b);
    for (int i = 0; i < n_wheels; i++) {
        c->steer[i] = steer[i];
        if (law_torque(&c->law, i, loads[i], fx_des[i], advance, ad, bd, &c->out[i]) != OK) return ERROR;
        if (c->believes) { /* both laws move on; the torque blended where the second soil is believed */
            double torque_b, s = c->shares[i];
            if (law_torque(&c->law_b, i, loads[i], fx_des[i], advance, ad_b, bd_b, &torque_b) != OK) return ERROR;
            if (s != 0.0) c->out[i] = (1.0 - s) * c->out[i] + s * torque_b;
        }
        c->out[n_wheels + i] = steer[i];
        c->out[2 * n_wheels + i] = fx_des[i];
        c->out[3 * n_wheels + i] = fy_des[i];
    }
    c->out[4 * n_wheels] = where.s;
    c->out[4 * n_wheels + 1] = s_ref;
    c->out[4 * n_wheels + 2] = where.cross_track;
    c->out[4 * n_wheels + 3] = offset;
    return OK;
}

int path_set_real(void *component, const unsigned int *vr, size_t n, const double *value) {
    PathController *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= (unsigned int)(N_INPUTS + c->ignored)) {
            snprintf(c->message, sizeof c->message, "set_real: no such input");
            return ERROR;
        }
        if (vr[k] < N_INPUTS) c->in[vr[k]] = value[k];
    }
    return OK;
}

int path_get_real(void *component, const unsigned int *vr, size_t n, double *value) {
    PathController *c = component;
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= N_OUTPUTS) {
            snprintf(c->message, sizeof c->message, "get_real: no such output");
            return ERROR;
        }
        value[k] = c->out[vr[k]];
    }
    return OK;
}

int path_do_step(void *component, double t, double h, int no_prior_state) {
    PathController *c = component;
    (void)no_prior_state;
    if (law_step_allowed(c->message, h, c->settings[STEP]) != OK) return ERROR;
    return outputs(c, t + h, 1, h);
}

/* Accept ``count`` inputs after the law's and ignore them (the adaptive path controller's telemetry). */
void path_ignore_inputs(void *component, int count) { ((PathController *)component)->ignored = count > 0 ? count : 0; }

const char *path_message(void *component) { return ((PathController *)component)->message; }

void path_free(void *component) {
    PathController *c = component;
    if (!c) return;
    law_free(&c->law);
    law_free(&c->law_b);
    soil_grid_free(&c->grid);
    height_spline_free(&c->spline);
    double *arrays[] = {c->arc, c->px, c->py, c->heading, c->curvature, c->lateral.scales, c->lateral.coefficients,
                        c->lateral_b.scales, c->lateral_b.coefficients};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; k++) free(arrays[k]);
    free(c);
}

/* A path controller: ``settings`` as the enum above; the law's tables as controller_new's
 * (inverse_controller.c) with the filter state of the six wheels; the path's ``n_path`` samples
 * (``path``: s, x, y, heading, curvature, each n_path long, one after the other) and the last
 * nearest sample ``hint`` (-1: none); the lateral model (``basis``: 0 rational, 1 exponential,
 * 2 polynomial; ``shape``: terms, slip powers, load powers; ``scales`` [rad]; ``lateral``: its
 * coefficients c[i][k][j]); the hubs (``hubs``: x[N], then y[N] [m]) and the last ``steer``
 * [rad] of its ``wheels`` N wheels (2 to MAX_WHEELS). All arrays are copied. NULL for bad sizes or
 * out of memory. */
void *path_new(const double *settings, int n_loads, int n_torques, int degree, const double *inverse,
               const double *torques, const double *settled, const double *log_t, const double *coefficients,
               const double *filter, int n_path, const double *path, int hint, int basis, const int *shape,
               const double *scales, const double *lateral, const double *hubs, const double *steer, int wheels) {
    if (n_path < 2 || basis < RATIONAL || basis > POLYNOMIAL || shape[0] < 1 || shape[0] > 16 || shape[1] < 1
        || shape[2] < 1 || wheels < 2 || wheels > MAX_WHEELS)
        return NULL;
    PathController *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->wheels = wheels;
    const int n_wheels = wheels;
    memcpy(c->settings, settings, sizeof c->settings);
    size_t n = (size_t)n_path, size = (size_t)(shape[0] * shape[1] * shape[2]);
    c->n_path = n_path;
    c->hint = hint;
    c->lateral.basis = basis; c->lateral.terms = shape[0]; c->lateral.n_slip = shape[1]; c->lateral.n_load = shape[2];
    c->arc = law_copy(path, n);
    c->px = law_copy(path + n, n);
    c->py = law_copy(path + 2 * n, n);
    c->heading = law_copy(path + 3 * n, n);
    c->curvature = law_copy(path + 4 * n, n);
    c->lateral.scales = law_copy(scales, (size_t)shape[0]);
    c->lateral.coefficients = law_copy(lateral, size);
    if (law_init(&c->law, n_wheels, n_loads, n_torques, degree, settings[WN], settings[STEP], inverse, torques, settled,
                 log_t, coefficients, filter, c->message) != 0
        || !c->arc || !c->px || !c->py || !c->heading || !c->curvature || !c->lateral.scales
        || !c->lateral.coefficients) {
        path_free(c);
        return NULL;
    }
    for (int i = 0; i < n_wheels; i++) {
        c->x_hub[i] = hubs[i];
        c->y_hub[i] = hubs[n_wheels + i];
        c->steer[i] = steer[i];
        c->rows[0][i] = 1.0; c->rows[0][n_wheels + i] = 0.0;
        c->rows[1][i] = 0.0; c->rows[1][n_wheels + i] = 1.0;
        c->rows[2][i] = -c->y_hub[i]; c->rows[2][n_wheels + i] = c->x_hub[i];
    }
    return c;
}

/* Believe a soil map: the second soil's longitudinal law (its tables as path_new's, with the
 * filter state of the six wheels) and lateral model (as path_new's), and the map's grid of
 * ``nx`` x ``ny`` points (``grid_x``, ``grid_y`` [m]; ``share``: row by row along x, one row per
 * y). All arrays are copied. 0 ok; 3 for bad sizes or out of memory (the message says which). */
int path_believe(void *component, int n_loads, int n_torques, int degree, const double *inverse,
                 const double *torques, const double *settled, const double *log_t, const double *coefficients,
                 const double *filter, int basis, const int *shape, const double *scales, const double *lateral,
                 int nx, int ny, const double *grid_x, const double *grid_y, const double *share) {
    PathController *c = component;
    const int n_wheels = c->wheels;
    if (basis < RATIONAL || basis > POLYNOMIAL || shape[0] < 1 || shape[0] > 16 || shape[1] < 1 || shape[2] < 1) {
        snprintf(c->message, sizeof c->message, "path_believe: bad lateral model");
        return ERROR;
    }
    c->lateral_b.basis = basis; c->lateral_b.terms = shape[0]; c->lateral_b.n_slip = shape[1];
    c->lateral_b.n_load = shape[2];
    c->lateral_b.scales = law_copy(scales, (size_t)shape[0]);
    c->lateral_b.coefficients = law_copy(lateral, (size_t)(shape[0] * shape[1] * shape[2]));
    if (law_init(&c->law_b, n_wheels, n_loads, n_torques, degree, c->settings[WN], c->settings[STEP], inverse, torques,
                 settled, log_t, coefficients, filter, c->message) != 0
        || !c->lateral_b.scales || !c->lateral_b.coefficients || soil_grid_init(&c->grid, nx, ny, grid_x, grid_y, share)) {
        snprintf(c->message, sizeof c->message, "path_believe: bad sizes or out of memory");
        return ERROR;
    }
    c->believes = 1;
    return OK;
}

/* Feed a height map's pull forward: its spline (knots along x and y, coefficients and the grid's
 * extent x0, x1, y0, y1 [m], as height_map.h's HeightSpline). All arrays are copied. 0 ok; 3 for
 * bad sizes or out of memory. */
int path_ground_map(void *component, int n_knots_x, const double *knots_x, int n_knots_y, const double *knots_y,
                    const double *coefficients, const double *extent) {
    PathController *c = component;
    if (height_spline_init(&c->spline, n_knots_x, knots_x, n_knots_y, knots_y, coefficients, extent) != 0) {
        snprintf(c->message, sizeof c->message, "path_ground_map: bad sizes or out of memory");
        return ERROR;
    }
    c->has_map = 1;
    return OK;
}
