/* rover-cosim FMU runtime: the FMI 2.0 API (Model Exchange and Co-Simulation) over the core
 * (core.h). All state lives in the instance: many instances per process and per thread.
 *
 * Shape (after the Modelica Association's Reference-FMUs):
 * - FUNCTIONS: one table with, per FMI function, its name and the instance states in which it may
 *   be called; every function starts with ENTER(F), which checks the instance pointer and the
 *   state against that table.
 * - rc_fail() (instance.c): the one error path. It logs "<function>: <message>" under
 *   logStatusError and returns fmi2Error; with BROKEN it also puts the instance into the error
 *   state (a failed model evaluation or integration: only inspection, fmi2SetFMUstate, fmi2Reset,
 *   fmi2Terminate and fmi2FreeInstance are allowed then). A REJECTED call (bad argument, illegal
 *   state) is refused before anything changes: the instance stays where it was.
 * - Every array argument is checked for NULL, every value reference against the range (as an
 *   unsigned number), every serialized FMU state against its size, layout and checksum.
 * Nothing aborts, nothing is read or written out of bounds whatever the caller passes. */
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "core.h"

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


static const char *function_name(int f) { return f >= 0 && f < F_COUNT ? FUNCTIONS[f].name : "fmi2?"; }

/* The FMI 2.0 logger takes a printf format: pass the text itself with '%' doubled, so importers
 * that do not expand the variable arguments (e.g. ctypes callbacks) still get the text. */
static void log_text(const fmi2CallbackFunctions *cb, fmi2String name, fmi2Status status, const char *category,
                     const char *text) {
    if (!cb || !cb->logger) return;
    char escaped[2048];
    size_t j = 0;
    for (size_t i = 0; text[i] && j + 2 < sizeof escaped; i++) {
        if (text[i] == '%') escaped[j++] = '%';
        escaped[j++] = text[i];
    }
    escaped[j] = '\0';
    cb->logger(cb->componentEnvironment, name ? name : "?", status, category, escaped);
}

static void log_instance(const Instance *c, Status status, const char *category, const char *text) {
    log_text(c->layer_data, c->name, (fmi2Status)status, category, text);
}

static const Layer FMI2 = {function_name, log_instance};

/* The instance behind a component handle, if it may call f in its state; NULL otherwise
 * (a NULL handle cannot be reported: there is no logger without an instance). */
static Instance *enter(fmi2Component component, Function f) {
    Instance *c = component;
    if (!c) return NULL;
    if (c->mode < 0 || c->mode >= MODE_COUNT || !(FUNCTIONS[f].allowed & S(c->mode))) {
        rc_fail(c, f, REJECTED, "not allowed in the %s state", rc_mode_name(c->mode));
        return NULL;
    }
    return c;
}

#define ENTER(F)                       \
    Instance *c = enter(component, F); \
    if (!c) return fmi2Error

/* ---- common functions ------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component component, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    ENTER(F_SetDebugLogging);
    return (fmi2Status)rc_set_debug_logging(c, F_SetDebugLogging, loggingOn, nCategories, categories);
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
    /* The callbacks stay with the instance (the logger reads them), in memory of the host's. */
    fmi2CallbackFunctions *kept = functions->allocateMemory(1, sizeof *kept);
    if (!kept) return NULL;
    *kept = *functions;
    Instance *c = rc_new(instanceName, fmuType == fmi2ModelExchange ? KIND_MODEL_EXCHANGE : KIND_CO_SIMULATION,
                         loggingOn, &FMI2, kept, functions->allocateMemory, functions->freeMemory);
    if (!c) {
        log_text(functions, instanceName, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        functions->freeMemory(kept);
        return NULL;
    }
    return c;
}

void fmi2FreeInstance(fmi2Component component) {
    Instance *c = component;
    if (!c) return;
    void (*release)(void *) = c->release;
    void *kept = c->layer_data;
    rc_free(c);
    release(kept);
}

fmi2Status fmi2SetupExperiment(fmi2Component component, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    ENTER(F_SetupExperiment);
    return (fmi2Status)rc_setup(c, F_SetupExperiment, toleranceDefined, tolerance, startTime, stopTimeDefined,
                                stopTime);
}

fmi2Status fmi2EnterInitializationMode(fmi2Component component) {
    ENTER(F_EnterInitializationMode);
    return (fmi2Status)rc_enter_initialization(c);
}

fmi2Status fmi2ExitInitializationMode(fmi2Component component) {
    ENTER(F_ExitInitializationMode);
    return (fmi2Status)rc_exit_initialization(c, F_ExitInitializationMode);
}

fmi2Status fmi2Terminate(fmi2Component component) {
    ENTER(F_Terminate);
    return (fmi2Status)rc_terminate(c);
}

fmi2Status fmi2Reset(fmi2Component component) {
    ENTER(F_Reset);
    rc_reset(c);
    return fmi2OK;
}

/* ---- values ----------------------------------------------------------------------------- */
fmi2Status fmi2GetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    ENTER(F_GetReal);
    return (fmi2Status)rc_get_real(c, F_GetReal, vr, nvr, value);
}

fmi2Status fmi2SetReal(fmi2Component component, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    ENTER(F_SetReal);
    return (fmi2Status)rc_set_real(c, F_SetReal, vr, nvr, value);
}

#define NO_VARIABLES_OF_TYPE(function, F, type_name, value_type)                                       \
    fmi2Status function(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,             \
                        value_type value[]) {                                                           \
        ENTER(F);                                                                                       \
        NOT_NULL(F, vr, nvr);                                                                           \
        NOT_NULL(F, value, nvr);                                                                        \
        if (nvr == 0) return fmi2OK;                                                                    \
        return (fmi2Status)rc_fail(c, F, REJECTED, "value reference %u: this model has no %s variables", vr[0], type_name); \
    }
NO_VARIABLES_OF_TYPE(fmi2GetInteger, F_GetInteger, "Integer", fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2GetBoolean, F_GetBoolean, "Boolean", fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2GetString, F_GetString, "String", fmi2String)
NO_VARIABLES_OF_TYPE(fmi2SetInteger, F_SetInteger, "Integer", const fmi2Integer)
NO_VARIABLES_OF_TYPE(fmi2SetBoolean, F_SetBoolean, "Boolean", const fmi2Boolean)
NO_VARIABLES_OF_TYPE(fmi2SetString, F_SetString, "String", const fmi2String)


/* ---- FMU state -------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component component, fmi2FMUstate *state) {
    ENTER(F_GetFMUstate);
    return (fmi2Status)rc_get_state(c, F_GetFMUstate, state);
}

fmi2Status fmi2SetFMUstate(fmi2Component component, fmi2FMUstate state) {
    ENTER(F_SetFMUstate);
    return (fmi2Status)rc_set_state(c, F_SetFMUstate, state);
}

fmi2Status fmi2FreeFMUstate(fmi2Component component, fmi2FMUstate *state) {
    ENTER(F_FreeFMUstate);
    rc_free_state(c, state);
    return fmi2OK;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component component, fmi2FMUstate state, size_t *size) {
    ENTER(F_SerializedFMUstateSize);
    NOT_NULL(F_SerializedFMUstateSize, state, 1);
    NOT_NULL(F_SerializedFMUstateSize, size, 1);
    *size = rc_serialized_size(state);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component component, fmi2FMUstate state, fmi2Byte serialized[], size_t size) {
    ENTER(F_SerializeFMUstate);
    return (fmi2Status)rc_serialize(c, F_SerializeFMUstate, state, (unsigned char *)serialized, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component component, const fmi2Byte serialized[], size_t size,
                                   fmi2FMUstate *state) {
    ENTER(F_DeSerializeFMUstate);
    return (fmi2Status)rc_deserialize(c, F_DeSerializeFMUstate, (const unsigned char *)serialized, size, state);
}

/* ---- directional derivatives ------------------------------------------------------------ */
fmi2Status fmi2GetDirectionalDerivative(fmi2Component component, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    ENTER(F_GetDirectionalDerivative);
    return (fmi2Status)rc_directional(c, F_GetDirectionalDerivative, vUnknown_ref, nUnknown, vKnown_ref, nKnown,
                                      dvKnown, dvUnknown);
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
    return (fmi2Status)rc_completed_integrator_step(c, F_CompletedIntegratorStep);
}

fmi2Status fmi2SetTime(fmi2Component component, fmi2Real time) {
    ENTER(F_SetTime);
    return (fmi2Status)rc_set_time(c, F_SetTime, time);
}

fmi2Status fmi2SetContinuousStates(fmi2Component component, const fmi2Real x[], size_t nx) {
    ENTER(F_SetContinuousStates);
    return (fmi2Status)rc_set_states(c, F_SetContinuousStates, x, nx);
}

fmi2Status fmi2GetDerivatives(fmi2Component component, fmi2Real derivatives[], size_t nx) {
    ENTER(F_GetDerivatives);
    return (fmi2Status)rc_get_derivatives(c, F_GetDerivatives, derivatives, nx);
}

fmi2Status fmi2GetEventIndicators(fmi2Component component, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    ENTER(F_GetEventIndicators);
    if (ni != 0)
        return (fmi2Status)rc_fail(c, F_GetEventIndicators, REJECTED, "ni = %zu: this model has no event indicators",
                                   ni);
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component component, fmi2Real x[], size_t nx) {
    ENTER(F_GetContinuousStates);
    return (fmi2Status)rc_get_states(c, F_GetContinuousStates, x, nx);
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component component, fmi2Real x_nominal[], size_t nx) {
    ENTER(F_GetNominalsOfContinuousStates);
    return (fmi2Status)rc_get_nominals(c, F_GetNominalsOfContinuousStates, x_nominal, nx);
}

/* ---- Co-Simulation ---------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    ENTER(F_SetRealInputDerivatives);
    return (fmi2Status)rc_set_input_derivatives(c, F_SetRealInputDerivatives, vr, nvr, order, value);
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component component, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    ENTER(F_GetRealOutputDerivatives);
    if (nvr == 0) return fmi2OK;
    return (fmi2Status)rc_fail(c, F_GetRealOutputDerivatives, REJECTED,
                               "output derivatives are not provided (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2DoStep(fmi2Component component, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(F_DoStep);
    return (fmi2Status)rc_do_step(c, F_DoStep, currentCommunicationPoint, communicationStepSize);
}

fmi2Status fmi2CancelStep(fmi2Component component) {
    ENTER(F_CancelStep);
    return (fmi2Status)rc_fail(c, F_CancelStep, REJECTED, "fmi2DoStep never runs asynchronously here; nothing to cancel");
}

static fmi2Status no_status(fmi2Component component, Function f) {
    Instance *c = enter(component, f);
    if (!c) return fmi2Error;
    return (fmi2Status)rc_fail(c, f, REJECTED, "fmi2DoStep never returns fmi2Pending; no status to query");
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
