/* A test FMU (FMI 2.0 Model Exchange only): the bouncing ball of ball_model.h, written for the
 * engine's tests (tests/ball_fmus.py builds it and its modelDescription.xml). The engine
 * integrates it: state events (the floor), a time event (tSwitch), a continuous input, an FMU
 * asking to end the simulation (maxBounces). Value references per type, as FMI 2.0 numbers them:
 *
 * Real     0 h  1 der(h)  2 v  3 der(v)  4 g  5 e  6 a (input)  7 tSwitch
 * Integer  0 count (output)  1 maxBounces (parameter)
 * Boolean  0 late (output)  1 frozen (discrete input: set only in Initialization or Event Mode,
 *          as FMI 2.0 requires of a discrete input of a Model Exchange FMU)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "ball_model.h"

/* The states of an instance, and the ones each value-setting call is allowed in. */
enum { INSTANTIATED = 1, INITIALIZATION = 2, EVENT = 4, CONTINUOUS = 8 };
#define SET_CONTINUOUS (INSTANTIATED | INITIALIZATION | EVENT | CONTINUOUS)
#define SET_DISCRETE (INSTANTIATED | INITIALIZATION | EVENT)

typedef struct {
    Ball ball;
    int mode;
    fmi2CallbackFunctions callbacks;
    char name[64];
} Instance;

static fmi2Status refuse(fmi2Component component, const char *message) {
    Instance *c = component;
    if (c && c->callbacks.logger)
        c->callbacks.logger(c->callbacks.componentEnvironment, c->name, fmi2Error, "error", message);
    return fmi2Error;
}

#define CHECK(c) if (!(c)) return fmi2Error

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) {
    (void)on; (void)n; (void)cat;
    CHECK(c);
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging) {
    (void)guid; (void)location; (void)visible; (void)logging;
    if (type != fmi2ModelExchange || !functions) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    c->callbacks = *functions;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "ball");
    ball_defaults(&c->ball);
    c->mode = INSTANTIATED;
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol, fmi2Real t, fmi2Real start, fmi2Boolean stop,
                               fmi2Real end) {
    (void)tol; (void)t; (void)stop; (void)end;
    CHECK(c);
    ((Instance *)c)->ball.time = start;
    return fmi2OK;
}
static fmi2Status enter(fmi2Component c, int mode) {
    CHECK(c);
    ((Instance *)c)->mode = mode;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return enter(c, INITIALIZATION); }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return enter(c, EVENT); }
fmi2Status fmi2Terminate(fmi2Component c) { CHECK(c); return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) {
    CHECK(c);
    ball_defaults(&((Instance *)c)->ball);
    return enter(c, INSTANTIATED);
}

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *c = component;
    CHECK(c);
    const Ball *b = &c->ball;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: value[i] = b->h; break;
        case 1: value[i] = ball_height_rate(b); break;
        case 2: value[i] = b->v; break;
        case 3: value[i] = ball_acceleration(b); break;
        case 4: value[i] = b->g; break;
        case 5: value[i] = b->e; break;
        case 6: value[i] = b->a; break;
        case 7: value[i] = b->t_switch; break;
        default: return refuse(c, "fmi2GetReal: no such Real");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *c = component;
    CHECK(c);
    Ball *b = &c->ball;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: b->h = value[i]; break;
        case 2: b->v = value[i]; break;
        case 4: b->g = value[i]; break;
        case 5: b->e = value[i]; break;
        case 6: b->a = value[i]; break;
        case 7: b->t_switch = value[i]; break;
        default: return refuse(c, "fmi2SetReal: not a settable Real");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    Instance *c = component;
    CHECK(c);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) value[i] = c->ball.count;
        else if (vr[i] == 1) value[i] = c->ball.max_bounces;
        else return refuse(c, "fmi2GetInteger: no such Integer");
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    Instance *c = component;
    CHECK(c);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 1) c->ball.max_bounces = value[i];
        else return refuse(c, "fmi2SetInteger: not a settable Integer");
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    Instance *c = component;
    CHECK(c);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) value[i] = c->ball.late ? fmi2True : fmi2False;
        else if (vr[i] == 1) value[i] = c->ball.frozen ? fmi2True : fmi2False;
        else return refuse(c, "fmi2GetBoolean: no such Boolean");
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean value[]) {
    Instance *c = component;
    CHECK(c);
    if (!(c->mode & SET_DISCRETE))
        return refuse(c, "fmi2SetBoolean: the discrete input frozen cannot be set in Continuous-Time Mode");
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 1) return refuse(c, "fmi2SetBoolean: not the Boolean input");
        c->ball.frozen = value[i] != fmi2False;
    }
    return fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    (void)vr; (void)n; (void)value;
    return refuse(c, "fmi2GetString: no String");
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[]) {
    (void)vr; (void)n; (void)value;
    return refuse(c, "fmi2SetString: no String");
}

/* FMU states: a copy of the instance. */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    CHECK(c && s);
    Instance *copy = malloc(sizeof(Instance));
    if (!copy) return refuse(c, "out of memory");
    memcpy(copy, c, sizeof(Instance));
    *s = copy;
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    CHECK(c);
    if (!s) return refuse(c, "no FMU state given");
    memcpy(c, s, sizeof(Instance));
    return fmi2OK;
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    CHECK(c);
    if (s) { free(*s); *s = NULL; }
    return fmi2OK;
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s; (void)n;
    return refuse(c, "no serialized FMU state");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s; (void)b; (void)n;
    return refuse(c, "no serialized FMU state");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)b; (void)n; (void)s;
    return refuse(c, "no serialized FMU state");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[],
                                        fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz;
    return refuse(c, "no directional derivatives");
}

/* --- Model Exchange ------------------------------------------------------------------------- */
fmi2Status fmi2EnterEventMode(fmi2Component c) { return enter(c, EVENT); }
fmi2Status fmi2NewDiscreteStates(fmi2Component component, fmi2EventInfo *info) {
    Instance *c = component;
    CHECK(c && info);
    int before = c->ball.count;
    info->terminateSimulation = ball_event(&c->ball) ? fmi2True : fmi2False;
    info->newDiscreteStatesNeeded = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = c->ball.count != before ? fmi2True : fmi2False;
    double next = ball_next_time_event(&c->ball);
    info->nextEventTimeDefined = isfinite(next) ? fmi2True : fmi2False;
    info->nextEventTime = isfinite(next) ? next : 0.0;
    return fmi2OK;
}
fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { return enter(c, CONTINUOUS); }
fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean no_prior, fmi2Boolean *event,
                                       fmi2Boolean *terminate) {
    (void)no_prior;
    CHECK(c && event && terminate);
    *event = fmi2False;
    *terminate = fmi2False;
    return fmi2OK;
}
fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    CHECK(c);
    ((Instance *)c)->ball.time = time;
    return fmi2OK;
}
fmi2Status fmi2SetContinuousStates(fmi2Component component, const fmi2Real x[], size_t n) {
    Instance *c = component;
    CHECK(c && n == 2);
    c->ball.h = x[0];
    c->ball.v = x[1];
    return fmi2OK;
}
fmi2Status fmi2GetDerivatives(fmi2Component component, fmi2Real dx[], size_t n) {
    Instance *c = component;
    CHECK(c && n == 2);
    dx[0] = ball_height_rate(&c->ball);
    dx[1] = ball_acceleration(&c->ball);
    return fmi2OK;
}
fmi2Status fmi2GetEventIndicators(fmi2Component component, fmi2Real z[], size_t n) {
    Instance *c = component;
    CHECK(c && n == 1);
    z[0] = ball_indicator(&c->ball);
    return fmi2OK;
}
fmi2Status fmi2GetContinuousStates(fmi2Component component, fmi2Real x[], size_t n) {
    Instance *c = component;
    CHECK(c && n == 2);
    x[0] = c->ball.h;
    x[1] = c->ball.v;
    return fmi2OK;
}
fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x[], size_t n) {
    CHECK(c && n == 2);
    x[0] = x[1] = 1.0;
    return fmi2OK;
}
