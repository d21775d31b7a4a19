/* A test FMU (FMI 3.0 Co-Simulation) with array variables, written for the engine's tests
 * (tests/arrays_fmu.py builds it and its modelDescription.xml). Value references:
 *
 *  0 time     independent
 *  1 u[3]     Float64 input, start 0 0 0
 *  2 y[3]     Float64 output, y = gain u + offset (direct feedthrough)
 *  3 gain     Float64 parameter, start 2
 *  4 offset[3] Float64 parameter, start 1 2 3
 *  5 m[2,2]   Float64 output, [[t, 2t], [3t, 4t]] (row-major: m[1,2] = 2t)
 *  6 k[2]     Int32 output, [steps, -steps]
 *  7 s        Float64 output, the sum of u (a scalar)
 *
 * An array is set and got whole (FMI 3.0): its elements follow each other in the value array.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

typedef struct {
    double time, u[3], gain, offset[3];
    int steps;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
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
    c->time = 0.0;
    for (int i = 0; i < 3; i++) c->u[i] = 0.0;
    c->gain = 2.0;
    c->offset[0] = 1.0; c->offset[1] = 2.0; c->offset[2] = 3.0;
    c->steps = 0;
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
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)environment; (void)log;
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                         fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,
                                         const fmi3ValueReference required[], size_t n_required,
                                         fmi3InstanceEnvironment environment, fmi3LogMessageCallback log,
                                         fmi3IntermediateUpdateCallback update) {
    (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)early_return; (void)required;
    (void)n_required; (void)update;
    if (event_mode) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    c->environment = environment;
    c->log = log;
    defaults(c);
    return c;
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
    ((Instance *)instance)->time = start;
    return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3EnterEventMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance instance) { CHECK(instance); return fmi3OK; }
fmi3Status fmi3Reset(fmi3Instance instance) { CHECK(instance); defaults(instance); return fmi3OK; }

/* --- values: each reference gives as many values as its variable has elements --------------- */
fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Float64 values[],
                          size_t n_values) {
    Instance *c = instance;
    CHECK(c);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: CHECK(k + 1 <= n_values); values[k++] = c->time; break;
        case 1: CHECK(k + 3 <= n_values); for (int j = 0; j < 3; j++) values[k++] = c->u[j]; break;
        case 2: CHECK(k + 3 <= n_values); for (int j = 0; j < 3; j++) values[k++] = c->gain * c->u[j] + c->offset[j];
                break;
        case 3: CHECK(k + 1 <= n_values); values[k++] = c->gain; break;
        case 4: CHECK(k + 3 <= n_values); for (int j = 0; j < 3; j++) values[k++] = c->offset[j]; break;
        case 5: CHECK(k + 4 <= n_values); for (int j = 0; j < 4; j++) values[k++] = (j + 1) * c->time; break;
        case 7: CHECK(k + 1 <= n_values); values[k++] = c->u[0] + c->u[1] + c->u[2]; break;
        default: return refuse(c, "fmi3GetFloat64: not a Float64 variable");
        }
    }
    return k == n_values ? fmi3OK : refuse(c, "fmi3GetFloat64: nValues is not the number of elements");
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, const fmi3Float64 values[],
                          size_t n_values) {
    Instance *c = instance;
    CHECK(c);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 1: CHECK(k + 3 <= n_values); for (int j = 0; j < 3; j++) c->u[j] = values[k++]; break;
        case 3: CHECK(k + 1 <= n_values); c->gain = values[k++]; break;
        case 4: CHECK(k + 3 <= n_values); for (int j = 0; j < 3; j++) c->offset[j] = values[k++]; break;
        default: return refuse(c, "fmi3SetFloat64: not a settable Float64 variable");
        }
    }
    return k == n_values ? fmi3OK : refuse(c, "fmi3SetFloat64: nValues is not the number of elements");
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference vr[], size_t n, fmi3Int32 values[],
                        size_t n_values) {
    Instance *c = instance;
    CHECK(c);
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 6 || k + 2 > n_values) return refuse(c, "fmi3GetInt32: not the Int32 array k");
        values[k++] = c->steps;
        values[k++] = -c->steps;
    }
    return k == n_values ? fmi3OK : refuse(c, "fmi3GetInt32: nValues is not the number of elements");
}

REFUSED(fmi3GetFloat32, const fmi3ValueReference vr[], size_t n, fmi3Float32 values[], size_t n_values)
REFUSED(fmi3GetInt8, const fmi3ValueReference vr[], size_t n, fmi3Int8 values[], size_t n_values)
REFUSED(fmi3GetUInt8, const fmi3ValueReference vr[], size_t n, fmi3UInt8 values[], size_t n_values)
REFUSED(fmi3GetInt16, const fmi3ValueReference vr[], size_t n, fmi3Int16 values[], size_t n_values)
REFUSED(fmi3GetUInt16, const fmi3ValueReference vr[], size_t n, fmi3UInt16 values[], size_t n_values)
REFUSED(fmi3GetUInt32, const fmi3ValueReference vr[], size_t n, fmi3UInt32 values[], size_t n_values)
REFUSED(fmi3GetInt64, const fmi3ValueReference vr[], size_t n, fmi3Int64 values[], size_t n_values)
REFUSED(fmi3GetUInt64, const fmi3ValueReference vr[], size_t n, fmi3UInt64 values[], size_t n_values)
REFUSED(fmi3GetBoolean, const fmi3ValueReference vr[], size_t n, fmi3Boolean values[], size_t n_values)
REFUSED(fmi3GetString, const fmi3ValueReference vr[], size_t n, fmi3String values[], size_t n_values)
REFUSED(fmi3SetFloat32, const fmi3ValueReference vr[], size_t n, const fmi3Float32 values[], size_t n_values)
REFUSED(fmi3SetInt8, const fmi3ValueReference vr[], size_t n, const fmi3Int8 values[], size_t n_values)
REFUSED(fmi3SetUInt8, const fmi3ValueReference vr[], size_t n, const fmi3UInt8 values[], size_t n_values)
REFUSED(fmi3SetInt16, const fmi3ValueReference vr[], size_t n, const fmi3Int16 values[], size_t n_values)
REFUSED(fmi3SetUInt16, const fmi3ValueReference vr[], size_t n, const fmi3UInt16 values[], size_t n_values)
REFUSED(fmi3SetInt32, const fmi3ValueReference vr[], size_t n, const fmi3Int32 values[], size_t n_values)
REFUSED(fmi3SetUInt32, const fmi3ValueReference vr[], size_t n, const fmi3UInt32 values[], size_t n_values)
REFUSED(fmi3SetInt64, const fmi3ValueReference vr[], size_t n, const fmi3Int64 values[], size_t n_values)
REFUSED(fmi3SetUInt64, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 values[], size_t n_values)
REFUSED(fmi3SetBoolean, const fmi3ValueReference vr[], size_t n, const fmi3Boolean values[], size_t n_values)
REFUSED(fmi3SetString, const fmi3ValueReference vr[], size_t n, const fmi3String values[], size_t n_values)
REFUSED(fmi3GetBinary, const fmi3ValueReference vr[], size_t n, size_t sizes[], fmi3Binary values[], size_t n_values)
REFUSED(fmi3SetBinary, const fmi3ValueReference vr[], size_t n, const size_t sizes[], const fmi3Binary values[],
        size_t n_values)
REFUSED(fmi3GetClock, const fmi3ValueReference vr[], size_t n, fmi3Clock values[])
REFUSED(fmi3SetClock, const fmi3ValueReference vr[], size_t n, const fmi3Clock values[])
REFUSED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
REFUSED(fmi3GetVariableDependencies, fmi3ValueReference dependent, size_t element[], fmi3ValueReference independents[],
        size_t elements[], fmi3DependencyKind kinds[], size_t n)
REFUSED(fmi3GetFMUState, fmi3FMUState *state)
REFUSED(fmi3SetFMUState, fmi3FMUState state)
REFUSED(fmi3FreeFMUState, fmi3FMUState *state)
#include "fmi3_unsupported.h"
REFUSED(fmi3UpdateDiscreteStates, fmi3Boolean *again, fmi3Boolean *terminate, fmi3Boolean *nominals_changed,
        fmi3Boolean *values_changed, fmi3Boolean *next_defined, fmi3Float64 *next_time)
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { return refuse(instance, "no Model Exchange"); }
REFUSED(fmi3CompletedIntegratorStep, fmi3Boolean no_prior, fmi3Boolean *event, fmi3Boolean *terminate)
REFUSED(fmi3SetTime, fmi3Float64 time)
REFUSED(fmi3SetContinuousStates, const fmi3Float64 x[], size_t n)
REFUSED(fmi3GetContinuousStateDerivatives, fmi3Float64 dx[], size_t n)
REFUSED(fmi3GetEventIndicators, fmi3Float64 z[], size_t n)
REFUSED(fmi3GetContinuousStates, fmi3Float64 x[], size_t n)
REFUSED(fmi3GetNominalsOfContinuousStates, fmi3Float64 nominals[], size_t n)
REFUSED(fmi3GetNumberOfEventIndicators, size_t *n)
REFUSED(fmi3GetNumberOfContinuousStates, size_t *n)

/* --- Co-Simulation -------------------------------------------------------------------------- */
fmi3Status fmi3EnterStepMode(fmi3Instance instance) { CHECK(instance); return fmi3OK; }

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_prior,
                      fmi3Boolean *event, fmi3Boolean *terminate, fmi3Boolean *early, fmi3Float64 *last) {
    Instance *c = instance;
    (void)no_prior;
    CHECK(c && event && terminate && early && last);
    if (!(h > 0.0)) return refuse(c, "fmi3DoStep: the step must be > 0");
    c->time = t + h;
    c->steps++;
    *event = fmi3False;
    *early = fmi3False;
    *terminate = fmi3False;
    *last = c->time;
    return fmi3OK;
}
