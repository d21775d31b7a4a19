/* rover-cosim FMI 2.0 runtime: Model Exchange and Co-Simulation around a generated model
 * (model.h). All state lives in the instance: many instances per process and per thread.
 * Every failure is reported through the logger and returned as fmi2Error; nothing aborts. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"
#include "ode23s.h"

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_EVENT, MODE_CONTINUOUS, MODE_STEP,
               MODE_TERMINATED, MODE_ERROR } Mode;

#define FMU_STATE_MAGIC 0x524f5643u /* "ROVC" */

/* What fmi2Get/SetFMUstate save and restore. */
typedef struct {
    unsigned magic, nx, nu, np;
    int mode;
    int f0_valid, jac_valid, jac_current, jac_age;  /* integrator memory, so a restored run repeats exactly */
    double t, rtol, max_step, h;
    /* followed by x[nx], u[nu], p[np], x_set[nx], F0[nx], J[nx*nx] (doubles) */
} StateHeader;

typedef struct {
    fmi2CallbackFunctions cb;
    char *name;
    fmi2Type type;
    int logging;
    Mode mode;
    double t, t_stop;
    int has_stop;
    double *p, *x, *u, *xdot, *y, *x_set;  /* x_set[i] != 0: the start of state i was set by the user */
    double rtol, max_step;
    int xdot_valid, y_valid;
    /* CasADi work */
    const double **arg;
    double **res;
    casadi_int *iw;
    double *w;
    double *seed_x, *seed_u, *sens_x, *sens_y;
    Ode23s solver;
} Instance;

#define DEFAULT_RTOL 1e-6
#define DEFAULT_MAX_STEP 0.0

/* ---- value references ------------------------------------------------------------------- */
static int off_p(void) { return 0; }
static int off_x(void) { return model_info.np; }
static int off_dx(void) { return model_info.np + model_info.nx; }
static int off_u(void) { return model_info.np + 2 * model_info.nx; }
static int off_y(void) { return model_info.np + 2 * model_info.nx + model_info.nu; }
static int vr_rtol(void) { return off_y() + model_info.ny; }
static int vr_max_step(void) { return vr_rtol() + 1; }
static int n_real(void) { return vr_max_step() + 1; }

/* ---- logging ---------------------------------------------------------------------------- */
static void log_message(Instance *c, fmi2Status status, const char *category, const char *format, ...) {
    if (!c || !c->cb.logger) return;
    if (status == fmi2OK && !c->logging) return;
    char buffer[1024], escaped[2048];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    /* The logger takes a printf format: pass the text itself with '%' doubled, so importers
     * that do not expand the variable arguments (e.g. ctypes callbacks) still get the text. */
    size_t j = 0;
    for (size_t i = 0; buffer[i] && j + 2 < sizeof escaped; i++) {
        if (buffer[i] == '%') escaped[j++] = '%';
        escaped[j++] = buffer[i];
    }
    escaped[j] = '\0';
    c->cb.logger(c->cb.componentEnvironment, c->name ? c->name : "?", status, category, escaped);
}

static fmi2Status fail(Instance *c, const char *function, const char *format, ...) {
    char buffer[900];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    log_message(c, fmi2Error, "logStatusError", "%s: %s", function, buffer);
    return fmi2Error;
}

static const char *real_name(fmi2ValueReference vr) {
    return (int)vr < n_real() ? model_info.real_names[vr] : "?";
}

/* ---- model evaluation ------------------------------------------------------------------- */
static int call4(Instance *c, casadi_eval f, double t, const double *x, double *out0, double *out1) {
    c->arg[0] = &t; c->arg[1] = x; c->arg[2] = c->u; c->arg[3] = c->p;
    c->res[0] = out0; c->res[1] = out1;
    return f(c->arg, c->res, c->iw, c->w, 0);
}

static int all_finite(const double *v, int n) {
    for (int i = 0; i < n; i++) if (!isfinite(v[i])) return 0;
    return 1;
}

static int rhs(void *ctx, double t, const double *x, double *xdot) {
    Instance *c = ctx;
    return call4(c, model_ode, t, x, xdot, NULL);
}

static int jacobian(void *ctx, double t, const double *x, double *dfdx, double *dfdt) {
    Instance *c = ctx;
    return call4(c, model_ode_jacobian, t, x, dfdx, dfdt);
}

/* States whose start value is an expression of the parameters, unless the user set them. */
static fmi2Status initial_states(Instance *c, const char *function) {
    int any = 0;
    for (int i = 0; i < model_info.nx; i++) any |= model_info.x_start_calculated[i] && !c->x_set[i];
    if (!any) return fmi2OK;
    double *x0 = c->sens_x; /* scratch of size nx */
    c->arg[0] = c->p;
    c->res[0] = x0;
    if (model_initial(c->arg, c->res, c->iw, c->w, 0) || !all_finite(x0, model_info.nx))
        return fail(c, function, "the start values of the states are not finite for these parameters");
    for (int i = 0; i < model_info.nx; i++)
        if (model_info.x_start_calculated[i] && !c->x_set[i]) c->x[i] = x0[i];
    return fmi2OK;
}

static fmi2Status update(Instance *c, const char *function, int need_xdot, int need_y) {
    if (c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) {
        if (initial_states(c, function) != fmi2OK) return fmi2Error;
    }
    if (need_xdot && !c->xdot_valid) {
        if (call4(c, model_ode, c->t, c->x, c->xdot, NULL) || !all_finite(c->xdot, model_info.nx))
            return fail(c, function, "the derivatives are not finite at t = %.17g", c->t);
        c->xdot_valid = 1;
    }
    if (need_y && !c->y_valid) {
        if (call4(c, model_outputs, c->t, c->x, c->y, NULL) || !all_finite(c->y, model_info.ny))
            return fail(c, function, "the outputs are not finite at t = %.17g", c->t);
        c->y_valid = 1;
    }
    return fmi2OK;
}

static void invalidate(Instance *c) {
    c->xdot_valid = 0;
    c->y_valid = 0;
    c->solver.f0_valid = 0;
}

static void set_defaults(Instance *c) {
    memcpy(c->p, model_info.p_default, sizeof(double) * model_info.np);
    memcpy(c->u, model_info.u_default, sizeof(double) * model_info.nu);
    memcpy(c->x, model_info.x_start, sizeof(double) * model_info.nx);
    for (int i = 0; i < model_info.nx; i++) c->x_set[i] = 0.0;
    c->rtol = DEFAULT_RTOL;
    c->max_step = DEFAULT_MAX_STEP;
    c->t = 0.0;
    c->has_stop = 0;
    c->mode = MODE_INSTANTIATED;
    c->solver.h = 0.0;
    c->solver.jac_valid = 0;
    invalidate(c);
}

/* ---- checks ----------------------------------------------------------------------------- */
static Instance *check(fmi2Component component, const char *function, unsigned allowed) {
    Instance *c = component;
    if (!c) return NULL;
    if (!(allowed & (1u << c->mode))) {
        static const char *names[] = {"instantiated", "initialization", "event", "continuous-time",
                                      "step-complete", "terminated", "error"};
        fail(c, function, "not allowed in the %s state", names[c->mode]);
        return NULL;
    }
    return c;
}

#define S(m) (1u << (m))
#define ANY_MODE (S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | S(MODE_EVENT) | S(MODE_CONTINUOUS) | \
                  S(MODE_STEP) | S(MODE_TERMINATED) | S(MODE_ERROR))
#define RUNNING (S(MODE_EVENT) | S(MODE_CONTINUOUS) | S(MODE_STEP))

/* ---- common functions ------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    Instance *c = check(component, "fmi2SetDebugLogging", ANY_MODE);
    if (!c) return fmi2Error;
    (void)nCategories; (void)categories;
    c->logging = loggingOn;
    return fmi2OK;
}

static void free_instance(Instance *c) {
    fmi2CallbackFreeMemory release = c->cb.freeMemory;
    void *blocks[] = {c->name, c->p, c->x, c->u, c->xdot, c->y, c->x_set, (void *)c->arg, c->res, c->iw,
                      c->w, c->seed_x, c->seed_u, c->sens_x, c->sens_y};
    for (size_t i = 0; i < sizeof(blocks) / sizeof(blocks[0]); i++) if (blocks[i]) release(blocks[i]);
    ode23s_free(&c->solver, release);
    release(c);
}

static casadi_eval const EVALS[] = {model_ode, model_outputs, model_initial, model_ode_jacobian, model_directional};
static casadi_work const WORKS[] = {model_ode_work, model_outputs_work, model_initial_work,
                                    model_ode_jacobian_work, model_directional_work};

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; (void)visible; (void)EVALS;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
    if (!instanceName || !instanceName[0]) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                              "fmi2Instantiate: the instance name is empty");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, model_info.guid) != 0) {
        if (functions->logger) {
            char text[512];
            snprintf(text, sizeof text, "fmi2Instantiate: GUID %s does not match this binary of %s (%s)",
                     fmuGUID ? fmuGUID : "(null)", model_info.identifier, model_info.guid);
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                              strchr(text, '%') ? "fmi2Instantiate: GUID does not match this binary" : text);
        }
        return NULL;
    }
    Instance *c = functions->allocateMemory(1, sizeof(Instance));
    if (!c) return NULL;
    c->cb = *functions;
    c->type = fmuType;
    c->logging = loggingOn;
    c->name = functions->allocateMemory(strlen(instanceName) + 1, 1);
    if (c->name) strcpy(c->name, instanceName);
    casadi_int sz_arg = 6, sz_res = 2, sz_iw = 0, sz_w = 0;
    for (size_t i = 0; i < sizeof(WORKS) / sizeof(WORKS[0]); i++) {
        casadi_int a = 0, r = 0, iw = 0, w = 0;
        WORKS[i](&a, &r, &iw, &w);
        if (a > sz_arg) sz_arg = a;
        if (r > sz_res) sz_res = r;
        if (iw > sz_iw) sz_iw = iw;
        if (w > sz_w) sz_w = w;
    }
    size_t nx = model_info.nx ? model_info.nx : 1, nu = model_info.nu ? model_info.nu : 1;
    size_t np = model_info.np ? model_info.np : 1, ny = model_info.ny ? model_info.ny : 1;
    c->p = functions->allocateMemory(np, sizeof(double));
    c->x = functions->allocateMemory(nx, sizeof(double));
    c->u = functions->allocateMemory(nu, sizeof(double));
    c->xdot = functions->allocateMemory(nx, sizeof(double));
    c->y = functions->allocateMemory(ny, sizeof(double));
    c->x_set = functions->allocateMemory(nx, sizeof(double));
    c->arg = functions->allocateMemory((size_t)sz_arg, sizeof(double *));
    c->res = functions->allocateMemory((size_t)sz_res, sizeof(double *));
    c->iw = functions->allocateMemory((size_t)sz_iw + 1, sizeof(casadi_int));
    c->w = functions->allocateMemory((size_t)sz_w + 1, sizeof(double));
    c->seed_x = functions->allocateMemory(nx, sizeof(double));
    c->seed_u = functions->allocateMemory(nu, sizeof(double));
    c->sens_x = functions->allocateMemory(nx, sizeof(double));
    c->sens_y = functions->allocateMemory(ny, sizeof(double));
    int solver_failed = ode23s_alloc(&c->solver, model_info.nx, functions->allocateMemory);
    if (!c->name || !c->p || !c->x || !c->u || !c->xdot || !c->y || !c->x_set || !c->arg || !c->res || !c->iw ||
        !c->w || !c->seed_x || !c->seed_u || !c->sens_x || !c->sens_y || solver_failed) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                              "fmi2Instantiate: out of memory");
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
    Instance *c = check(component, "fmi2SetupExperiment", S(MODE_INSTANTIATED));
    if (!c) return fmi2Error;
    if (toleranceDefined) {
        if (!(tolerance > 0.0 && tolerance < 1.0))
            return fail(c, "fmi2SetupExperiment", "tolerance %g: expected 0 < tolerance < 1", tolerance);
        c->rtol = tolerance;
    }
    if (!isfinite(startTime)) return fail(c, "fmi2SetupExperiment", "start time %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return fail(c, "fmi2SetupExperiment", "stop time %g before start time %g", stopTime, startTime);
    c->t = startTime;
    c->has_stop = stopTimeDefined;
    c->t_stop = stopTime;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component) {
    Instance *c = check(component, "fmi2EnterInitializationMode", S(MODE_INSTANTIATED));
    if (!c) return fmi2Error;
    c->mode = MODE_INITIALIZATION;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    Instance *c = check(component, "fmi2ExitInitializationMode", S(MODE_INITIALIZATION));
    if (!c) return fmi2Error;
    if (update(c, "fmi2ExitInitializationMode", 1, 1) != fmi2OK) {
        c->mode = MODE_ERROR;
        return fmi2Error;
    }
    c->mode = c->type == fmi2ModelExchange ? MODE_EVENT : MODE_STEP;
    c->solver.h = 0.0;
    c->solver.f0_valid = 0;
    c->solver.jac_valid = 0;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component component) {
    Instance *c = check(component, "fmi2Terminate", RUNNING | S(MODE_ERROR) | S(MODE_TERMINATED));
    if (!c) return fmi2Error;
    if (c->type == fmi2CoSimulation)
        log_message(c, fmi2OK, "logStatistics", "integrator: %ld steps, %ld rejected, %ld Jacobians, %ld derivative evaluations",
                    c->solver.steps, c->solver.rejected, c->solver.jacobians, c->solver.rhs_calls);
    c->mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component component) {
    Instance *c = check(component, "fmi2Reset", ANY_MODE);
    if (!c) return fmi2Error;
    set_defaults(c);
    return fmi2OK;
}

/* ---- values ----------------------------------------------------------------------------- */
fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Instance *c = check(component, "fmi2GetReal", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return fail(c, "fmi2GetReal", "null value-reference or value array");
    int need_xdot = 0, need_y = 0;
    for (size_t i = 0; i < nvr; i++) {
        int r = (int)vr[i];
        if (r >= n_real()) return fail(c, "fmi2GetReal", "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        need_xdot |= r >= off_dx() && r < off_u();
        need_y |= r >= off_y() && r < vr_rtol();
    }
    if (update(c, "fmi2GetReal", need_xdot, need_y) != fmi2OK) return fmi2Error;
    for (size_t i = 0; i < nvr; i++) {
        int r = (int)vr[i];
        if (r < off_x()) value[i] = c->p[r];
        else if (r < off_dx()) value[i] = c->x[r - off_x()];
        else if (r < off_u()) value[i] = c->xdot[r - off_dx()];
        else if (r < off_y()) value[i] = c->u[r - off_u()];
        else if (r < vr_rtol()) value[i] = c->y[r - off_y()];
        else if (r == vr_rtol()) value[i] = c->rtol;
        else value[i] = c->max_step;
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Instance *c = check(component, "fmi2SetReal", S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING);
    if (!c) return fmi2Error;
    if (nvr > 0 && (!vr || !value)) return fail(c, "fmi2SetReal", "null value-reference or value array");
    int initializing = c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION;
    /* Check everything first, so a rejected call changes nothing. */
    for (size_t i = 0; i < nvr; i++) {
        int r = (int)vr[i];
        if (r >= n_real()) return fail(c, "fmi2SetReal", "value reference %u: no such Real variable (0..%d)", vr[i], n_real() - 1);
        const char *name = real_name(vr[i]);
        if (!isfinite(value[i])) return fail(c, "fmi2SetReal", "%s = %g: expected a finite value", name, value[i]);
        if (r < off_x() && !initializing)
            return fail(c, "fmi2SetReal", "%s is a fixed parameter: it can only be set before fmi2ExitInitializationMode", name);
        if (r >= off_x() && r < off_dx() && !initializing)
            return fail(c, "fmi2SetReal", "%s is a state: set it before fmi2ExitInitializationMode "
                        "(Model Exchange: fmi2SetContinuousStates)", name);
        if (r >= off_dx() && r < off_u())
            return fail(c, "fmi2SetReal", "%s is a derivative (calculated): it cannot be set", name);
        if (r >= off_y() && r < vr_rtol())
            return fail(c, "fmi2SetReal", "%s is calculated by the model: it cannot be set", name);
        if (r == vr_rtol() && !(value[i] > 0.0 && value[i] < 1.0))
            return fail(c, "fmi2SetReal", "%s = %g: expected 0 < tolerance < 1", name, value[i]);
        if (r == vr_max_step() && !(value[i] >= 0.0))
            return fail(c, "fmi2SetReal", "%s = %g: expected >= 0 (0: no limit besides the communication step)", name, value[i]);
    }
    for (size_t i = 0; i < nvr; i++) {
        int r = (int)vr[i];
        if (r < off_x()) c->p[r] = value[i];
        else if (r < off_dx()) { c->x[r - off_x()] = value[i]; c->x_set[r - off_x()] = 1.0; }
        else if (r >= off_u() && r < off_y()) c->u[r - off_u()] = value[i];
        else if (r == vr_rtol()) c->rtol = value[i];
        else if (r == vr_max_step()) c->max_step = value[i];
    }
    if (nvr > 0) invalidate(c);
    return fmi2OK;
}

static fmi2Status no_such(Instance *c, const char *function, const char *type, size_t nvr, const fmi2ValueReference vr[]) {
    if (nvr == 0) return fmi2OK;
    return fail(c, function, "value reference %u: this model has no %s variables", vr ? vr[0] : 0u, type);
}

/* The models have Real variables only: the other types' get/set accept empty requests. */
#define NO_VARIABLES_OF_TYPE(function, type_name, value_type)                                          \
    fmi2Status function(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,             \
                        value_type value[]) {                                                           \
        (void)value;                                                                                    \
        Instance *c = check(component, #function, ANY_MODE);                                            \
        return c ? no_such(c, #function, type_name, nvr, vr) : fmi2Error;                               \
    }
NO_VARIABLES_OF_TYPE(fmi2GetInteger, "Integer", fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2GetBoolean, "Boolean", fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2GetString, "String", fmi2String)
NO_VARIABLES_OF_TYPE(fmi2SetInteger, "Integer", const fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2SetBoolean, "Boolean", const fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2SetString, "String", const fmi2String)

/* ---- FMU state -------------------------------------------------------------------------- */
static size_t state_size(void) {
    return sizeof(StateHeader) +
           sizeof(double) * (size_t)(3 * model_info.nx + model_info.nu + model_info.np + model_info.nx * model_info.nx);
}

static void state_write(const Instance *c, unsigned char *buffer) {
    StateHeader head = {FMU_STATE_MAGIC, (unsigned)model_info.nx, (unsigned)model_info.nu, (unsigned)model_info.np,
                        (int)c->mode, c->solver.f0_valid, c->solver.jac_valid, c->solver.jac_current,
                        c->solver.jac_age, c->t, c->rtol, c->max_step, c->solver.h};
    memcpy(buffer, &head, sizeof head);
    double *v = (double *)(buffer + sizeof head);
    memcpy(v, c->x, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->u, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->p, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(v, c->x_set, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.F0, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.J, sizeof(double) * model_info.nx * model_info.nx);
}

static fmi2Status state_read(Instance *c, const unsigned char *buffer, size_t size, const char *function) {
    StateHeader head;
    if (size < sizeof head) return fail(c, function, "FMU state of %zu bytes is too short", size);
    memcpy(&head, buffer, sizeof head);
    if (head.magic != FMU_STATE_MAGIC || head.nx != (unsigned)model_info.nx || head.nu != (unsigned)model_info.nu ||
        head.np != (unsigned)model_info.np || size != state_size())
        return fail(c, function, "the FMU state was not saved by %s", model_info.identifier);
    const double *v = (const double *)(buffer + sizeof head);
    memcpy(c->x, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->u, v, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(c->p, v, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(c->x_set, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.F0, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.J, v, sizeof(double) * model_info.nx * model_info.nx);
    c->mode = (Mode)head.mode;
    c->t = head.t;
    c->rtol = head.rtol;
    c->max_step = head.max_step;
    invalidate(c);
    c->solver.f0_valid = head.f0_valid;
    c->solver.jac_valid = head.jac_valid;
    c->solver.jac_current = head.jac_current;
    c->solver.jac_age = head.jac_age;
    c->solver.h = head.h;
    return fmi2OK;
}

fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *state) {
    Instance *c = check(component, "fmi2GetFMUstate", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (!state) return fail(c, "fmi2GetFMUstate", "null state pointer");
    size_t size = state_size();
    unsigned char *buffer = *state;
    if (!buffer) {
        buffer = c->cb.allocateMemory(size + sizeof(size_t), 1);
        if (!buffer) return fail(c, "fmi2GetFMUstate", "out of memory");
        memcpy(buffer, &size, sizeof size);
    }
    state_write(c, buffer + sizeof(size_t));
    *state = buffer;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate state) {
    Instance *c = check(component, "fmi2SetFMUstate", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (!state) return fail(c, "fmi2SetFMUstate", "null state");
    size_t size;
    memcpy(&size, state, sizeof size);
    return state_read(c, (const unsigned char *)state + sizeof(size_t), size, "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *state) {
    Instance *c = check(component, "fmi2FreeFMUstate", ANY_MODE);
    if (!c) return fmi2Error;
    if (state && *state) { c->cb.freeMemory(*state); *state = NULL; }
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate state, size_t *size) {
    Instance *c = check(component, "fmi2SerializedFMUstateSize", ANY_MODE);
    if (!c) return fmi2Error;
    if (!state || !size) return fail(c, "fmi2SerializedFMUstateSize", "null argument");
    memcpy(size, state, sizeof *size);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate state, fmi2Byte serialized[], size_t size) {
    Instance *c = check(component, "fmi2SerializeFMUstate", ANY_MODE);
    if (!c) return fmi2Error;
    if (!state || !serialized) return fail(c, "fmi2SerializeFMUstate", "null argument");
    size_t stored;
    memcpy(&stored, state, sizeof stored);
    if (size < stored) return fail(c, "fmi2SerializeFMUstate", "buffer of %zu bytes, %zu needed", size, stored);
    memcpy(serialized, (const unsigned char *)state + sizeof(size_t), stored);
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte serialized[], size_t size, fmi2FMUstate *state) {
    Instance *c = check(component, "fmi2DeSerializeFMUstate", ANY_MODE);
    if (!c) return fmi2Error;
    if (!serialized || !state) return fail(c, "fmi2DeSerializeFMUstate", "null argument");
    StateHeader head;
    if (size != state_size()) return fail(c, "fmi2DeSerializeFMUstate", "%zu bytes: expected %zu", size, state_size());
    memcpy(&head, serialized, sizeof head);
    if (head.magic != FMU_STATE_MAGIC) return fail(c, "fmi2DeSerializeFMUstate", "not a state of %s", model_info.identifier);
    unsigned char *buffer = *state ? *state : c->cb.allocateMemory(size + sizeof(size_t), 1);
    if (!buffer) return fail(c, "fmi2DeSerializeFMUstate", "out of memory");
    memcpy(buffer, &size, sizeof size);
    memcpy(buffer + sizeof(size_t), serialized, size);
    *state = buffer;
    return fmi2OK;
}

/* ---- directional derivatives ------------------------------------------------------------ */
fmi2Status fmi2GetDirectionalDerivative(fmi2Component component, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    const char *function = "fmi2GetDirectionalDerivative";
    Instance *c = check(component, function, S(MODE_INITIALIZATION) | RUNNING);
    if (!c) return fmi2Error;
    for (int i = 0; i < model_info.nx; i++) c->seed_x[i] = 0.0;
    for (int i = 0; i < model_info.nu; i++) c->seed_u[i] = 0.0;
    for (size_t k = 0; k < nKnown; k++) {
        int r = (int)vKnown_ref[k];
        if (r >= off_x() && r < off_dx()) c->seed_x[r - off_x()] += dvKnown[k];
        else if (r >= off_u() && r < off_y()) c->seed_u[r - off_u()] += dvKnown[k];
        else return fail(c, function, "known %u (%s): expected a state or an input", vKnown_ref[k], real_name(vKnown_ref[k]));
    }
    for (size_t k = 0; k < nUnknown; k++) {
        int r = (int)vUnknown_ref[k];
        if (!((r >= off_x() && r < off_y()) || (r >= off_y() && r < vr_rtol())))
            return fail(c, function, "unknown %u (%s): expected a derivative, an output or a local variable",
                        vUnknown_ref[k], real_name(vUnknown_ref[k]));
    }
    if (c->mode == MODE_INITIALIZATION && initial_states(c, function) != fmi2OK) return fmi2Error;
    double t = c->t;
    c->arg[0] = &t; c->arg[1] = c->x; c->arg[2] = c->u; c->arg[3] = c->p; c->arg[4] = c->seed_x; c->arg[5] = c->seed_u;
    c->res[0] = c->sens_x; c->res[1] = c->sens_y;
    if (model_directional(c->arg, c->res, c->iw, c->w, 0) || !all_finite(c->sens_x, model_info.nx) ||
        !all_finite(c->sens_y, model_info.ny))
        return fail(c, function, "the directional derivative is not finite at t = %.17g", c->t);
    for (size_t k = 0; k < nUnknown; k++) {
        int r = (int)vUnknown_ref[k];
        if (r < off_dx()) dvUnknown[k] = c->seed_x[r - off_x()];
        else if (r < off_u()) dvUnknown[k] = c->sens_x[r - off_dx()];
        else if (r < off_y()) dvUnknown[k] = c->seed_u[r - off_u()];
        else dvUnknown[k] = c->sens_y[r - off_y()];
    }
    return fmi2OK;
}

/* ---- Model Exchange --------------------------------------------------------------------- */
fmi2Status fmi2EnterEventMode(fmi2Component component) {
    Instance *c = check(component, "fmi2EnterEventMode", S(MODE_EVENT) | S(MODE_CONTINUOUS));
    if (!c) return fmi2Error;
    c->mode = MODE_EVENT;
    return fmi2OK;
}

fmi2Status fmi2NewDiscreteStates(fmi2Component component, fmi2EventInfo *info) {
    Instance *c = check(component, "fmi2NewDiscreteStates", S(MODE_EVENT));
    if (!c) return fmi2Error;
    if (!info) return fail(c, "fmi2NewDiscreteStates", "null event info");
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component component) {
    Instance *c = check(component, "fmi2EnterContinuousTimeMode", S(MODE_EVENT));
    if (!c) return fmi2Error;
    c->mode = MODE_CONTINUOUS;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component component, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *c = check(component, "fmi2CompletedIntegratorStep", S(MODE_CONTINUOUS));
    if (!c) return fmi2Error;
    if (enterEventMode) *enterEventMode = fmi2False;
    if (terminateSimulation) *terminateSimulation = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component component, fmi2Real time) {
    Instance *c = check(component, "fmi2SetTime", S(MODE_EVENT) | S(MODE_CONTINUOUS));
    if (!c) return fmi2Error;
    if (!isfinite(time)) return fail(c, "fmi2SetTime", "time %g is not finite", time);
    c->t = time;
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component component, const fmi2Real x[], size_t nx) {
    Instance *c = check(component, "fmi2SetContinuousStates", S(MODE_EVENT) | S(MODE_CONTINUOUS));
    if (!c) return fmi2Error;
    if (nx != (size_t)model_info.nx) return fail(c, "fmi2SetContinuousStates", "nx = %zu: expected %d", nx, model_info.nx);
    for (size_t i = 0; i < nx; i++)
        if (!isfinite(x[i])) return fail(c, "fmi2SetContinuousStates", "%s = %g: expected a finite value",
                                         real_name((fmi2ValueReference)(off_x() + (int)i)), x[i]);
    memcpy(c->x, x, sizeof(double) * nx);
    invalidate(c);
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component component, fmi2Real derivatives[], size_t nx) {
    Instance *c = check(component, "fmi2GetDerivatives", S(MODE_INITIALIZATION) | S(MODE_EVENT) | S(MODE_CONTINUOUS) | S(MODE_TERMINATED));
    if (!c) return fmi2Error;
    if (nx != (size_t)model_info.nx) return fail(c, "fmi2GetDerivatives", "nx = %zu: expected %d", nx, model_info.nx);
    if (update(c, "fmi2GetDerivatives", 1, 0) != fmi2OK) return fmi2Error;
    memcpy(derivatives, c->xdot, sizeof(double) * nx);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component component, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    Instance *c = check(component, "fmi2GetEventIndicators", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (ni != 0) return fail(c, "fmi2GetEventIndicators", "ni = %zu: this model has no event indicators", ni);
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component component, fmi2Real x[], size_t nx) {
    Instance *c = check(component, "fmi2GetContinuousStates", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (nx != (size_t)model_info.nx) return fail(c, "fmi2GetContinuousStates", "nx = %zu: expected %d", nx, model_info.nx);
    if ((c->mode == MODE_INSTANTIATED || c->mode == MODE_INITIALIZATION) && initial_states(c, "fmi2GetContinuousStates") != fmi2OK)
        return fmi2Error;
    memcpy(x, c->x, sizeof(double) * nx);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component component, fmi2Real x_nominal[], size_t nx) {
    Instance *c = check(component, "fmi2GetNominalsOfContinuousStates", ANY_MODE & ~S(MODE_ERROR));
    if (!c) return fmi2Error;
    if (nx != (size_t)model_info.nx) return fail(c, "fmi2GetNominalsOfContinuousStates", "nx = %zu: expected %d", nx, model_info.nx);
    for (size_t i = 0; i < nx; i++) x_nominal[i] = 1.0;
    return fmi2OK;
}

/* ---- Co-Simulation ---------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    Instance *c = check(component, "fmi2SetRealInputDerivatives", ANY_MODE);
    if (!c) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(c, "fmi2SetRealInputDerivatives", "input derivatives are not supported (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    Instance *c = check(component, "fmi2GetRealOutputDerivatives", ANY_MODE);
    if (!c) return fmi2Error;
    if (nvr == 0) return fmi2OK;
    return fail(c, "fmi2GetRealOutputDerivatives", "output derivatives are not provided (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    const char *function = "fmi2DoStep";
    Instance *c = check(component, function, S(MODE_STEP));
    if (!c) return fmi2Error;
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize))
        return fail(c, function, "communication step size %g: expected > 0", communicationStepSize);
    if (fabs(currentCommunicationPoint - c->t) > 1e-9 * fmax(1.0, fabs(c->t)))
        return fail(c, function, "current communication point %.17g differs from the FMU's time %.17g",
                    currentCommunicationPoint, c->t);
    double t_end = currentCommunicationPoint + communicationStepSize;
    if (c->has_stop && t_end > c->t_stop * (1.0 + 1e-12) + 1e-12)
        return fail(c, function, "step to t = %.17g goes past the stop time %.17g", t_end, c->t_stop);
    c->solver.rtol = c->rtol;
    c->solver.atol = c->rtol;
    c->solver.max_step = c->max_step;
    char message[512];
    double t = currentCommunicationPoint;
    int status = ode23s_integrate(&c->solver, &t, c->x, t_end, message, sizeof message);
    c->t = t;
    c->xdot_valid = 0;
    c->y_valid = 0;
    if (status != 0) {
        c->mode = MODE_ERROR;
        return fail(c, function, "integration failed: %s", message);
    }
    c->t = t_end;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component component) {
    Instance *c = check(component, "fmi2CancelStep", ANY_MODE);
    if (!c) return fmi2Error;
    return fail(c, "fmi2CancelStep", "fmi2DoStep never runs asynchronously here; nothing to cancel");
}

static fmi2Status status_query(fmi2Component component, const char *function) {
    Instance *c = check(component, function, ANY_MODE);
    if (!c) return fmi2Error;
    return fail(c, function, "fmi2DoStep never returns fmi2Pending; no status to query");
}

fmi2Status fmi2GetStatus(fmi2Component component, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value;
    return status_query(component, "fmi2GetStatus");
}
fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind s, fmi2Real *value) {
    Instance *c = component;
    if (c && s == fmi2LastSuccessfulTime && value) { *value = c->t; return fmi2OK; }
    return status_query(component, "fmi2GetRealStatus");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component component, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s; (void)value;
    return status_query(component, "fmi2GetIntegerStatus");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component component, const fmi2StatusKind s, fmi2Boolean *value) {
    Instance *c = component;
    if (c && s == fmi2Terminated && value) { *value = fmi2False; return fmi2OK; }
    return status_query(component, "fmi2GetBooleanStatus");
}
fmi2Status fmi2GetStringStatus(fmi2Component component, const fmi2StatusKind s, fmi2String *value) {
    (void)s; (void)value;
    return status_query(component, "fmi2GetStringStatus");
}
