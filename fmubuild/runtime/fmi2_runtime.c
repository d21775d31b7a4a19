/* rover-cosim FMI 2.0 runtime: Model Exchange and Co-Simulation around a generated model
 * (model.h). All state lives in the instance: many instances per process and per thread.
 *
 * Shape (after the Modelica Association's Reference-FMUs):
 * - FUNCTIONS: one table with, per FMI function, its name and the instance states in which it may
 *   be called; every function starts with ENTER(F), which checks the instance pointer and the
 *   state against that table.
 * - fail(): the one error path. It logs "<function>: <message>" under logStatusError and returns
 *   fmi2Error; with BROKEN it also puts the instance into the error state (a failed model
 *   evaluation or integration: only inspection, fmi2SetFMUstate, fmi2Reset, fmi2Terminate and
 *   fmi2FreeInstance are allowed then). A REJECTED call (bad argument, illegal state) is refused
 *   before anything changes: the instance stays where it was.
 * - Every array argument is checked for NULL, every value reference against the range (as an
 *   unsigned number), every serialized FMU state against its size, layout and checksum.
 * Nothing aborts, nothing is read or written out of bounds whatever the caller passes. */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"
#include "ode23s.h"

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_EVENT, MODE_CONTINUOUS, MODE_STEP,
               MODE_TERMINATED, MODE_ERROR, MODE_COUNT } Mode;

static const char *const MODE_NAMES[MODE_COUNT] = {"instantiated", "initialization", "event", "continuous-time",
                                                   "step-complete", "terminated", "error"};

/* ---- the FMI functions and the states they may be called in ---------------------------- */
#define S(m) (1u << (m))
#define ANY_MODE (S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | S(MODE_EVENT) | S(MODE_CONTINUOUS) | \
                  S(MODE_STEP) | S(MODE_TERMINATED) | S(MODE_ERROR))
#define RUNNING (S(MODE_EVENT) | S(MODE_CONTINUOUS) | S(MODE_STEP))
#define NOT_ERROR (ANY_MODE & ~S(MODE_ERROR))
#define ME_MODES (S(MODE_EVENT) | S(MODE_CONTINUOUS))

typedef enum {
    F_SetDebugLogging, F_FreeInstance, F_SetupExperiment, F_EnterInitializationMode, F_ExitInitializationMode,
    F_Terminate, F_Reset, F_GetReal, F_SetReal, F_GetInteger, F_GetBoolean, F_GetString, F_SetInteger,
    F_SetBoolean, F_SetString, F_GetFMUstate, F_SetFMUstate, F_FreeFMUstate, F_SerializedFMUstateSize,
    F_SerializeFMUstate, F_DeSerializeFMUstate, F_GetDirectionalDerivative, F_EnterEventMode,
    F_NewDiscreteStates, F_EnterContinuousTimeMode, F_CompletedIntegratorStep, F_SetTime,
    F_SetContinuousStates, F_GetDerivatives, F_GetEventIndicators, F_GetContinuousStates,
    F_GetNominalsOfContinuousStates, F_SetRealInputDerivatives, F_GetRealOutputDerivatives, F_DoStep,
    F_CancelStep, F_GetStatus, F_GetRealStatus, F_GetIntegerStatus, F_GetBooleanStatus, F_GetStringStatus,
    F_COUNT
} Function;

static const struct {
    const char *name;
    unsigned allowed; /* bit set of Mode */
} FUNCTIONS[F_COUNT] = {
    [F_SetDebugLogging] = {"fmi2SetDebugLogging", ANY_MODE},
    [F_FreeInstance] = {"fmi2FreeInstance", ANY_MODE},
    [F_SetupExperiment] = {"fmi2SetupExperiment", S(MODE_INSTANTIATED)},
    [F_EnterInitializationMode] = {"fmi2EnterInitializationMode", S(MODE_INSTANTIATED)},
    [F_ExitInitializationMode] = {"fmi2ExitInitializationMode", S(MODE_INITIALIZATION)},
    [F_Terminate] = {"fmi2Terminate", RUNNING | S(MODE_TERMINATED) | S(MODE_ERROR)},
    [F_Reset] = {"fmi2Reset", ANY_MODE},
    [F_GetReal] = {"fmi2GetReal", ANY_MODE},
    [F_SetReal] = {"fmi2SetReal", S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING},
    [F_GetInteger] = {"fmi2GetInteger", ANY_MODE},
    [F_GetBoolean] = {"fmi2GetBoolean", ANY_MODE},
    [F_GetString] = {"fmi2GetString", ANY_MODE},
    [F_SetInteger] = {"fmi2SetInteger", S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING},
    [F_SetBoolean] = {"fmi2SetBoolean", S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING},
    [F_SetString] = {"fmi2SetString", S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING},
    [F_GetFMUstate] = {"fmi2GetFMUstate", NOT_ERROR},
    [F_SetFMUstate] = {"fmi2SetFMUstate", ANY_MODE},
    [F_FreeFMUstate] = {"fmi2FreeFMUstate", ANY_MODE},
    [F_SerializedFMUstateSize] = {"fmi2SerializedFMUstateSize", ANY_MODE},
    [F_SerializeFMUstate] = {"fmi2SerializeFMUstate", ANY_MODE},
    [F_DeSerializeFMUstate] = {"fmi2DeSerializeFMUstate", ANY_MODE},
    [F_GetDirectionalDerivative] = {"fmi2GetDirectionalDerivative", S(MODE_INITIALIZATION) | RUNNING},
    [F_EnterEventMode] = {"fmi2EnterEventMode", ME_MODES},
    [F_NewDiscreteStates] = {"fmi2NewDiscreteStates", S(MODE_EVENT)},
    [F_EnterContinuousTimeMode] = {"fmi2EnterContinuousTimeMode", S(MODE_EVENT)},
    [F_CompletedIntegratorStep] = {"fmi2CompletedIntegratorStep", S(MODE_CONTINUOUS)},
    [F_SetTime] = {"fmi2SetTime", ME_MODES},
    [F_SetContinuousStates] = {"fmi2SetContinuousStates", ME_MODES},
    [F_GetDerivatives] = {"fmi2GetDerivatives", S(MODE_INITIALIZATION) | ME_MODES | S(MODE_TERMINATED)},
    [F_GetEventIndicators] = {"fmi2GetEventIndicators", NOT_ERROR},
    [F_GetContinuousStates] = {"fmi2GetContinuousStates", NOT_ERROR},
    [F_GetNominalsOfContinuousStates] = {"fmi2GetNominalsOfContinuousStates", NOT_ERROR},
    [F_SetRealInputDerivatives] = {"fmi2SetRealInputDerivatives",
                                   S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | S(MODE_STEP)},
    [F_GetRealOutputDerivatives] = {"fmi2GetRealOutputDerivatives", ANY_MODE},
    [F_DoStep] = {"fmi2DoStep", S(MODE_STEP)},
    [F_CancelStep] = {"fmi2CancelStep", ANY_MODE},
    [F_GetStatus] = {"fmi2GetStatus", ANY_MODE},
    [F_GetRealStatus] = {"fmi2GetRealStatus", ANY_MODE},
    [F_GetIntegerStatus] = {"fmi2GetIntegerStatus", ANY_MODE},
    [F_GetBooleanStatus] = {"fmi2GetBooleanStatus", ANY_MODE},
    [F_GetStringStatus] = {"fmi2GetStringStatus", ANY_MODE},
};

#define FMU_STATE_MAGIC 0x524f5646u /* layout 4: the interface kind, input derivatives and statistics */

/* What fmi2Get/SetFMUstate save and restore. */
typedef struct {
    unsigned magic, nx, nu, np, nm;
    int type;           /* fmi2ModelExchange or fmi2CoSimulation: a state is restored into its own kind only */
    int mode;
    int f0_valid, jac_valid, jac_current, jac_age;  /* integrator memory, so a restored run repeats exactly */
    int interpolating;  /* input derivatives set for the next step (u_der follows the inputs) */
    double t, rtol, max_step, h, t_step;
    long steps, rejected, jacobians, rhs_calls;    /* the statistics */
    unsigned long long evaluations, reused;
    uint64_t checksum;  /* FNV-1a of the header (this field zero) and the doubles that follow */
    /* followed by x[nx], u[nu], u_der[nu], p[np], x_set[nx], F0[nx], J[nx*nx], m[nm] (doubles) */
} StateHeader;

/* The last evaluation of the model (model_evaluate) and the exact point (t, x, u) and memories m
 * it was made with: asking again with the same ones reuses it. */
typedef struct {
    int valid;
    double t;
    double *x, *u, *m, *xdot, *y, *holds, *values;
    unsigned long long evaluations, reused;
} Evaluation;

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    fmi2Type type;
    unsigned log_mask;  /* bit k: LOG_CATEGORIES[k] is logged (errors always are) */
    Mode mode;
    double t, t_stop;
    int has_stop;
    double *p, *x, *u, *xdot, *y, *x_set;  /* x_set[i] != 0: the start of state i was set by the user */
    double *m;  /* memories: values of the previous step (model.h), e.g. the start of a sinkage solve */
    double *holds, *assert_values;         /* the model's asserts, evaluated with the outputs */
    double rtol, max_step;
    int xdot_valid, y_valid;
    /* Input interpolation over one communication step (fmi2SetRealInputDerivatives, order 1):
     * u(t) = u + u_der (t - t_step) while interpolating; cleared after each fmi2DoStep. */
    double *u_der, *u_step, t_step;
    int interpolating;
    /* CasADi work */
    const double **arg;
    double **res;
    casadi_int *iw;
    double *w;
    double *seed_x, *seed_u, *sens_x, *sens_y;
    Evaluation eval;
    Ode23s solver;
} Instance;

#define DEFAULT_RTOL 1e-6
#define DEFAULT_MAX_STEP 0.0

/* ---- value references ------------------------------------------------------------------- */
static int off_x(void) { return model_info.np; }
static int off_dx(void) { return model_info.np + model_info.nx; }
static int off_u(void) { return model_info.np + 2 * model_info.nx; }
static int off_y(void) { return model_info.np + 2 * model_info.nx + model_info.nu; }
static int off_m(void) { return off_y() + model_info.ny; }
static int vr_rtol(void) { return off_m() + model_info.nm; }
static int vr_max_step(void) { return vr_rtol() + 1; }
static int vr_statistics(void) { return vr_max_step() + 1; }
#define N_STATISTICS 5 /* codegen.STATISTICS */
static int n_real(void) { return vr_statistics() + N_STATISTICS; }

/* A value reference as an index, or -1 when it is no Real variable (compared unsigned, so
 * 0xFFFFFFFF and values >= 2^31 are out of range, not negative). */
static int real_index(fmi2ValueReference vr) {
    return vr < (fmi2ValueReference)n_real() ? (int)vr : -1;
}

static const char *real_name(fmi2ValueReference vr) {
    int r = real_index(vr);
    return r >= 0 ? model_info.real_names[r] : "?";
}

/* ---- logging and the one error path -------------------------------------------------------- */
/* The log categories of the model description (fmubuild.description), in this order. */
static const char *const LOG_CATEGORIES[] = {"logStatusError", "logStatusWarning", "logStatistics"};
#define N_LOG_CATEGORIES 3
#define ALL_CATEGORIES ((1u << N_LOG_CATEGORIES) - 1u)
#define DEFAULT_CATEGORIES 3u /* without debug logging: errors and warnings */

static int log_category(const char *name) {
    for (int k = 0; k < N_LOG_CATEGORIES; k++)
        if (name && strcmp(name, LOG_CATEGORIES[k]) == 0) return k;
    return -1;
}

static void log_text(const fmi2CallbackFunctions *cb, fmi2String name, fmi2Status status, const char *category,
                     const char *text) {
    if (!cb || !cb->logger) return;
    /* The logger takes a printf format: pass the text itself with '%' doubled, so importers
     * that do not expand the variable arguments (e.g. ctypes callbacks) still get the text. */
    char escaped[2048];
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    cb->logger(cb->componentEnvironment, name ? name : "?", status, category, escaped);
}

static void log_message(Instance *c, fmi2Status status, const char *category, const char *format, ...) {
    int k = log_category(category);
    if (!c || (status != fmi2Error && (k < 0 || !(c->log_mask & (1u << k))))) return;
    char buffer[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    log_text(&c->cb, c->name, status, category, buffer);
}

typedef enum { REJECTED, BROKEN } Severity;

static fmi2Status fail(Instance *c, Function f, Severity severity, const char *format, ...) {
    char buffer[900];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    log_message(c, fmi2Error, "logStatusError", "%s: %s", FUNCTIONS[f].name, buffer);
    if (severity == BROKEN) c->mode = MODE_ERROR;
    return fmi2Error;
}

/* The instance behind a component handle, if it may call f in its state; NULL otherwise
 * (a NULL handle cannot be reported: there is no logger without an instance). */
static Instance *enter(fmi2Component component, Function f) {
    Instance *c = component;
    if (!c) return NULL;
    if (c->mode < 0 || c->mode >= MODE_COUNT || !(FUNCTIONS[f].allowed & S(c->mode))) {
        fail(c, f, REJECTED, "not allowed in the %s state",
             c->mode >= 0 && c->mode < MODE_COUNT ? MODE_NAMES[c->mode] : "unknown");
        return NULL;
    }
    return c;
}

#define ENTER(F)                       \
    Instance *c = enter(component, F); \
    if (!c) return fmi2Error

/* Arrays of n elements must not be NULL when n > 0. */
#define NOT_NULL(F, array, n) \
    if ((n) > 0 && !(array)) return fail(c, F, REJECTED, "%s is NULL (%zu elements expected)", #array, (size_t)(n))

/* ---- model evaluation ------------------------------------------------------------------- */
/* The inputs at time t: the held values, or their linear interpolation within the step. */
static const double *inputs_at(Instance *c, double t) {
    if (!c->interpolating) return c->u;
    for (int i = 0; i < model_info.nu; i++) c->u_step[i] = c->u[i] + c->u_der[i] * (t - c->t_step);
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
    const double *u = inputs_at(c, t);
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
    return 0;
}

static void forget_evaluation(Instance *c) { c->eval.valid = 0; }

static int all_finite(const double *v, int n) {
    for (int i = 0; i < n; i++) if (!isfinite(v[i])) return 0;
    return 1;
}

static int rhs(void *ctx, double t, const double *x, double *xdot) {
    Instance *c = ctx;
    if (evaluate(c, t, x)) return -1;
    if (model_info.nx) memcpy(xdot, c->eval.xdot, sizeof(double) * (size_t)model_info.nx);
    return 0;
}

static int jacobian(void *ctx, double t, const double *x, double *dfdx, double *dfdt) {
    Instance *c = ctx;
    c->arg[0] = &t; c->arg[1] = x; c->arg[2] = inputs_at(c, t); c->arg[3] = c->p; c->arg[4] = c->m;
    c->res[0] = dfdx; c->res[1] = dfdt;
    return model_ode_jacobian(c->arg, c->res, c->iw, c->w, 0);
}

/* States whose start value is an expression of the parameters, unless the user set them. */
static fmi2Status initial_states(Instance *c, Function f) {
    int any = 0;
    for (int i = 0; i < model_info.nx; i++) any |= model_info.x_start_calculated[i] && !c->x_set[i];
    if (!any) return fmi2OK;
    double *x0 = c->sens_x; /* scratch of size nx */
    c->arg[0] = c->p;
    c->res[0] = x0;
    if (model_initial(c->arg, c->res, c->iw, c->w, 0) || !all_finite(x0, model_info.nx))
        return fail(c, f, BROKEN, "the start values of the states are not finite for these parameters");
    for (int i = 0; i < model_info.nx; i++)
        if (model_info.x_start_calculated[i] && !c->x_set[i]) c->x[i] = x0[i];
    return fmi2OK;
}

/* Every parameter finite (NaN and infinities pass no range check). */
static fmi2Status check_parameters(Instance *c, Function f) {
    for (int i = 0; i < model_info.np; i++)
        if (!isfinite(c->p[i]))
            return fail(c, f, BROKEN, "parameter %s = %g: expected a finite value", model_info.real_names[i], c->p[i]);
    return fmi2OK;
}

/* The model's asserts as last evaluated with the outputs: each one that does not hold is
 * reported with the values its condition reads; an error-level one breaks the instance. */
static fmi2Status check_asserts(Instance *c, Function f) {
    fmi2Status status = fmi2OK;
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
            status = fail(c, f, BROKEN, "%s", text);
        } else {
            log_message(c, fmi2Warning, "logStatusWarning", "%s: %s", FUNCTIONS[f].name, text);
            if (status == fmi2OK) status = fmi2Warning;
        }
    }
    return status;
}

static fmi2Status update(Instance *c, Function f, int need_xdot, int need_y) {
    if (c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) {
        if (check_parameters(c, f) != fmi2OK || initial_states(c, f) != fmi2OK) return fmi2Error;
    }
    fmi2Status status = fmi2OK;
    if ((need_y && !c->y_valid) || (need_xdot && !c->xdot_valid)) {
        int failed = evaluate(c, c->t, c->x);
        Evaluation *e = &c->eval;
        size_t n_values = (size_t)model_info.assert_value_start[model_info.n_asserts];
        if (!failed) {
            if (model_info.ny) memcpy(c->y, e->y, sizeof(double) * (size_t)model_info.ny);
            if (model_info.nx) memcpy(c->xdot, e->xdot, sizeof(double) * (size_t)model_info.nx);
            if (model_info.n_asserts) memcpy(c->holds, e->holds, sizeof(double) * (size_t)model_info.n_asserts);
            if (n_values) memcpy(c->assert_values, e->values, sizeof(double) * n_values);
        }
        fmi2Status checked = failed ? fmi2OK : check_asserts(c, f);
        if (checked == fmi2Error) return fmi2Error;
        if (failed || !all_finite(c->y, model_info.ny))
            return fail(c, f, BROKEN, "the outputs are not finite at t = %.17g", c->t);
        /* After the outputs: a parameter out of range is reported by its assert, not as a
         * non-finite derivative. */
        if (need_xdot && !all_finite(c->xdot, model_info.nx))
            return fail(c, f, BROKEN, "the derivatives are not finite at t = %.17g", c->t);
        c->y_valid = 1;
        c->xdot_valid = 1;
        status = checked;
    }
    return status;
}

/* After a completed step: each memory takes the value of its variable at the step's end (the
 * outputs, valid after update). The outputs stay valid: they were computed at this point. */
static void remember(Instance *c) {
    for (int i = 0; i < model_info.nm; i++) c->m[i] = c->y[model_info.m_source[i]];
}

static void invalidate(Instance *c) {
    c->xdot_valid = 0;
    c->y_valid = 0;
    c->solver.f0_valid = 0;
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
    c->solver.jac_valid = 0;
    c->solver.steps = c->solver.rejected = c->solver.jacobians = c->solver.rhs_calls = 0;
    c->eval.evaluations = c->eval.reused = 0;
    c->t_step = 0.0;
    forget_evaluation(c);
    invalidate(c);
}

/* ---- common functions ------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    ENTER(F_SetDebugLogging);
    NOT_NULL(F_SetDebugLogging, categories, nCategories);
    unsigned listed = 0;
    for (size_t i = 0; i < nCategories; i++) {
        int k = log_category(categories[i]);
        if (k < 0)
            return fail(c, F_SetDebugLogging, REJECTED, "log category %.100s: expected one of logStatusError, "
                        "logStatusWarning, logStatistics", categories[i] ? categories[i] : "(null)");
        listed |= 1u << k;
    }
    if (nCategories == 0) c->log_mask = loggingOn ? ALL_CATEGORIES : 1u; /* errors are always logged */
    else c->log_mask = loggingOn ? (listed | 1u) : ((c->log_mask & ~listed) | 1u);
    return fmi2OK;
}

static void free_instance(Instance *c) {
    fmi2CallbackFreeMemory release = c->cb.freeMemory;
    void *blocks[] = {c->name, c->p, c->x, c->m, c->u, c->u_der, c->u_step, c->xdot, c->y, c->x_set, c->holds, c->assert_values,
                      (void *)c->arg, c->res, c->iw, c->w, c->seed_x, c->seed_u, c->sens_x, c->sens_y,
                      c->eval.x, c->eval.u, c->eval.m, c->eval.xdot, c->eval.y, c->eval.holds, c->eval.values};
    for (size_t i = 0; i < sizeof(blocks) / sizeof(blocks[0]); i++) if (blocks[i]) release(blocks[i]);
    ode23s_free(&c->solver, release);
    release(c);
}

static casadi_work const WORKS[] = {model_evaluate_work, model_initial_work,
                                    model_ode_jacobian_work, model_directional_work};

static int allocate_work(Instance *c, const fmi2CallbackFunctions *functions) {
    casadi_int sz_arg = 7, sz_res = 4, sz_iw = 0, sz_w = 0;
    for (size_t i = 0; i < sizeof(WORKS) / sizeof(WORKS[0]); i++) {
        casadi_int a = 0, r = 0, iw = 0, w = 0;
        WORKS[i](&a, &r, &iw, &w);
        if (a > sz_arg) sz_arg = a;
        if (r > sz_res) sz_res = r;
        if (iw > sz_iw) sz_iw = iw;
        if (w > sz_w) sz_w = w;
    }
    fmi2CallbackAllocateMemory alloc = functions->allocateMemory;
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
    Evaluation *e = &c->eval;
    e->x = alloc(nx, sizeof(double));
    e->u = alloc(nu, sizeof(double));
    e->m = alloc(nm, sizeof(double));
    e->xdot = alloc(nx, sizeof(double));
    e->y = alloc(ny, sizeof(double));
    e->holds = alloc(model_info.n_asserts ? (size_t)model_info.n_asserts : 1, sizeof(double));
    e->values = alloc(n_values ? (size_t)n_values : 1, sizeof(double));
    int solver_failed = ode23s_alloc(&c->solver, model_info.nx, alloc);
    return c->p && c->m && c->x && c->u && c->u_der && c->u_step && c->xdot && c->y && c->x_set && c->holds && c->assert_values && c->arg && c->res && c->iw && c->w && c->seed_x &&
           c->seed_u && c->sens_x && c->sens_y && e->x && e->u && e->xdot && e->y && e->holds && e->values &&
           e->m && !solver_failed;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; (void)visible;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
    if (!instanceName || !instanceName[0]) {
        log_text(functions, "?", fmi2Error, "logStatusError", "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (fmuType != fmi2ModelExchange && fmuType != fmi2CoSimulation) {
        log_text(functions, instanceName, fmi2Error, "logStatusError",
                 "fmi2Instantiate: fmuType is neither fmi2ModelExchange nor fmi2CoSimulation");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, model_info.guid) != 0) {
        char text[512];
        snprintf(text, sizeof text, "fmi2Instantiate: GUID %.200s does not match this binary of %s (%s)",
                 fmuGUID ? fmuGUID : "(null)", model_info.identifier, model_info.guid);
        log_text(functions, instanceName, fmi2Error, "logStatusError", text);
        return NULL;
    }
    Instance *c = functions->allocateMemory(1, sizeof(Instance));
    if (!c) return NULL;
    c->cb = *functions;
    c->type = fmuType;
    c->log_mask = loggingOn ? ALL_CATEGORIES : DEFAULT_CATEGORIES;
    c->name = functions->allocateMemory(strlen(instanceName) + 1, 1);
    if (c->name) memcpy(c->name, instanceName, strlen(instanceName) + 1);
    if (!c->name || !allocate_work(c, functions)) {
        log_text(functions, instanceName, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        free_instance(c);
        return NULL;
    }
    c->solver.rhs = rhs;
    c->solver.jacobian = jacobian;
    c->solver.ctx = c;
    c->solver.max_steps = 1000000;
    set_defaults(c);
    return c;
}

void fmi2FreeInstance(fmi2Component component) {
    if (component) free_instance(component);
}

fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    ENTER(F_SetupExperiment);
    if (toleranceDefined && !(tolerance > 0.0 && tolerance < 1.0))
        return fail(c, F_SetupExperiment, REJECTED, "tolerance %g: expected 0 < tolerance < 1", tolerance);
    if (!isfinite(startTime))
        return fail(c, F_SetupExperiment, REJECTED, "start time %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return fail(c, F_SetupExperiment, REJECTED, "stop time %g before start time %g", stopTime, startTime);
    if (toleranceDefined) c->rtol = tolerance;
    c->t = startTime;
    c->has_stop = stopTimeDefined;
    c->t_stop = stopTime;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component) {
    ENTER(F_EnterInitializationMode);
    c->mode = MODE_INITIALIZATION;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    ENTER(F_ExitInitializationMode);
    fmi2Status status = update(c, F_ExitInitializationMode, 1, 1);
    if (status == fmi2Error) return fmi2Error;
    c->mode = c->type == fmi2ModelExchange ? MODE_EVENT : MODE_STEP;
    c->solver.h = 0.0;
    c->solver.f0_valid = 0;
    c->solver.jac_valid = 0;
    return status;
}

fmi2Status fmi2Terminate(fmi2Component component) {
    ENTER(F_Terminate);
    if (c->type == fmi2CoSimulation)
        log_message(c, fmi2OK, "logStatistics", "integrator: %ld steps, %ld rejected, %ld Jacobians, %ld derivative "
                    "requests; model: %llu evaluations, %llu requests answered by the last one",
                    c->solver.steps, c->solver.rejected, c->solver.jacobians, c->solver.rhs_calls,
                    c->eval.evaluations, c->eval.reused);
    c->mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component component) {
    ENTER(F_Reset);
    set_defaults(c);
    return fmi2OK;
}

/* ---- values ----------------------------------------------------------------------------- */
/* The runtime's counters, in the order of codegen.STATISTICS. */
static double statistic(const Instance *c, int k) {
    switch (k) {
    case 0: return (double)c->eval.evaluations;
    case 1: return (double)c->eval.reused;
    case 2: return (double)c->solver.jacobians;
    case 3: return (double)c->solver.steps;
    default: return (double)c->solver.rejected;
    }
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    ENTER(F_GetReal);
    NOT_NULL(F_GetReal, vr, nvr);
    NOT_NULL(F_GetReal, value, nvr);
    int need_xdot = 0, need_y = 0;
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < 0)
            return fail(c, F_GetReal, REJECTED, "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        need_xdot |= r >= off_dx() && r < off_u();
        need_y |= r >= off_y() && r < vr_rtol();
    }
    /* In the error state the values are shown as they are, for inspection. */
    if (c->mode != MODE_ERROR && update(c, F_GetReal, need_xdot, need_y) == fmi2Error) return fmi2Error;
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
    return fmi2OK;
}

/* Why the Real ``r`` cannot take ``value`` now, or NULL if it can. */
static const char *set_real_refusal(const Instance *c, int r, double value) {
    int initializing = c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION;
    if (!isfinite(value)) return "expected a finite value";
    if (r < off_x() && !initializing)
        return "is a fixed parameter: it can only be set before fmi2ExitInitializationMode";
    if (r >= off_x() && r < off_dx() && !initializing)
        return "is a state: set it before fmi2ExitInitializationMode (Model Exchange: fmi2SetContinuousStates)";
    if (r >= off_dx() && r < off_u()) return "is a derivative (calculated): it cannot be set";
    if (r >= off_y() && r < off_m()) return "is calculated by the model: it cannot be set";
    if (r >= off_m() && r < vr_rtol()) return "is kept by the runtime from the previous step: it cannot be set";
    if (r == vr_rtol() && !(value > 0.0 && value < 1.0)) return "expected 0 < tolerance < 1";
    if (r == vr_max_step() && !(value >= 0.0)) return "expected >= 0 (0: no limit besides the communication step)";
    if (r >= vr_statistics()) return "is a statistic of the runtime: it cannot be set";
    return NULL;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    ENTER(F_SetReal);
    NOT_NULL(F_SetReal, vr, nvr);
    NOT_NULL(F_SetReal, value, nvr);
    /* Check everything first, so a rejected call changes nothing. */
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < 0)
            return fail(c, F_SetReal, REJECTED, "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        const char *refusal = set_real_refusal(c, r, value[i]);
        if (refusal) return fail(c, F_SetReal, REJECTED, "%s = %g: %s", real_name(vr[i]), value[i], refusal);
    }
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < off_x()) { c->p[r] = value[i]; forget_evaluation(c); }
        else if (r < off_dx()) { c->x[r - off_x()] = value[i]; c->x_set[r - off_x()] = 1.0; }
        else if (r >= off_u() && r < off_y()) c->u[r - off_u()] = value[i];
        else if (r == vr_rtol()) c->rtol = value[i];
        else if (r == vr_max_step()) c->max_step = value[i];
    }
    if (nvr > 0) invalidate(c);
    return fmi2OK;
}

/* The models have Real variables only: the other types' get/set accept empty requests. */
#define NO_VARIABLES_OF_TYPE(function, F, type_name, value_type)                                       \
    fmi2Status function(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,             \
                        value_type value[]) {                                                           \
        ENTER(F);                                                                                       \
        NOT_NULL(F, vr, nvr);                                                                           \
        NOT_NULL(F, value, nvr);                                                                        \
        if (nvr == 0) return fmi2OK;                                                                    \
        return fail(c, F, REJECTED, "value reference %u: this model has no %s variables", vr[0], type_name); \
    }
NO_VARIABLES_OF_TYPE(fmi2GetInteger, F_GetInteger, "Integer", fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2GetBoolean, F_GetBoolean, "Boolean", fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2GetString, F_GetString, "String", fmi2String)
NO_VARIABLES_OF_TYPE(fmi2SetInteger, F_SetInteger, "Integer", const fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2SetBoolean, F_SetBoolean, "Boolean", const fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2SetString, F_SetString, "String", const fmi2String)

/* ---- FMU state -------------------------------------------------------------------------- */
/* In memory an FMU state is [size_t payload size | payload]; the payload is what
 * fmi2SerializeFMUstate hands out: a StateHeader and the doubles after it. */
static size_t state_size(void) {
    return sizeof(StateHeader) +
           sizeof(double) * (size_t)(3 * model_info.nx + 2 * model_info.nu + model_info.np +
                                     model_info.nx * model_info.nx + model_info.nm);
}

static uint64_t fnv1a(uint64_t hash, const unsigned char *bytes, size_t n) {
    for (size_t i = 0; i < n; i++) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
    return hash;
}

static uint64_t state_checksum(const unsigned char *payload, size_t size) {
    StateHeader head;
    memcpy(&head, payload, sizeof head);
    head.checksum = 0;
    uint64_t hash = fnv1a(0xcbf29ce484222325ULL, (const unsigned char *)&head, sizeof head);
    return fnv1a(hash, payload + sizeof head, size - sizeof head);
}

static void state_write(const Instance *c, unsigned char *payload) {
    StateHeader head;
    memset(&head, 0, sizeof head); /* padding bytes too: the checksum covers them */
    head.magic = FMU_STATE_MAGIC;
    head.nx = (unsigned)model_info.nx; head.nu = (unsigned)model_info.nu; head.np = (unsigned)model_info.np;
    head.nm = (unsigned)model_info.nm;
    head.type = (int)c->type;
    head.mode = (int)c->mode;
    head.interpolating = c->interpolating;
    head.t_step = c->t_step;
    head.steps = c->solver.steps; head.rejected = c->solver.rejected;
    head.jacobians = c->solver.jacobians; head.rhs_calls = c->solver.rhs_calls;
    head.evaluations = c->eval.evaluations; head.reused = c->eval.reused;
    head.f0_valid = c->solver.f0_valid; head.jac_valid = c->solver.jac_valid;
    head.jac_current = c->solver.jac_current; head.jac_age = c->solver.jac_age;
    head.t = c->t; head.rtol = c->rtol; head.max_step = c->max_step; head.h = c->solver.h;
    memcpy(payload, &head, sizeof head);
    double *v = (double *)(payload + sizeof head);
    memcpy(v, c->x, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->u, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->u_der, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->p, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(v, c->x_set, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.F0, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.J, sizeof(double) * model_info.nx * model_info.nx); v += model_info.nx * model_info.nx;
    memcpy(v, c->m, sizeof(double) * model_info.nm);
    head.checksum = state_checksum(payload, state_size());
    memcpy(payload, &head, sizeof head);
}

/* Why ``payload`` of ``size`` bytes is not a state of this model (for an instance of kind
 * ``type``), or NULL if it is one. */
static const char *state_refusal(const unsigned char *payload, size_t size, fmi2Type type) {
    StateHeader head;
    if (size != state_size()) return "its size does not match this model's FMU state";
    memcpy(&head, payload, sizeof head);
    if (head.magic != FMU_STATE_MAGIC || head.nx != (unsigned)model_info.nx || head.nu != (unsigned)model_info.nu ||
        head.np != (unsigned)model_info.np || head.nm != (unsigned)model_info.nm)
        return "it was not saved by this model";
    if (head.checksum != state_checksum(payload, size)) return "its checksum does not match (corrupted)";
    if (head.type != (int)type)
        return head.type == fmi2ModelExchange ? "it was saved by a Model Exchange instance, this one is Co-Simulation"
                                              : "it was saved by a Co-Simulation instance, this one is Model Exchange";
    if (head.mode < 0 || head.mode >= MODE_COUNT || head.jac_age < 0 || !isfinite(head.t) ||
        !(head.rtol > 0.0 && head.rtol < 1.0) || !(head.max_step >= 0.0) || !(head.h >= 0.0) || !isfinite(head.h) ||
        !isfinite(head.t_step) || head.steps < 0 || head.rejected < 0 || head.jacobians < 0 || head.rhs_calls < 0)
        return "its values are out of range";
    return NULL;
}

static void state_read(Instance *c, const unsigned char *payload) {
    StateHeader head;
    memcpy(&head, payload, sizeof head);
    const double *v = (const double *)(payload + sizeof head);
    memcpy(c->x, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->u, v, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(c->u_der, v, sizeof(double) * model_info.nu); v += model_info.nu;
    c->interpolating = head.interpolating != 0;
    c->t_step = head.t_step;
    memcpy(c->p, v, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(c->x_set, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.F0, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.J, v, sizeof(double) * model_info.nx * model_info.nx); v += model_info.nx * model_info.nx;
    memcpy(c->m, v, sizeof(double) * model_info.nm);
    c->mode = (Mode)head.mode;
    c->t = head.t;
    c->rtol = head.rtol;
    c->max_step = head.max_step;
    forget_evaluation(c);
    invalidate(c);
    c->solver.f0_valid = head.f0_valid != 0;
    c->solver.jac_valid = head.jac_valid != 0;
    c->solver.jac_current = head.jac_current != 0;
    c->solver.jac_age = head.jac_age;
    c->solver.h = head.h;
    c->solver.steps = head.steps; c->solver.rejected = head.rejected;
    c->solver.jacobians = head.jacobians; c->solver.rhs_calls = head.rhs_calls;
    c->eval.evaluations = head.evaluations; c->eval.reused = head.reused;
}

fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *state) {
    ENTER(F_GetFMUstate);
    NOT_NULL(F_GetFMUstate, state, 1);
    size_t size = state_size();
    unsigned char *buffer = *state;
    if (!buffer) {
        buffer = c->cb.allocateMemory(size + sizeof(size_t), 1);
        if (!buffer) return fail(c, F_GetFMUstate, REJECTED, "out of memory");
        memcpy(buffer, &size, sizeof size);
    }
    state_write(c, buffer + sizeof(size_t));
    *state = buffer;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate state) {
    ENTER(F_SetFMUstate);
    NOT_NULL(F_SetFMUstate, state, 1);
    size_t size;
    memcpy(&size, state, sizeof size);
    const unsigned char *payload = (const unsigned char *)state + sizeof(size_t);
    const char *refusal = state_refusal(payload, size, c->type);
    if (refusal) return fail(c, F_SetFMUstate, REJECTED, "not an FMU state of %s: %s", model_info.identifier, refusal);
    state_read(c, payload);
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *state) {
    ENTER(F_FreeFMUstate);
    if (state && *state) { c->cb.freeMemory(*state); *state = NULL; }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate state, size_t *size) {
    ENTER(F_SerializedFMUstateSize);
    NOT_NULL(F_SerializedFMUstateSize, state, 1);
    NOT_NULL(F_SerializedFMUstateSize, size, 1);
    memcpy(size, state, sizeof *size);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate state, fmi2Byte serialized[], size_t size) {
    ENTER(F_SerializeFMUstate);
    NOT_NULL(F_SerializeFMUstate, state, 1);
    NOT_NULL(F_SerializeFMUstate, serialized, size);
    size_t stored;
    memcpy(&stored, state, sizeof stored);
    if (size < stored)
        return fail(c, F_SerializeFMUstate, REJECTED, "buffer of %zu bytes, %zu needed", size, stored);
    memcpy(serialized, (const unsigned char *)state + sizeof(size_t), stored);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte serialized[], size_t size,
                                   fmi2FMUstate *state) {
    ENTER(F_DeSerializeFMUstate);
    NOT_NULL(F_DeSerializeFMUstate, serialized, size);
    NOT_NULL(F_DeSerializeFMUstate, state, 1);
    const char *refusal = state_refusal((const unsigned char *)serialized, size, c->type);
    if (refusal)
        return fail(c, F_DeSerializeFMUstate, REJECTED, "%zu bytes are not an FMU state of %s: %s", size,
                    model_info.identifier, refusal);
    unsigned char *buffer = *state ? *state : c->cb.allocateMemory(size + sizeof(size_t), 1);
    if (!buffer) return fail(c, F_DeSerializeFMUstate, REJECTED, "out of memory");
    memcpy(buffer, &size, sizeof size);
    memcpy(buffer + sizeof(size_t), serialized, size);
    *state = buffer;
    return fmi2OK;
}

/* ---- directional derivatives ------------------------------------------------------------ */
static fmi2Status seed(Instance *c, const fmi2ValueReference known[], size_t n, const fmi2Real dv[]) {
    for (int i = 0; i < model_info.nx; i++) c->seed_x[i] = 0.0;
    for (int i = 0; i < model_info.nu; i++) c->seed_u[i] = 0.0;
    for (size_t k = 0; k < n; k++) {
        int r = real_index(known[k]);
        if (r >= off_x() && r < off_dx()) c->seed_x[r - off_x()] += dv[k];
        else if (r >= off_u() && r < off_y()) c->seed_u[r - off_u()] += dv[k];
        else return fail(c, F_GetDirectionalDerivative, REJECTED, "known %u (%s): expected a state or an input",
                         known[k], real_name(known[k]));
    }
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component component, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    const Function F = F_GetDirectionalDerivative;
    ENTER(F);
    NOT_NULL(F, vUnknown_ref, nUnknown);
    NOT_NULL(F, dvUnknown, nUnknown);
    NOT_NULL(F, vKnown_ref, nKnown);
    NOT_NULL(F, dvKnown, nKnown);
    if (seed(c, vKnown_ref, nKnown, dvKnown) != fmi2OK) return fmi2Error;
    for (size_t k = 0; k < nUnknown; k++) {
        int r = real_index(vUnknown_ref[k]);
        int allowed = (r >= off_x() && r < off_u()) ||  /* a state or a derivative */
                      (r >= off_y() && r < off_m() && model_info.y_is_output[r - off_y()]);
        if (!allowed)
            return fail(c, F, REJECTED, "unknown %u (%s): expected a state, a derivative or an output",
                        vUnknown_ref[k], real_name(vUnknown_ref[k]));
    }
    if (c->mode == MODE_INITIALIZATION && initial_states(c, F) != fmi2OK) return fmi2Error;
    double t = c->t;
    c->arg[0] = &t; c->arg[1] = c->x; c->arg[2] = c->u; c->arg[3] = c->p; c->arg[4] = c->m;
    c->arg[5] = c->seed_x; c->arg[6] = c->seed_u;
    c->res[0] = c->sens_x; c->res[1] = c->sens_y;
    if (model_directional(c->arg, c->res, c->iw, c->w, 0) || !all_finite(c->sens_x, model_info.nx) ||
        !all_finite(c->sens_y, model_info.ny))
        return fail(c, F, BROKEN, "the directional derivative is not finite at t = %.17g", c->t);
    for (size_t k = 0; k < nUnknown; k++) {
        int r = real_index(vUnknown_ref[k]);
        if (r < off_dx()) dvUnknown[k] = c->seed_x[r - off_x()];
        else if (r < off_u()) dvUnknown[k] = c->sens_x[r - off_dx()];
        else dvUnknown[k] = c->sens_y[r - off_y()];
    }
    return fmi2OK;
}

/* ---- Model Exchange --------------------------------------------------------------------- */
fmi2Status fmi2EnterEventMode(fmi2Component component) {
    ENTER(F_EnterEventMode);
    c->mode = MODE_EVENT;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component component, fmi2EventInfo *info) {
    ENTER(F_NewDiscreteStates);
    NOT_NULL(F_NewDiscreteStates, info, 1);
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component component) {
    ENTER(F_EnterContinuousTimeMode);
    c->mode = MODE_CONTINUOUS;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component component, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(F_CompletedIntegratorStep);
    NOT_NULL(F_CompletedIntegratorStep, enterEventMode, 1);
    NOT_NULL(F_CompletedIntegratorStep, terminateSimulation, 1);
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    fmi2Status status = update(c, F_CompletedIntegratorStep, 0, 1); /* the asserts */
    if (status != fmi2Error) remember(c);
    return status;
}

fmi2Status fmi2SetTime(fmi2Component component, fmi2Real time) {
    ENTER(F_SetTime);
    if (!isfinite(time)) return fail(c, F_SetTime, REJECTED, "time %g is not finite", time);
    c->t = time;
    invalidate(c);
    return fmi2OK;
}

static fmi2Status check_nx(Instance *c, Function f, size_t nx) {
    if (nx != (size_t)model_info.nx) return fail(c, f, REJECTED, "nx = %zu: expected %d", nx, model_info.nx);
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component component, const fmi2Real x[], size_t nx) {
    ENTER(F_SetContinuousStates);
    if (check_nx(c, F_SetContinuousStates, nx) != fmi2OK) return fmi2Error;
    NOT_NULL(F_SetContinuousStates, x, nx);
    for (size_t i = 0; i < nx; i++)
        if (!isfinite(x[i]))
            return fail(c, F_SetContinuousStates, REJECTED, "%s = %g: expected a finite value",
                        real_name((fmi2ValueReference)(off_x() + (int)i)), x[i]);
    memcpy(c->x, x, sizeof(double) * nx);
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component component, fmi2Real derivatives[], size_t nx) {
    ENTER(F_GetDerivatives);
    if (check_nx(c, F_GetDerivatives, nx) != fmi2OK) return fmi2Error;
    NOT_NULL(F_GetDerivatives, derivatives, nx);
    if (update(c, F_GetDerivatives, 1, 0) != fmi2OK) return fmi2Error;
    memcpy(derivatives, c->xdot, sizeof(double) * nx);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component component, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    ENTER(F_GetEventIndicators);
    if (ni != 0)
        return fail(c, F_GetEventIndicators, REJECTED, "ni = %zu: this model has no event indicators", ni);
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component component, fmi2Real x[], size_t nx) {
    ENTER(F_GetContinuousStates);
    if (check_nx(c, F_GetContinuousStates, nx) != fmi2OK) return fmi2Error;
    NOT_NULL(F_GetContinuousStates, x, nx);
    if ((c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) &&
        initial_states(c, F_GetContinuousStates) != fmi2OK)
        return fmi2Error;
    memcpy(x, c->x, sizeof(double) * nx);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component component, fmi2Real x_nominal[], size_t nx) {
    ENTER(F_GetNominalsOfContinuousStates);
    if (check_nx(c, F_GetNominalsOfContinuousStates, nx) != fmi2OK) return fmi2Error;
    NOT_NULL(F_GetNominalsOfContinuousStates, x_nominal, nx);
    for (size_t i = 0; i < nx; i++) x_nominal[i] = 1.0;
    return fmi2OK;
}

/* ---- Co-Simulation ---------------------------------------------------------------------- */
/* First derivatives of inputs for the next fmi2DoStep (canInterpolateInputs): the input is
 * interpolated linearly from its value at the communication point; after the step it holds its
 * value at the step's end and the derivatives are cleared. */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    const Function F = F_SetRealInputDerivatives;
    ENTER(F);
    if (c->type != fmi2CoSimulation && nvr > 0)
        return fail(c, F, REJECTED, "input derivatives are for Co-Simulation only");
    NOT_NULL(F, vr, nvr);
    NOT_NULL(F, order, nvr);
    NOT_NULL(F, value, nvr);
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < off_u() || r >= off_y())
            return fail(c, F, REJECTED, "value reference %u: not an input", vr[i]);
        if (order[i] != 1)
            return fail(c, F, REJECTED, "%s: derivative order %d; only order 1 is supported", real_name(vr[i]),
                        (int)order[i]);
        if (!isfinite(value[i]))
            return fail(c, F, REJECTED, "%s: derivative %g: expected a finite value", real_name(vr[i]), value[i]);
    }
    for (size_t i = 0; i < nvr; i++) c->u_der[real_index(vr[i]) - off_u()] = value[i];
    c->t_step = c->t;  /* the inputs' values hold at the current time (the start time before the first step) */
    c->interpolating = 0;
    for (int i = 0; i < model_info.nu; i++) c->interpolating |= c->u_der[i] != 0.0;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    ENTER(F_GetRealOutputDerivatives);
    if (nvr == 0) return fmi2OK;
    return fail(c, F_GetRealOutputDerivatives, REJECTED,
                "output derivatives are not provided (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    const Function F = F_DoStep;
    ENTER(F);
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize))
        return fail(c, F, REJECTED, "communication step size %g: expected > 0", communicationStepSize);
    if (!isfinite(currentCommunicationPoint) || fabs(currentCommunicationPoint - c->t) > 1e-9 * fmax(1.0, fabs(c->t)))
        return fail(c, F, REJECTED, "current communication point %.17g differs from the FMU's time %.17g",
                    currentCommunicationPoint, c->t);
    double t_end = currentCommunicationPoint + communicationStepSize;
    if (!(t_end > currentCommunicationPoint))
        return fail(c, F, REJECTED, "communication step size %g does not advance the time %.17g (t + h == t)",
                    communicationStepSize, currentCommunicationPoint);
    if (c->has_stop && t_end > c->t_stop * (1.0 + 1e-12) + 1e-12)
        return fail(c, F, REJECTED, "step to t = %.17g goes past the stop time %.17g", t_end, c->t_stop);
    c->solver.rtol = c->rtol;
    c->solver.atol = c->rtol;
    c->solver.max_step = c->max_step;
    char message[512];
    double t = currentCommunicationPoint;
    c->t_step = currentCommunicationPoint;
    int status = ode23s_integrate(&c->solver, &t, c->x, t_end, message, sizeof message);
    c->t = t;
    c->xdot_valid = 0;
    c->y_valid = 0;
    if (c->interpolating) { /* the inputs now hold their values at the step's end */
        for (int i = 0; i < model_info.nu; i++) { c->u[i] += c->u_der[i] * (t - c->t_step); c->u_der[i] = 0.0; }
        c->interpolating = 0;
        c->solver.f0_valid = 0;
    }
    if (status != 0) return fail(c, F, BROKEN, "integration failed: %s", message);
    c->t = t_end;
    fmi2Status checked = update(c, F, 0, 1); /* the outputs at t_end, and with them the asserts */
    if (checked != fmi2Error) remember(c);
    return checked;
}

fmi2Status fmi2CancelStep(fmi2Component component) {
    ENTER(F_CancelStep);
    return fail(c, F_CancelStep, REJECTED, "fmi2DoStep never runs asynchronously here; nothing to cancel");
}

static fmi2Status no_status(fmi2Component component, Function f) {
    Instance *c = enter(component, f);
    if (!c) return fmi2Error;
    return fail(c, f, REJECTED, "fmi2DoStep never returns fmi2Pending; no status to query");
}

fmi2Status fmi2GetStatus(fmi2Component component, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value;
    return no_status(component, F_GetStatus);
}
fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind s, fmi2Real *value) {
    ENTER(F_GetRealStatus);
    NOT_NULL(F_GetRealStatus, value, 1);
    if (s == fmi2LastSuccessfulTime) { *value = c->t; return fmi2OK; }
    return no_status(component, F_GetRealStatus);
}
fmi2Status fmi2GetIntegerStatus(fmi2Component component, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s; (void)value;
    return no_status(component, F_GetIntegerStatus);
}
fmi2Status fmi2GetBooleanStatus(fmi2Component component, const fmi2StatusKind s, fmi2Boolean *value) {
    ENTER(F_GetBooleanStatus);
    NOT_NULL(F_GetBooleanStatus, value, 1);
    if (s == fmi2Terminated) { *value = fmi2False; return fmi2OK; }
    return no_status(component, F_GetBooleanStatus);
}
fmi2Status fmi2GetStringStatus(fmi2Component component, const fmi2StatusKind s, fmi2String *value) {
    (void)s; (void)value;
    return no_status(component, F_GetStringStatus);
}
