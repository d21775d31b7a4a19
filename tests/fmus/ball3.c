/* A test FMU (FMI 3.0, Co-Simulation and Model Exchange): the bouncing ball of ball_model.h,
 * written for the engine's tests (tests/ball_fmus.py builds it and its modelDescription.xml),
 * with a variable of each FMI 3.0 scalar type the tests exchange. Value references are unique
 * across all variables, as FMI 3.0 requires:
 *
 *  0 time      independent            10 tSwitch   Float64 parameter [s]
 *  1 h         Float64 output, state  11 maxBounces Int32 parameter
 *  2 der(h)    Float64 local          12 h32       Float32 output (h)
 *  3 v         Float64 output, state  13 count64   Int64 output (count)
 *  4 der(v)    Float64 local          14 label     String parameter
 *  5 g         Float64 parameter      15 tag       String output (label + "!")
 *  6 e         Float64 parameter      16 gainU8    UInt8 parameter
 *  7 a         Float64 input          17 countU8   UInt8 output (count * gainU8 mod 256)
 *  8 count     Int32 output           18 z         Float64 local, the event indicator (h)
 *  9 late      Boolean output
 *
 * Co-Simulation steps the exact free flight (ball_advance); Model Exchange gives the engine the
 * derivatives, the event indicator and the time event to integrate.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "ball_model.h"

typedef struct {
    Ball ball;
    char label[128], tag[130];
    fmi3UInt8 gain;
    int co_simulation;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
    char name[64];
} Instance;

static fmi3Status refuse(fmi3Instance instance, const char *message) {
    Instance *c = instance;
    if (c && c->log) c->log(c->environment, fmi3Error, "error", message);
    return fmi3Error;
}

#define CHECK(c) if (!(c)) return fmi3Error
#define REFUSED(name, ...) \
    fmi3Status name(fmi3Instance instance, __VA_ARGS__) { return refuse(instance, #name ": not supported"); }

static void defaults(Instance *c) {
    ball_defaults(&c->ball);
    strcpy(c->label, "ball");
    c->gain = 3;
}

static fmi3Instance instantiate(fmi3String name, fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                int co_simulation) {
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "ball");
    c->environment = environment;
    c->log = log;
    c->co_simulation = co_simulation;
    defaults(c);
    return c;
}

const char *fmi3GetVersion(void) { return fmi3Version; }
fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean on, size_t n, const fmi3String categories[]) {
    (void)on; (void)n; (void)categories;
    CHECK(instance);
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                          fmi3Boolean logging, fmi3InstanceEnvironment environment,
                                          fmi3LogMessageCallback log) {
    (void)token; (void)resources; (void)visible; (void)logging;
    return instantiate(name, environment, log, 0);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                         fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,
                                         const fmi3ValueReference required[], size_t n_required,
                                         fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                         fmi3IntermediateUpdateCallback update) {
    (void)token; (void)resources; (void)visible; (void)logging; (void)early_return; (void)required;
    (void)n_required; (void)update;
    if (event_mode) return NULL; /* no Event Mode in Co-Simulation */
    return instantiate(name, environment, log, 1);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                               fmi3Boolean visible, fmi3Boolean logging,
                                               fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                               fmi3ClockUpdateCallback clock, fmi3LockPreemptionCallback lock,
                                               fmi3UnlockPreemptionCallback unlock) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)environment; (void)log;
    (void)clock; (void)lock; (void)unlock;
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) { free(instance); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean tolerance_defined, fmi3Float64 tolerance,
                                       fmi3Float64 start, fmi3Boolean stop_defined, fmi3Float64 stop) {
    (void)tolerance_defined; (void)tolerance; (void)stop_defined; (void)stop;
    CHECK(instance);
    ((Instance *)instance)->ball.time = start;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3EnterEventMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance instance) { CHECK(instance); defaults(instance); return fmi3OK; }

/* --- values ------------------------------------------------------------------------------- */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float64 values[],
                          size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    const Ball *b = &c->ball;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: values[i] = b->time; break;
        case 1: values[i] = b->h; break;
        case 2: values[i] = ball_height_rate(b); break;
        case 3: values[i] = b->v; break;
        case 4: values[i] = ball_acceleration(b); break;
        case 5: values[i] = b->g; break;
        case 6: values[i] = b->e; break;
        case 7: values[i] = b->a; break;
        case 10: values[i] = b->t_switch; break;
        case 18: values[i] = ball_indicator(b); break;
        default: return refuse(c, "fmi3GetFloat64: no such Float64");
        }
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n,
                          const fmi3Float64 values[], size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    Ball *b = &c->ball;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 1: b->h = values[i]; break;
        case 3: b->v = values[i]; break;
        case 5: b->g = values[i]; break;
        case 6: b->e = values[i]; break;
        case 7: b->a = values[i]; break;
        case 10: b->t_switch = values[i]; break;
        default: return refuse(c, "fmi3SetFloat64: not a settable Float64");
        }
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float32 values[],
                          size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 12) return refuse(c, "fmi3GetFloat32: no such Float32");
        values[i] = (fmi3Float32)c->ball.h;
    }
    return fmi3OK;
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Int32 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 8) values[i] = c->ball.count;
        else if (vr[i] == 11) values[i] = c->ball.max_bounces;
        else return refuse(c, "fmi3GetInt32: no such Int32");
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Int32 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 11) c->ball.max_bounces = values[i];
        else return refuse(c, "fmi3SetInt32: not a settable Int32");
    }
    return fmi3OK;
}

fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Int64 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 13) return refuse(c, "fmi3GetInt64: no such Int64");
        values[i] = c->ball.count;
    }
    return fmi3OK;
}

fmi3Status fmi3GetUInt8(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3UInt8 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 16) values[i] = c->gain;
        else if (vr[i] == 17) values[i] = (fmi3UInt8)((c->ball.count * c->gain) % 256);
        else return refuse(c, "fmi3GetUInt8: no such UInt8");
    }
    return fmi3OK;
}

fmi3Status fmi3SetUInt8(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3UInt8 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 16) c->gain = values[i];
        else return refuse(c, "fmi3SetUInt8: not a settable UInt8");
    }
    return fmi3OK;
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Boolean values[],
                          size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 9) return refuse(c, "fmi3GetBoolean: no such Boolean");
        values[i] = c->ball.late ? fmi3True : fmi3False;
    }
    return fmi3OK;
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3String values[],
                         size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 14) values[i] = c->label;
        else if (vr[i] == 15) {
            snprintf(c->tag, sizeof c->tag, "%s!", c->label);
            values[i] = c->tag;
        } else return refuse(c, "fmi3GetString: no such String");
    }
    return fmi3OK;
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3String values[],
                         size_t n_values) {
    Instance *c = instance;
    CHECK(c && n_values >= n);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 14 || !values[i]) return refuse(c, "fmi3SetString: not the String parameter");
        snprintf(c->label, sizeof c->label, "%s", values[i]);
    }
    return fmi3OK;
}

REFUSED(fmi3GetInt8, const fmi3ValueReference vr[], size_t n, fmi3Int8 values[], size_t n_values)
REFUSED(fmi3GetInt16, const fmi3ValueReference vr[], size_t n, fmi3Int16 values[], size_t n_values)
REFUSED(fmi3GetUInt16, const fmi3ValueReference vr[], size_t n, fmi3UInt16 values[], size_t n_values)
REFUSED(fmi3GetUInt32, const fmi3ValueReference vr[], size_t n, fmi3UInt32 values[], size_t n_values)
REFUSED(fmi3GetUInt64, const fmi3ValueReference vr[], size_t n, fmi3UInt64 values[], size_t n_values)
REFUSED(fmi3SetFloat32, const fmi3ValueReference vr[], size_t n, const fmi3Float32 values[], size_t n_values)
REFUSED(fmi3SetInt8, const fmi3ValueReference vr[], size_t n, const fmi3Int8 values[], size_t n_values)
REFUSED(fmi3SetInt16, const fmi3ValueReference vr[], size_t n, const fmi3Int16 values[], size_t n_values)
REFUSED(fmi3SetUInt16, const fmi3ValueReference vr[], size_t n, const fmi3UInt16 values[], size_t n_values)
REFUSED(fmi3SetUInt32, const fmi3ValueReference vr[], size_t n, const fmi3UInt32 values[], size_t n_values)
REFUSED(fmi3SetInt64, const fmi3ValueReference vr[], size_t n, const fmi3Int64 values[], size_t n_values)
REFUSED(fmi3SetUInt64, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 values[], size_t n_values)
REFUSED(fmi3SetBoolean, const fmi3ValueReference vr[], size_t n, const fmi3Boolean values[], size_t n_values)
REFUSED(fmi3GetBinary, const fmi3ValueReference vr[], size_t n, size_t sizes[], fmi3Binary values[], size_t n_values)
REFUSED(fmi3SetBinary, const fmi3ValueReference vr[], size_t n, const size_t sizes[], const fmi3Binary values[],
        size_t n_values)
REFUSED(fmi3GetClock, const fmi3ValueReference vr[], size_t n, fmi3Clock values[])
REFUSED(fmi3SetClock, const fmi3ValueReference vr[], size_t n, const fmi3Clock values[])
REFUSED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
REFUSED(fmi3GetVariableDependencies, fmi3ValueReference dependent, size_t element[], fmi3ValueReference independents[],
        size_t elements[], fmi3DependencyKind kinds[], size_t n)

/* --- FMU states: a copy of the instance ------------------------------------------------------- */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    CHECK(instance && state);
    Instance *copy = malloc(sizeof(Instance));
    if (!copy) return refuse(instance, "out of memory");
    memcpy(copy, instance, sizeof(Instance));
    *state = copy;
    return fmi3OK;
}
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    CHECK(instance);
    if (!state) return refuse(instance, "fmi3SetFMUState: no state given");
    memcpy(instance, state, sizeof(Instance));
    return fmi3OK;
}
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    CHECK(instance);
    if (state) { free(*state); *state = NULL; }
    return fmi3OK;
}
#include "fmi3_unsupported.h"

/* --- Model Exchange ------------------------------------------------------------------------- */
fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *again, fmi3Boolean *terminate,
                                    fmi3Boolean *nominals_changed, fmi3Boolean *values_changed,
                                    fmi3Boolean *next_defined, fmi3Float64 *next_time) {
    Instance *c = instance;
    CHECK(c && again && terminate && nominals_changed && values_changed && next_defined && next_time);
    int before = c->ball.count;
    *terminate = ball_event(&c->ball) ? fmi3True : fmi3False;
    *again = fmi3False;
    *nominals_changed = fmi3False;
    *values_changed = c->ball.count != before ? fmi3True : fmi3False;
    double next = ball_next_time_event(&c->ball);
    *next_defined = isfinite(next) ? fmi3True : fmi3False;
    *next_time = isfinite(next) ? next : 0.0;
    return fmi3OK;
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean no_prior, fmi3Boolean *event,
                                       fmi3Boolean *terminate) {
    (void)no_prior;
    CHECK(instance && event && terminate);
    *event = fmi3False;
    *terminate = fmi3False;
    return fmi3OK;
}
fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    CHECK(instance);
    ((Instance *)instance)->ball.time = time;
    return fmi3OK;
}
fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 x[], size_t n) {
    Instance *c = instance;
    CHECK(c && n == 2);
    c->ball.h = x[0];
    c->ball.v = x[1];
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 dx[], size_t n) {
    Instance *c = instance;
    CHECK(c && n == 2);
    dx[0] = ball_height_rate(&c->ball);
    dx[1] = ball_acceleration(&c->ball);
    return fmi3OK;
}
fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 z[], size_t n) {
    Instance *c = instance;
    CHECK(c && n == 1);
    z[0] = ball_indicator(&c->ball);
    return fmi3OK;
}
fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 x[], size_t n) {
    Instance *c = instance;
    CHECK(c && n == 2);
    x[0] = c->ball.h;
    x[1] = c->ball.v;
    return fmi3OK;
}
fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t n) {
    CHECK(instance && n == 2);
    nominals[0] = nominals[1] = 1.0;
    return fmi3OK;
}
fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    CHECK(instance && n);
    *n = 1;
    return fmi3OK;
}
fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    CHECK(instance && n);
    *n = 2;
    return fmi3OK;
}

/* --- Co-Simulation -------------------------------------------------------------------------- */
fmi3Status fmi3EnterStepMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_prior,
                      fmi3Boolean *event, fmi3Boolean *terminate, fmi3Boolean *early, fmi3Float64 *last) {
    Instance *c = instance;
    (void)no_prior;
    CHECK(c && event && terminate && early && last);
    if (!c->co_simulation) return refuse(c, "fmi3DoStep: instantiated for Model Exchange");
    if (c->ball.terminated) return refuse(c, "fmi3DoStep: the simulation has ended");
    if (!(h > 0.0)) return refuse(c, "fmi3DoStep: the step must be > 0");
    c->ball.time = t;
    int ended = ball_advance(&c->ball, h);
    *event = fmi3False;
    *early = fmi3False;
    *terminate = ended ? fmi3True : fmi3False;
    *last = c->ball.time;
    if (ended && c->log) c->log(c->environment, fmi3OK, "terminate", "maxBounces reached");
    return fmi3OK;
}
