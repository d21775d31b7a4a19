/* A test FMU (FMI 2.0 Co-Simulation) with a variable of every FMI 2.0 type, written for the
 * engine's tests (tests/typed_fmu.py builds it and its modelDescription.xml). Value references
 * are shared across types, as FMI 2.0 allows: each type numbers its variables from 0.
 *
 * Real     0 x        output    time since the start [s]
 *          1 u        input     continuous
 *          2 y        output    gain * u (direct feedthrough)
 *          3 gain     parameter
 * Integer  0 counter  output    completed communication steps
 *          1 k        input     discrete
 *          2 k2       output    k + counter (direct feedthrough)
 *          3 stopAfter parameter  > 0: the step that completes that many ends the simulation
 *                                (its work done, fmi2Discard with fmi2Terminated true and
 *                                fmi2LastSuccessfulTime at its end, as the Reference-FMUs' Stair)
 * Enum.    4 mode     output    1 + counter mod 3 (items one, two, three)
 * Boolean  0 even     output    counter is even
 *          1 b        input     discrete
 *          2 notb     output    not b (direct feedthrough)
 * String   0 label    parameter (kept, returned by fmi2GetString)
 *          1 s        input
 *          2 sout     output    label + ":" + s (direct feedthrough)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

typedef struct {
    double x, u, gain;
    int counter, k, stop_after;
    int b;
    char label[128], s[128], sout[260];
    int terminated;
    fmi2CallbackFunctions callbacks;
    char name[64];
} Instance;

static fmi2Status refuse(Instance *c, const char *message) {
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

static void defaults(Instance *c) {
    c->x = 0.0; c->u = 0.0; c->gain = 2.0;
    c->counter = 0; c->k = 0; c->stop_after = 0; c->b = fmi2False; c->terminated = 0;
    strcpy(c->label, "none");
    strcpy(c->s, "");
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible, fmi2Boolean logging) {
    (void)guid; (void)location; (void)visible; (void)logging;
    if (type != fmi2CoSimulation || !functions) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    c->callbacks = *functions;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "typed");
    defaults(c);
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol, fmi2Real t, fmi2Real start, fmi2Boolean stop,
                               fmi2Real end) {
    (void)tol; (void)t; (void)stop; (void)end;
    ((Instance *)c)->x = 0.0;
    (void)start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { defaults((Instance *)c); return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: value[i] = c->x; break;
        case 1: value[i] = c->u; break;
        case 2: value[i] = c->gain * c->u; break;
        case 3: value[i] = c->gain; break;
        default: return refuse(c, "fmi2GetReal: no such Real");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: value[i] = c->counter; break;
        case 1: value[i] = c->k; break;
        case 2: value[i] = c->k + c->counter; break;
        case 3: value[i] = c->stop_after; break;
        case 4: value[i] = 1 + c->counter % 3; break;
        default: return refuse(c, "fmi2GetInteger: no such Integer");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        switch (vr[i]) {
        case 0: value[i] = c->counter % 2 == 0; break;
        case 1: value[i] = c->b; break;
        case 2: value[i] = !c->b; break;
        default: return refuse(c, "fmi2GetBoolean: no such Boolean");
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2String value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) value[i] = c->label;
        else if (vr[i] == 1) value[i] = c->s;
        else if (vr[i] == 2) {
            snprintf(c->sout, sizeof c->sout, "%s:%s", c->label, c->s);
            value[i] = c->sout;
        } else return refuse(c, "fmi2GetString: no such String");
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 1) c->u = value[i];
        else if (vr[i] == 3) c->gain = value[i];
        else return refuse(c, "fmi2SetReal: not an input or parameter Real");
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 1) c->k = value[i];
        else if (vr[i] == 3) c->stop_after = value[i];
        else return refuse(c, "fmi2SetInteger: not an input or parameter Integer");
    }
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Boolean value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 1) c->b = value[i] != fmi2False;
        else return refuse(c, "fmi2SetBoolean: not an input Boolean");
    }
    return fmi2OK;
}

fmi2Status fmi2SetString(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                         const fmi2String value[]) {
    Instance *c = component;
    for (size_t i = 0; i < n; i++) {
        if (!value[i]) return refuse(c, "fmi2SetString: no text given");
        if (vr[i] == 0) snprintf(c->label, sizeof c->label, "%s", value[i]);
        else if (vr[i] == 1) snprintf(c->s, sizeof c->s, "%s", value[i]);
        else return refuse(c, "fmi2SetString: not the String parameter or input");
    }
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    Instance *c = component;
    (void)no_prior;
    if (c->terminated) return refuse(c, "fmi2DoStep: the simulation has ended");
    c->x = t + h;
    c->counter += 1;
    if (c->stop_after > 0 && c->counter >= c->stop_after) {
        c->terminated = 1;
        /* Formatted here: a ctypes logger (FMPy's callback type) does not receive variadic arguments. */
        char message[64];
        snprintf(message, sizeof message, "stopAfter = %d steps reached", c->stop_after);
        if (c->callbacks.logger)
            c->callbacks.logger(c->callbacks.componentEnvironment, c->name, fmi2Discard, "terminate", message);
        return fmi2Discard;
    }
    return fmi2OK;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component component, const fmi2StatusKind kind, fmi2Boolean *value) {
    Instance *c = component;
    if (kind != fmi2Terminated) return fmi2Discard;
    *value = c->terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component component, const fmi2StatusKind kind, fmi2Real *value) {
    Instance *c = component;
    if (kind != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = c->x;
    return fmi2OK;
}

/* FMU states: a copy of the instance (the model description may say it has none: a variant). */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    Instance *copy = malloc(sizeof(Instance));
    if (!copy) return refuse(c, "out of memory");
    memcpy(copy, c, sizeof(Instance));
    *s = copy;
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    if (!s) return refuse(c, "no FMU state given");
    memcpy(c, s, sizeof(Instance));
    return fmi2OK;
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)c;
    if (s) { free(*s); *s = NULL; }
    return fmi2OK;
}

/* Not supported: the capability flags say so. */
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)s; (void)n;
    return refuse(c, "no FMU state");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)s; (void)b; (void)n;
    return refuse(c, "no FMU state");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)b; (void)n; (void)s;
    return refuse(c, "no FMU state");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[],
                                        fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)du; (void)dz;
    return refuse(c, "no directional derivatives");
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return refuse(c, "cannot interpolate inputs");
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return refuse(c, "no output derivatives");
}
fmi2Status fmi2CancelStep(fmi2Component c) { return refuse(c, "no asynchronous steps"); }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) {
    (void)k; (void)v;
    return refuse(c, "no status");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) {
    (void)k; (void)v;
    return refuse(c, "no status");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) {
    (void)k; (void)v;
    return refuse(c, "no status");
}
