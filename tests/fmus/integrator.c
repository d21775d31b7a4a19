/* A test FMU (FMI 2.0, Co-Simulation and Model Exchange) whose answer is known exactly: an
 * integrator x' = u, written for the input-timing tests (tests/integrator_fmu.py builds it).
 *
 * Real     0 x        output    the state, x(0) = 0
 *          1 der(x)   local     = u
 *          2 u        input     continuous
 *          3 y        output    = u (direct feedthrough)
 *          4 r        output    discrete: a relay, 1 where u > 0.5 else 0, taken at events only
 * Integer  0 k        input     discrete
 *          1 m        output    = k (direct feedthrough)
 *
 * Co-Simulation: fmi2DoStep integrates x exactly with u held over the step (x += u h) and sets r
 * from u; Model Exchange: the importer integrates x' = u; one event indicator, u - 0.5: r changes
 * in Event Mode only, so an importer that sets a jumping continuous u without an event iteration
 * leaves r where it was. The FMU state can be saved and restored.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct {
    double time, x, u, r;
    int k;
    fmi2Type type;
    fmi2CallbackFunctions callbacks;
    char name[64];
} Instance;

static fmi2Status refuse(fmi2Component component, const char *message) {
    Instance *c = (Instance *)component;
    if (c && c->callbacks.logger)
        c->callbacks.logger(c->callbacks.componentEnvironment, c->name, fmi2Error, "error", message);
    return fmi2Error;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)c; (void)on; (void)n; (void)cat;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging) {
    (void)guid; (void)location; (void)visible; (void)logging;
    if (!functions) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    c->callbacks = *functions;
    c->type = type;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "integrator");
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean tol, fmi2Real t, fmi2Real start,
                               fmi2Boolean stop, fmi2Real end) {
    (void)tol; (void)t; (void)stop; (void)end;
    ((Instance *)component)->time = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
static double relay(double u) { return u > 0.5 ? 1.0 : 0.0; }
fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    Instance *c = (Instance *)component;
    c->r = relay(c->u);
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component component) {
    Instance *c = (Instance *)component;
    c->time = c->x = c->u = c->r = 0.0;
    c->k = 0;
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *c = (Instance *)component;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: value[i] = c->x; break;
        case 1: value[i] = c->u; break;
        case 2: value[i] = c->u; break;
        case 3: value[i] = c->u; break;
        case 4: value[i] = c->r; break;
        default: return refuse(component, "fmi2GetReal: unknown value reference");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    Instance *c = (Instance *)component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] > 1) return refuse(component, "fmi2GetInteger: unknown value reference");
        value[i] = c->k;
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *c = (Instance *)component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) c->x = value[i];
        else if (vr[i] == 2) c->u = value[i];
        else return refuse(component, "fmi2SetReal: not settable");
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    Instance *c = (Instance *)component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 0) return refuse(component, "fmi2SetInteger: not settable");
        c->k = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    (void)vr; (void)value;
    return n ? refuse(c, "no Boolean variables") : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[]) {
    (void)vr; (void)value;
    return n ? refuse(c, "no Boolean variables") : fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    (void)vr; (void)value;
    return n ? refuse(c, "no String variables") : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    (void)vr; (void)value;
    return n ? refuse(c, "no String variables") : fmi2OK;
}

/* --- Co-Simulation ------------------------------------------------------------------------- */
fmi2Status fmi2DoStep(fmi2Component component, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    Instance *c = (Instance *)component;
    (void)no_prior;
    c->r = relay(c->u);
    c->x += c->u * h;
    c->time = t + h;
    return fmi2OK;
}

/* --- Model Exchange ------------------------------------------------------------------------ */
fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2NewDiscreteStates(fmi2Component component, fmi2EventInfo *info) {
    Instance *c = (Instance *)component;
    c->r = relay(c->u);
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    info->nextEventTimeDefined = fmi2False;
    info->nextEventTime = 0.0;
    return fmi2OK;
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean no_prior, fmi2Boolean *enter_event_mode,
                                       fmi2Boolean *terminate) {
    (void)c; (void)no_prior;
    *enter_event_mode = fmi2False;
    *terminate = fmi2False;
    return fmi2OK;
}
fmi2Status fmi2SetTime(fmi2Component component, fmi2Real t) { ((Instance *)component)->time = t; return fmi2OK; }
fmi2Status fmi2SetContinuousStates(fmi2Component component, const fmi2Real x[], size_t n) {
    if (n != 1) return refuse(component, "one state");
    ((Instance *)component)->x = x[0];
    return fmi2OK;
}
fmi2Status fmi2GetDerivatives(fmi2Component component, fmi2Real dx[], size_t n) {
    if (n != 1) return refuse(component, "one state");
    dx[0] = ((Instance *)component)->u;
    return fmi2OK;
}
fmi2Status fmi2GetEventIndicators(fmi2Component component, fmi2Real z[], size_t n) {
    if (n != 1) return refuse(component, "one event indicator");
    z[0] = ((Instance *)component)->u - 0.5;
    return fmi2OK;
}
fmi2Status fmi2GetContinuousStates(fmi2Component component, fmi2Real x[], size_t n) {
    if (n != 1) return refuse(component, "one state");
    x[0] = ((Instance *)component)->x;
    return fmi2OK;
}
fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component component, fmi2Real nominal[], size_t n) {
    if (n != 1) return refuse(component, "one state");
    nominal[0] = 1.0;
    return fmi2OK;
}

/* --- FMU state (the iterative master repeats steps) and what is not supported ------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *state) {
    Instance *copy = *state ? (Instance *)*state : malloc(sizeof(Instance));
    if (!copy) return refuse(component, "out of memory");
    *copy = *(Instance *)component;
    *state = copy;
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate state) {
    if (!state) return refuse(component, "no state given");
    *(Instance *)component = *(Instance *)state;
    return fmi2OK;
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)c;
    free(*state);
    *state = NULL;
    return fmi2OK;
}

#include "fmi2_unsupported.h"
