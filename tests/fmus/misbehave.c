/* A test FMU (FMI 2.0 Co-Simulation) that misbehaves on purpose, for the isolation tests
 * (tests/misbehave_fmu.py builds it): x counts time (x' = 1) until t >= at, then the call named
 * by `mode` does what a broken FMU does.
 *
 * Real     0 x      output     = time
 *          1 at     parameter  s, when DoStep (or GetReal) misbehaves, default 0.5
 * Integer  0 mode   parameter  0 fine, 1 DoStep segfaults, 2 DoStep aborts, 3 DoStep calls exit(0),
 *                              4 DoStep busy-loops, 5 DoStep sleeps for ever, 6 FreeInstance
 *                              segfaults, 7 Terminate hangs, 8 GetReal segfaults, 9 ExitInitializationMode
 *                              calls exit(3), 10 DoStep fails logging a 100,000-character message
 *                              that starts with an escape sequence
 * An instance whose name contains "segv_at_instantiate" segfaults in fmi2Instantiate.
 */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "fmi2Functions.h"

typedef struct {
    double time, at;
    int mode;
    fmi2CallbackFunctions callbacks;
    char name[64];
} Instance;

static void segfault(void) {
    raise(SIGSEGV);
}

static void hang(int busy) {
    volatile unsigned long spin = 0;
    for (;;) {
        if (busy) spin++;
        else pause();
    }
}

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
    (void)type; (void)guid; (void)location; (void)visible; (void)logging;
    if (!functions) return NULL;
    if (name && strstr(name, "segv_at_instantiate")) segfault();
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    c->callbacks = *functions;
    c->at = 0.5;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "misbehave");
    return c;
}

void fmi2FreeInstance(fmi2Component component) {
    Instance *c = (Instance *)component;
    if (c && c->mode == 6) segfault();
    free(c);
}
fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean tol, fmi2Real t, fmi2Real start,
                               fmi2Boolean stop, fmi2Real end) {
    (void)tol; (void)t; (void)stop; (void)end;
    ((Instance *)component)->time = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    if (((Instance *)component)->mode == 9) exit(3);
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component component) {
    if (((Instance *)component)->mode == 7) hang(0);
    return fmi2OK;
}
fmi2Status fmi2Reset(fmi2Component component) { ((Instance *)component)->time = 0.0; return fmi2OK; }

fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *c = (Instance *)component;
    if (c->mode == 8 && c->time >= c->at) segfault();
    for (size_t i = 0; i < n; i++) {
        if (vr[i] == 0) value[i] = c->time;
        else if (vr[i] == 1) value[i] = c->at;
        else return refuse(component, "fmi2GetReal: unknown value reference");
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 1) return refuse(component, "fmi2SetReal: not settable");
        ((Instance *)component)->at = value[i];
    }
    return fmi2OK;
}
fmi2Status fmi2GetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n, fmi2Integer value[]) {
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 0) return refuse(component, "fmi2GetInteger: unknown value reference");
        value[i] = ((Instance *)component)->mode;
    }
    return fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component component, const fmi2ValueReference vr[], size_t n,
                          const fmi2Integer value[]) {
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != 0) return refuse(component, "fmi2SetInteger: not settable");
        ((Instance *)component)->mode = value[i];
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

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real t, fmi2Real h, fmi2Boolean no_prior) {
    Instance *c = (Instance *)component;
    (void)no_prior;
    if (t >= c->at) {
        switch (c->mode) {
        case 1: segfault(); break;
        case 2: abort();
        case 3: exit(0);
        case 4: hang(1); break;
        case 5: hang(0); break;
        case 10: {
            static char text[100001];
            memset(text, 'x', sizeof text - 1);
            memcpy(text, "\x1b[31mred", 8);
            return refuse(component, text);
        }
        default: break;
        }
    }
    c->time = t + h;
    return fmi2OK;
}
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return refuse(c, "no FMU state"); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)s; return refuse(c, "no FMU state"); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return refuse(c, "no FMU state"); }

#include "fmi2_unsupported.h"
