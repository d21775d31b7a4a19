/* rover-cosim FMU runtime, the core (core.h): an instance, the evaluation of its model, its
 * values, asserts and directional derivatives, Model Exchange; the one error path. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core.h"
#include "finite.h"

#define DEFAULT_RTOL 1e-6
#define DEFAULT_MAX_STEP 0.0

static const char *const MODE_NAMES[MODE_COUNT] = {"instantiated", "initialization", "event", "continuous-time",
                                                   "step-complete", "terminated", "error"};
static const char *const LOG_CATEGORIES[N_LOG_CATEGORIES] = {"logStatusError", "logStatusWarning", "logStatistics"};

const char *rc_mode_name(Mode mode) { return mode >= 0 && mode < MODE_COUNT ? MODE_NAMES[mode] : "unknown"; }

/* ---- logging and the one error path -------------------------------------------------------- */
int rc_log_category(const char *name) {
    for (int k = 0; k < N_LOG_CATEGORIES; k++)
        if (name && strcmp(name, LOG_CATEGORIES[k]) == 0) return k;
    return -1;
}

void rc_log(Instance *c, Status status, const char *category, const char *format, ...) {
    int k = rc_log_category(category);
    if (!c || (status != STATUS_ERROR && (k < 0 || !(c->log_mask & (1u << k))))) return;
    char buffer[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    c->layer->log(c, status, category, buffer);
}

/* The one error path: "<API function>: <message>" under logStatusError, STATUS_ERROR, and for a
 * BROKEN instance the error state. */
Status rc_fail(Instance *c, int f, Severity severity, const char *format, ...) {
    char buffer[900];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    rc_log(c, STATUS_ERROR, "logStatusError", "%s: %s", c->layer->function_name(f), buffer);
    if (severity == BROKEN) c->mode = MODE_ERROR;
    return STATUS_ERROR;
}

Status rc_set_debug_logging(Instance *c, int f, int on, size_t n, const char *const categories[]) {
    NOT_NULL(f, categories, n);
    unsigned listed = 0;
    for (size_t i = 0; i < n; i++) {
        int k = rc_log_category(categories[i]);
        if (k < 0)
            return rc_fail(c, f, REJECTED, "log category %.100s: expected one of logStatusError, "
                           "logStatusWarning, logStatistics", categories[i] ? categories[i] : "(null)");
        listed |= 1u << k;
    }
    if (n == 0) c->log_mask = on ? ALL_CATEGORIES : 1u; /* errors are always logged */
    else c->log_mask = on ? (listed | 1u) : ((c->log_mask & ~listed) | 1u);
    return STATUS_OK;
}

/* ---- model evaluation ------------------------------------------------------------------- */
/* The inputs at time t: the held values, or their linear interpolation within the step. */
const double *rc_inputs_at(Instance *c, double t) {
    if (!c->interpolating) return c->u;
    double elapsed = c->h_step > 0.0 && t == c->t_step + c->h_step ? c->h_step : t - c->t_step;
    for (int i = 0; i < model_info.nu; i++) c->u_step[i] = c->u[i] + c->u_der[i] * elapsed;
    return c->u_step;
}

static int same(const double *a, const double *b, int n) {
    return n == 0 || memcmp(a, b, sizeof(double) * (size_t)n) == 0;
}

/* Derivatives, outputs and asserts at (t, x) with the inputs at t, into c->eval. The derivatives
 * and outputs share one evaluation of the model (one sinkage solve per wheel), and the last one
 * is reused at the same point with the same memories, bit for bit (so an evaluation is a function
 * of (t, x, u, p, m) and a restored FMU state repeats a run exactly): the outputs right after a step are those of its
 * last stage, and the next step starts from them when the inputs did not change. Parameters
 * change only through calls that clear it (forget_evaluation). */
static int evaluate(Instance *c, double t, const double *x) {
    const double *u = rc_inputs_at(c, t);
    Evaluation *e = &c->eval;
    if (e->valid && e->t == t && same(e->x, x, model_info.nx) && same(e->u, u, model_info.nu) &&
        same(e->m, c->m, model_info.nm)) {
        e->reused++;
        return 0;
    }
    e->valid = 0;
    c->arg[0] = &t; c->arg[1] = x; c->arg[2] = u; c->arg[3] = c->p; c->arg[4] = c->m;
    c->res[0] = e->xdot; c->res[1] = e->y; c->res[2] = e->holds; c->res[3] = e->values;
    e->evaluations++;
    if (model_evaluate(c->arg, c->res, c->iw, c->w, 0)) return -1;
    e->t = t;
    if (model_info.nx) memcpy(e->x, x, sizeof(double) * (size_t)model_info.nx);
    if (model_info.nu) memcpy(e->u, u, sizeof(double) * (size_t)model_info.nu);
    if (model_info.nm) memcpy(e->m, c->m, sizeof(double) * (size_t)model_info.nm);
    e->valid = 1;
    e->outputs_fresh = 1;
    return 0;
}

static void swap_buffers(double **a, double **b) {
    double *kept = *a;
    *a = *b;
    *b = kept;
}

void rc_forget_evaluation(Instance *c) {
    c->eval.valid = 0;
    c->gain_valid = 0;
}

static int rhs(void *ctx, double t, const double *x, double *xdot) {
    Instance *c = ctx;
    if (evaluate(c, t, x)) return -1;
    if (model_info.nx) memcpy(xdot, c->eval.xdot, sizeof(double) * (size_t)model_info.nx);
    return 0;
}

/* dfdt = t_explicit, plus dfdu . u_der while the inputs are interpolated (held: t_explicit, bit for bit). */
static void rates_into(const Instance *c, double *dfdt) {
    int nx = model_info.nx;
    if (nx) memcpy(dfdt, c->t_explicit, sizeof(double) * (size_t)nx);
    if (!c->interpolating) return;
    for (int j = 0; j < model_info.nu; j++) {
        double rate = c->u_der[j];
        if (rate == 0.0) continue;
        const double *column = c->dfdu + (size_t)nx * j;
        for (int i = 0; i < nx; i++) dfdt[i] += column[i] * rate;
    }
}

/* Relative step of the forward differences of dfdu: the sinkage solves converge to 1e-10, so a
 * step of 1e-6 keeps their noise at 1e-4 of a column and its truncation error about as small. */
#define INPUT_DIFFERENCE 1e-6

/* dfdu's columns of the inputs that ramp (u_der != 0) at (t, x), by forward differences from the
 * instance's evaluation there (the differences' own go to the fd_ scratch); the others marked
 * unknown. */
static int input_columns(Instance *c, double t, const double *x) {
    int nx = model_info.nx, nu = model_info.nu;
    for (int j = 0; j < nu; j++) c->dfdu_valid[j] = 0.0;
    if (!c->interpolating || nx == 0) return 0;
    if (evaluate(c, t, x)) return -1;
    const double *base = c->eval.xdot;
    if (nu) memcpy(c->u_fd, rc_inputs_at(c, t), sizeof(double) * (size_t)nu);
    for (int j = 0; j < nu; j++) {
        if (c->u_der[j] == 0.0) continue;
        double held = c->u_fd[j];
        c->u_fd[j] = held + INPUT_DIFFERENCE * fmax(fabs(held), 1.0);
        double delta = c->u_fd[j] - held;
        c->arg[0] = &t; c->arg[1] = x; c->arg[2] = c->u_fd; c->arg[3] = c->p; c->arg[4] = c->m;
        c->res[0] = c->fd_xdot; c->res[1] = c->fd_y; c->res[2] = c->fd_holds; c->res[3] = c->fd_values;
        c->eval.evaluations++;
        int failed = model_evaluate(c->arg, c->res, c->iw, c->w, 0);
        c->u_fd[j] = held;
        if (failed || !rc_all_finite(c->fd_xdot, nx)) return -1;
        double *column = c->dfdu + (size_t)nx * j;
        for (int i = 0; i < nx; i++) column[i] = (c->fd_xdot[i] - base[i]) / delta;
        c->dfdu_valid[j] = 1.0;
    }
    return 0;
}

static int jacobian(void *ctx, double t, const double *x, double *dfdx, double *dfdt) {
    Instance *c = ctx;
    if (input_columns(c, t, x)) return -1;
    c->arg[0] = &t; c->arg[1] = x; c->arg[2] = rc_inputs_at(c, t); c->arg[3] = c->p; c->arg[4] = c->m;
    c->res[0] = dfdx; c->res[1] = c->t_explicit;
    if (model_ode_jacobian(c->arg, c->res, c->iw, c->w, 0)) return -1;
    rates_into(c, dfdt);
    return 0;
}

void rc_input_rates(Instance *c) {
    if (!c->solver.jac_valid) return; /* the step begins with a new Jacobian, and dfdt with it */
    if (c->interpolating)
        for (int j = 0; j < model_info.nu; j++)
            if (c->u_der[j] != 0.0 && c->dfdu_valid[j] == 0.0) {
                c->solver.jac_valid = 0; /* an input that did not ramp at the last Jacobian now does */
                return;
            }
    rates_into(c, c->solver.T);
}

/* States whose start value is an expression of the parameters, unless the user set them. */
static Status initial_states(Instance *c, int f) {
    int any = 0;
    for (int i = 0; i < model_info.nx; i++) any |= model_info.x_start_calculated[i] && !c->x_set[i];
    if (!any) return STATUS_OK;
    double *x0 = c->sens_x; /* scratch of size nx */
    c->arg[0] = c->p;
    c->res[0] = x0;
    if (model_initial(c->arg, c->res, c->iw, c->w, 0) || !rc_all_finite(x0, model_info.nx))
        return rc_fail(c, f, BROKEN, "the start values of the states are not finite for these parameters");
    for (int i = 0; i < model_info.nx; i++)
        if (model_info.x_start_calculated[i] && !c->x_set[i]) c->x[i] = x0[i];
    return STATUS_OK;
}

/* Every parameter finite (NaN and infinities pass no range check). */
static Status check_parameters(Instance *c, int f) {
    for (int i = 0; i < model_info.np; i++)
        if (!isfinite(c->p[i]))
            return rc_fail(c, f, BROKEN, "parameter %s = %g: expected a finite value", model_info.real_names[i], c->p[i]);
    return STATUS_OK;
}

/* The model's asserts as last evaluated with the outputs: each one that does not hold is
 * reported with the values its condition reads; an error-level one breaks the instance. */
static Status check_asserts(Instance *c, int f) {
    Status status = STATUS_OK;
    for (int i = 0; i < model_info.n_asserts; i++) {
        if (c->holds[i] != 0.0) continue;
        char text[800];
        size_t used = (size_t)snprintf(text, sizeof text, "%s (", model_info.assert_messages[i]);
        for (int k = model_info.assert_value_start[i]; k < model_info.assert_value_start[i + 1]; k++)
            if (used < sizeof text)
                used += (size_t)snprintf(text + used, sizeof text - used, "%s%s = %.10g",
                                         k > model_info.assert_value_start[i] ? ", " : "",
                                         model_info.assert_value_names[k], c->assert_values[k]);
        if (used < sizeof text) snprintf(text + used, sizeof text - used, ") at t = %.10g", c->t);
        if (model_info.assert_is_error[i]) {
            status = rc_fail(c, f, BROKEN, "%s", text);
        } else {
            rc_log(c, STATUS_WARNING, "logStatusWarning", "%s: %s", c->layer->function_name(f), text);
            if (status == STATUS_OK) status = STATUS_WARNING;
        }
    }
    return status;
}

Status rc_update(Instance *c, int f, int need_xdot, int need_y) {
    if (c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) {
        if (check_parameters(c, f) != STATUS_OK || initial_states(c, f) != STATUS_OK) return STATUS_ERROR;
    }
    Status status = STATUS_OK;
    if ((need_y && !c->y_valid) || (need_xdot && !c->xdot_valid)) {
        int failed = evaluate(c, c->t, c->x);
        Evaluation *e = &c->eval;
        if (!failed) {
            /* The evaluation's outputs become the instance's by exchanging the buffers (a leg-wheel
             * rover's 2033 values each step); asked again at the same point, the instance holds them
             * already. The buffers have the same sizes (outputs_alloc). */
            if (e->outputs_fresh) {
                swap_buffers(&c->y, &e->y);
                swap_buffers(&c->holds, &e->holds);
                swap_buffers(&c->assert_values, &e->values);
                e->outputs_fresh = 0;
            }
            if (model_info.nx) memcpy(c->xdot, e->xdot, sizeof(double) * (size_t)model_info.nx);
        }
        Status checked = failed ? STATUS_OK : check_asserts(c, f);
        if (checked == STATUS_ERROR) return STATUS_ERROR;
        if (failed || !rc_all_finite(c->y, model_info.ny))
            return rc_fail(c, f, BROKEN, "the outputs are not finite at t = %.17g", c->t);
        /* After the outputs: a parameter out of range is reported by its assert, not as a
         * non-finite derivative. */
        if (need_xdot && !rc_all_finite(c->xdot, model_info.nx))
            return rc_fail(c, f, BROKEN, "the derivatives are not finite at t = %.17g", c->t);
        c->y_valid = 1;
        c->xdot_valid = 1;
        status = checked;
    }
    return status;
}

/* After a completed step: each memory takes the value of its variable at the step's end (the
 * outputs, valid after update). The outputs stay valid: they were computed at this point. */
void rc_remember(Instance *c) {
    for (int i = 0; i < model_info.nm; i++) c->m[i] = c->y[model_info.m_source[i]];
}

void rc_invalidate(Instance *c) {
    c->xdot_valid = 0;
    c->y_valid = 0;
    c->solver.f0_valid = 0;
    c->gain_valid = 0;
    c->f0_updated = 0;
}

static void set_defaults(Instance *c) {
    memcpy(c->p, model_info.p_default, sizeof(double) * model_info.np);
    memcpy(c->u, model_info.u_default, sizeof(double) * model_info.nu);
    for (int i = 0; i < model_info.nu; i++) c->u_der[i] = 0.0;
    c->interpolating = 0;
    memcpy(c->x, model_info.x_start, sizeof(double) * model_info.nx);
    for (int i = 0; i < model_info.nx; i++) c->x_set[i] = 0.0;
    memcpy(c->m, model_info.m_default, sizeof(double) * model_info.nm);
    c->rtol = DEFAULT_RTOL;
    c->max_step = DEFAULT_MAX_STEP;
    c->t = 0.0;
    c->has_stop = 0;
    c->mode = MODE_INSTANTIATED;
    c->solver.h = 0.0;
    c->solver.h_entry = 0.0;
    c->solver.jac_valid = 0;
    c->solver.steps = c->solver.rejected = c->solver.jacobians = c->solver.rhs_calls = 0;
    c->eval.evaluations = c->eval.reused = 0;
    c->t_step = 0.0;
    c->h_step = 0.0;
    rc_forget_evaluation(c);
    rc_invalidate(c);
}

void rc_free(Instance *c) {
    if (!c) return;
    void (*release)(void *) = c->release;
    void *blocks[] = {c->name, c->p, c->x, c->m, c->u, c->u_der, c->u_step, c->xdot, c->y, c->x_set, c->holds, c->assert_values,
                      (void *)c->arg, c->res, c->iw, c->w, c->seed_x, c->seed_u, c->sens_x, c->sens_y, c->gain,
                      c->t_explicit, c->dfdu, c->dfdu_valid, c->u_fd, c->fd_xdot, c->fd_y, c->fd_holds,
                      c->fd_values, c->eval.x, c->eval.u, c->eval.m, c->eval.xdot, c->eval.y, c->eval.holds, c->eval.values};
    for (size_t i = 0; i < sizeof(blocks) / sizeof(blocks[0]); i++) if (blocks[i]) release(blocks[i]);
    ode23s_free(&c->solver, release);
    release(c);
}

static casadi_work const WORKS[] = {model_evaluate_work, model_initial_work,
                                    model_ode_jacobian_work, model_directional_work, model_input_gain_work};

/* What model_evaluate writes: the derivatives, the outputs, the asserts' conditions and values. */
static void outputs_alloc(void *(*alloc)(size_t, size_t), double **xdot, double **y, double **holds,
                          double **values) {
    int n_values = model_info.assert_value_start[model_info.n_asserts];
    *xdot = alloc(model_info.nx ? (size_t)model_info.nx : 1, sizeof(double));
    *y = alloc(model_info.ny ? (size_t)model_info.ny : 1, sizeof(double));
    *holds = alloc(model_info.n_asserts ? (size_t)model_info.n_asserts : 1, sizeof(double));
    *values = alloc(n_values ? (size_t)n_values : 1, sizeof(double));
}

static int allocate_work(Instance *c) {
    casadi_int sz_arg = 7, sz_res = 4, sz_iw = 0, sz_w = 0;
    for (size_t i = 0; i < sizeof(WORKS) / sizeof(WORKS[0]); i++) {
        casadi_int a = 0, r = 0, iw = 0, w = 0;
        WORKS[i](&a, &r, &iw, &w);
        if (a > sz_arg) sz_arg = a;
        if (r > sz_res) sz_res = r;
        if (iw > sz_iw) sz_iw = iw;
        if (w > sz_w) sz_w = w;
    }
    void *(*alloc)(size_t, size_t) = c->allocate;
    size_t nx = model_info.nx ? model_info.nx : 1, nu = model_info.nu ? model_info.nu : 1;
    size_t np = model_info.np ? model_info.np : 1, ny = model_info.ny ? model_info.ny : 1;
    size_t nm = model_info.nm ? model_info.nm : 1;
    c->p = alloc(np, sizeof(double));
    c->m = alloc(nm, sizeof(double));
    c->x = alloc(nx, sizeof(double));
    c->u = alloc(nu, sizeof(double));
    c->u_der = alloc(nu, sizeof(double));
    c->u_step = alloc(nu, sizeof(double));
    c->xdot = alloc(nx, sizeof(double));
    c->y = alloc(ny, sizeof(double));
    c->x_set = alloc(nx, sizeof(double));
    int n_values = model_info.assert_value_start[model_info.n_asserts];
    c->holds = alloc(model_info.n_asserts ? (size_t)model_info.n_asserts : 1, sizeof(double));
    c->assert_values = alloc(n_values ? (size_t)n_values : 1, sizeof(double));
    c->arg = alloc((size_t)sz_arg, sizeof(double *));
    c->res = alloc((size_t)sz_res, sizeof(double *));
    c->iw = alloc((size_t)sz_iw + 1, sizeof(casadi_int));
    c->w = alloc((size_t)sz_w + 1, sizeof(double));
    c->seed_x = alloc(nx, sizeof(double));
    c->seed_u = alloc(nu, sizeof(double));
    c->sens_x = alloc(nx, sizeof(double));
    c->sens_y = alloc(ny, sizeof(double));
    c->gain = alloc(nx * nu, sizeof(double));
    c->t_explicit = alloc(nx, sizeof(double));
    c->dfdu = alloc(nx * nu, sizeof(double));
    c->dfdu_valid = alloc(nu, sizeof(double));
    c->u_fd = alloc(nu, sizeof(double));
    outputs_alloc(alloc, &c->fd_xdot, &c->fd_y, &c->fd_holds, &c->fd_values);
    Evaluation *e = &c->eval;
    e->x = alloc(nx, sizeof(double));
    e->u = alloc(nu, sizeof(double));
    e->m = alloc(nm, sizeof(double));
    outputs_alloc(alloc, &e->xdot, &e->y, &e->holds, &e->values);
    int solver_failed = ode23s_alloc(&c->solver, model_info.nx, alloc);
    return c->p && c->m && c->x && c->u && c->u_der && c->u_step && c->xdot && c->y && c->x_set && c->holds && c->assert_values && c->arg && c->res && c->iw && c->w && c->seed_x &&
           c->seed_u && c->sens_x && c->sens_y && c->gain && c->t_explicit && c->dfdu && c->dfdu_valid && c->u_fd && c->fd_xdot &&
           c->fd_y && c->fd_holds && c->fd_values && e->x && e->u && e->xdot && e->y && e->holds && e->values &&
           e->m && !solver_failed;
}


/* ---- an instance ------------------------------------------------------------------------- */
Instance *rc_new(const char *name, Kind kind, int logging, const Layer *layer, void *layer_data,
                 void *(*allocate)(size_t, size_t), void (*release)(void *)) {
    Instance *c = allocate(1, sizeof(Instance));
    if (!c) return NULL;
    c->layer = layer;
    c->layer_data = layer_data;
    c->allocate = allocate;
    c->release = release;
    c->kind = kind;
    c->log_mask = logging ? ALL_CATEGORIES : DEFAULT_CATEGORIES;
    c->name = allocate(strlen(name) + 1, 1);
    if (c->name) memcpy(c->name, name, strlen(name) + 1);
    if (!c->name || !allocate_work(c)) {
        rc_free(c);
        return NULL;
    }
    c->solver.rhs = rhs;
    c->solver.jacobian = jacobian;
    c->solver.ctx = c;
    c->solver.max_steps = 1000000;
    set_defaults(c);
    return c;
}

void rc_reset(Instance *c) { set_defaults(c); }

Status rc_setup(Instance *c, int f, int tolerance_defined, double tolerance, double start, int stop_defined,
                double stop) {
    if (tolerance_defined && !(tolerance > 0.0 && tolerance < 1.0))
        return rc_fail(c, f, REJECTED, "tolerance %g: expected 0 < tolerance < 1", tolerance);
    if (!isfinite(start))
        return rc_fail(c, f, REJECTED, "start time %g is not finite", start);
    if (stop_defined && !(stop >= start))
        return rc_fail(c, f, REJECTED, "stop time %g before start time %g", stop, start);
    if (tolerance_defined) c->rtol = tolerance;
    c->t = start;
    c->has_stop = stop_defined;
    c->t_stop = stop;
    rc_invalidate(c);
    return STATUS_OK;
}

Status rc_enter_initialization(Instance *c) {
    c->mode = MODE_INITIALIZATION;
    rc_invalidate(c);
    return STATUS_OK;
}

Status rc_exit_initialization(Instance *c, int f) {
    Status status = rc_update(c, f, 1, 1);
    if (status == STATUS_ERROR) return STATUS_ERROR;
    c->mode = c->kind == KIND_MODEL_EXCHANGE ? MODE_EVENT : MODE_STEP;
    c->solver.h = 0.0;
    c->solver.h_entry = 0.0;
    c->solver.f0_valid = 0;
    c->solver.jac_valid = 0;
    return status;
}

Status rc_terminate(Instance *c) {
    if (c->kind == KIND_CO_SIMULATION)
        rc_log(c, STATUS_OK, "logStatistics", "integrator: %ld steps, %ld rejected, %ld Jacobians, %ld derivative "
               "requests; model: %llu evaluations, %llu requests answered by the last one",
               c->solver.steps, c->solver.rejected, c->solver.jacobians, c->solver.rhs_calls,
               c->eval.evaluations, c->eval.reused);
    c->mode = MODE_TERMINATED;
    return STATUS_OK;
}

/* ---- values ----------------------------------------------------------------------------- */
/* The runtime's counters, in the order of codegen.STATISTICS. */
static double statistic(const Instance *c, int k) {
    switch (k) {
    case 0: return (double)c->eval.evaluations;
    case 1: return (double)c->eval.reused;
    case 2: return (double)c->solver.jacobians;
    case 3: return (double)c->solver.steps;
    case 4: return (double)c->solver.rejected;
    default: return (double)c->eval.updated;
    }
}

Status rc_get_real(Instance *c, int f, const unsigned int vr[], size_t nvr, double value[]) {
    NOT_NULL(f, vr, nvr);
    NOT_NULL(f, value, nvr);
    int need_xdot = 0, need_y = 0;
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < 0)
            return rc_fail(c, f, REJECTED, "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        need_xdot |= r >= off_dx() && r < off_u();
        need_y |= r >= off_y() && r < vr_rtol();
    }
    /* In the error state the values are shown as they are, for inspection. */
    if (c->mode != MODE_ERROR && rc_update(c, f, need_xdot, need_y) == STATUS_ERROR) return STATUS_ERROR;
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < off_x()) value[i] = c->p[r];
        else if (r < off_dx()) value[i] = c->x[r - off_x()];
        else if (r < off_u()) value[i] = c->xdot[r - off_dx()];
        else if (r < off_y()) value[i] = c->u[r - off_u()];
        else if (r < off_m()) value[i] = c->y[r - off_y()];
        else if (r < vr_rtol()) value[i] = c->m[r - off_m()];
        else if (r == vr_rtol()) value[i] = c->rtol;
        else if (r == vr_max_step()) value[i] = c->max_step;
        else value[i] = statistic(c, r - vr_statistics());
    }
    return STATUS_OK;
}

/* Why the Real ``r`` cannot take ``value`` now, or NULL if it can. */
static const char *set_real_refusal(const Instance *c, int r, double value) {
    int initializing = c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION;
    if (!isfinite(value)) return "expected a finite value";
    if (r < off_x() && !initializing)
        return "is a fixed parameter: it can only be set before the end of initialization";
    if (r >= off_x() && r < off_dx() && !initializing)
        return "is a state: set it before the end of initialization (Model Exchange: as a continuous state)";
    if (r >= off_dx() && r < off_u()) return "is a derivative (calculated): it cannot be set";
    if (r >= off_y() && r < off_m()) return "is calculated by the model: it cannot be set";
    if (r >= off_m() && r < vr_rtol()) return "is kept by the runtime from the previous step: it cannot be set";
    if (r == vr_rtol() && !(value > 0.0 && value < 1.0)) return "expected 0 < tolerance < 1";
    if (r == vr_max_step() && !(value >= 0.0)) return "expected >= 0 (0: no limit besides the communication step)";
    if (r >= vr_statistics()) return "is a statistic of the runtime: it cannot be set";
    return NULL;
}

/* d xdot / d u in the columns of the affine inputs (model_info.u_affine) where the other inputs
 * and the parameters are now (model_input_gain: for those inputs a function of the parameters and
 * the other inputs only, a few hundred operations); 0 on success. */
static int input_gain(Instance *c) {
    if (c->gain_valid) return 0;
    double t = c->t;
    c->arg[0] = &t; c->arg[1] = c->x; c->arg[2] = c->u; c->arg[3] = c->p; c->arg[4] = c->m;
    c->res[0] = c->gain;
    if (model_input_gain(c->arg, c->res, c->iw, c->w, 0) || !rc_all_finite(c->gain, model_info.nx * model_info.nu))
        return -1;
    c->gain_valid = 1;
    return 0;
}

/* Whether the value of input ``j`` would change (any bit: -0.0 and 0.0 differ) by ``value``. */
static int changes_input(Instance *c, int j, double value) {
    return memcmp(&c->u[j], &value, sizeof value) != 0;
}

/* Whether setting ``vr`` to ``value`` keeps the Co-Simulation integrator's derivatives at the
 * current point (updated for the change, rc_set_real): every one an input set to the bits it has
 * or one the derivatives are affine in, and the derivatives known at the current point (input
 * derivatives set for the next step do not change them there). Saves the evaluation the next step
 * would begin with: a controller changes the motor torques every step, and set-points ramped over
 * a step end it where they are set next. */
static int keeps_derivatives(Instance *c, const unsigned int vr[], size_t nvr, const double value[]) {
    if (c->kind != KIND_CO_SIMULATION || c->mode != MODE_STEP || !c->solver.f0_valid) return 0;
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (!(r >= off_u() && r < off_y())) return 0;
        if (!model_info.u_affine[r - off_u()] && changes_input(c, r - off_u(), value[i])) return 0;
    }
    return input_gain(c) == 0;
}

/* Whether setting ``vr`` to ``value`` changes nothing: inputs only, each set to the bits it has. */
static int changes_nothing(Instance *c, const unsigned int vr[], size_t nvr, const double value[]) {
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (!(r >= off_u() && r < off_y()) || changes_input(c, r - off_u(), value[i])) return 0;
    }
    return 1;
}

Status rc_set_real(Instance *c, int f, const unsigned int vr[], size_t nvr, const double value[]) {
    NOT_NULL(f, vr, nvr);
    NOT_NULL(f, value, nvr);
    /* Check everything first, so a rejected call changes nothing. */
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < 0)
            return rc_fail(c, f, REJECTED, "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        const char *refusal = set_real_refusal(c, r, value[i]);
        if (refusal) return rc_fail(c, f, REJECTED, "%s = %g: %s", real_name(vr[i]), value[i], refusal);
    }
    if (changes_nothing(c, vr, nvr, value)) return STATUS_OK;
    int keep = keeps_derivatives(c, vr, nvr, value);
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < off_x()) { c->p[r] = value[i]; rc_forget_evaluation(c); }
        else if (r < off_dx()) { c->x[r - off_x()] = value[i]; c->x_set[r - off_x()] = 1.0; }
        else if (r >= off_u() && r < off_y()) {
            int j = r - off_u();
            double du = value[i] - c->u[j];
            if (keep && du != 0.0)
                for (int k = 0; k < model_info.nx; k++) c->solver.F0[k] += c->gain[k + (size_t)model_info.nx * j] * du;
            c->u[j] = value[i];
        }
        else if (r == vr_rtol()) c->rtol = value[i];
        else if (r == vr_max_step()) c->max_step = value[i];
    }
    if (keep) { /* the next step begins from the updated derivatives; outputs are evaluated again */
        c->xdot_valid = 0;
        c->y_valid = 0;
        c->f0_updated = 1;
    } else rc_invalidate(c);
    return STATUS_OK;
}

/* The models have Real variables only: the other types' get/set accept empty requests. */

/* ---- directional derivatives ------------------------------------------------------------ */
static Status seed(Instance *c, int f, const unsigned int known[], size_t n, const double dv[]) {
    for (int i = 0; i < model_info.nx; i++) c->seed_x[i] = 0.0;
    for (int i = 0; i < model_info.nu; i++) c->seed_u[i] = 0.0;
    for (size_t k = 0; k < n; k++) {
        int r = real_index(known[k]);
        if (r >= off_x() && r < off_dx()) c->seed_x[r - off_x()] += dv[k];
        else if (r >= off_u() && r < off_y()) c->seed_u[r - off_u()] += dv[k];
        else return rc_fail(c, f, REJECTED, "known %u (%s): expected a state or an input",
                         known[k], real_name(known[k]));
    }
    return STATUS_OK;
}

Status rc_directional(Instance *c, int f, const unsigned int vUnknown_ref[], size_t nUnknown,
                      const unsigned int vKnown_ref[], size_t nKnown, const double dvKnown[], double dvUnknown[]) {
    const int F = f;
    NOT_NULL(F, vUnknown_ref, nUnknown);
    NOT_NULL(F, dvUnknown, nUnknown);
    NOT_NULL(F, vKnown_ref, nKnown);
    NOT_NULL(F, dvKnown, nKnown);
    if (seed(c, F, vKnown_ref, nKnown, dvKnown) != STATUS_OK) return STATUS_ERROR;
    for (size_t k = 0; k < nUnknown; k++) {
        int r = real_index(vUnknown_ref[k]);
        int allowed = (r >= off_x() && r < off_u()) ||  /* a state or a derivative */
                      (r >= off_y() && r < off_m() && model_info.y_is_output[r - off_y()]);
        if (!allowed)
            return rc_fail(c, F, REJECTED, "unknown %u (%s): expected a state, a derivative or an output",
                        vUnknown_ref[k], real_name(vUnknown_ref[k]));
    }
    if (c->mode == MODE_INITIALIZATION && initial_states(c, F) != STATUS_OK) return STATUS_ERROR;
    double t = c->t;
    c->arg[0] = &t; c->arg[1] = c->x; c->arg[2] = c->u; c->arg[3] = c->p; c->arg[4] = c->m;
    c->arg[5] = c->seed_x; c->arg[6] = c->seed_u;
    c->res[0] = c->sens_x; c->res[1] = c->sens_y;
    if (model_directional(c->arg, c->res, c->iw, c->w, 0) || !rc_all_finite(c->sens_x, model_info.nx) ||
        !rc_all_finite(c->sens_y, model_info.ny))
        return rc_fail(c, F, BROKEN, "the directional derivative is not finite at t = %.17g", c->t);
    for (size_t k = 0; k < nUnknown; k++) {
        int r = real_index(vUnknown_ref[k]);
        if (r < off_dx()) dvUnknown[k] = c->seed_x[r - off_x()];
        else if (r < off_u()) dvUnknown[k] = c->sens_x[r - off_dx()];
        else dvUnknown[k] = c->sens_y[r - off_y()];
    }
    return STATUS_OK;
}


/* ---- Model Exchange --------------------------------------------------------------------- */
Status rc_completed_integrator_step(Instance *c, int f) {
    Status status = rc_update(c, f, 0, 1); /* the asserts */
    if (status != STATUS_ERROR) rc_remember(c);
    return status;
}

Status rc_set_time(Instance *c, int f, double time) {
    if (!isfinite(time)) return rc_fail(c, f, REJECTED, "time %g is not finite", time);
    c->t = time;
    rc_invalidate(c);
    return STATUS_OK;
}

static Status check_nx(Instance *c, int f, size_t nx) {
    if (nx != (size_t)model_info.nx) return rc_fail(c, f, REJECTED, "nx = %zu: expected %d", nx, model_info.nx);
    return STATUS_OK;
}

Status rc_set_states(Instance *c, int f, const double x[], size_t nx) {
    if (check_nx(c, f, nx) != STATUS_OK) return STATUS_ERROR;
    NOT_NULL(f, x, nx);
    for (size_t i = 0; i < nx; i++)
        if (!isfinite(x[i]))
            return rc_fail(c, f, REJECTED, "%s = %g: expected a finite value",
                           real_name((unsigned int)(off_x() + (int)i)), x[i]);
    memcpy(c->x, x, sizeof(double) * nx);
    rc_invalidate(c);
    return STATUS_OK;
}

Status rc_get_derivatives(Instance *c, int f, double derivatives[], size_t nx) {
    if (check_nx(c, f, nx) != STATUS_OK) return STATUS_ERROR;
    NOT_NULL(f, derivatives, nx);
    if (rc_update(c, f, 1, 0) != STATUS_OK) return STATUS_ERROR;
    memcpy(derivatives, c->xdot, sizeof(double) * nx);
    return STATUS_OK;
}

Status rc_get_states(Instance *c, int f, double x[], size_t nx) {
    if (check_nx(c, f, nx) != STATUS_OK) return STATUS_ERROR;
    NOT_NULL(f, x, nx);
    if ((c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) && initial_states(c, f) != STATUS_OK)
        return STATUS_ERROR;
    memcpy(x, c->x, sizeof(double) * nx);
    return STATUS_OK;
}

Status rc_get_nominals(Instance *c, int f, double x_nominal[], size_t nx) {
    if (check_nx(c, f, nx) != STATUS_OK) return STATUS_ERROR;
    NOT_NULL(f, x_nominal, nx);
    for (size_t i = 0; i < nx; i++) x_nominal[i] = 1.0;
    return STATUS_OK;
}

