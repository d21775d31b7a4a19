/* rover-cosim FMU runtime: the FMI 3.0 API (Model Exchange and Co-Simulation) over the core
 * (core.h), the same core as the FMI 2.0 layer (fmi2_api.c): one model code, two standards.
 *
 * Shape as in fmi2_api.c: FUNCTIONS gives, per FMI function, its name and the instance states it
 * may be called in, checked on entry (ENTER); rc_fail() is the one error path. The model's
 * variables are Float64 (value references as in FMI 2.0), plus the independent variable time
 * (value reference TIME_VR, after the runtime's statistics). Not provided, each refused with a
 * message: Scheduled Execution, clocks, configuration mode, adjoint derivatives, output
 * derivatives, per-element dependencies (the model has no arrays), early return and event mode in
 * Co-Simulation. Nothing aborts, nothing is read or written out of bounds whatever the caller
 * passes. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "core.h"

/* ---- the FMI functions and the states they may be called in ---------------------------- */
#define S(m) (1u << (m))
#define ANY_MODE (S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | S(MODE_EVENT) | S(MODE_CONTINUOUS) | \
                  S(MODE_STEP) | S(MODE_TERMINATED) | S(MODE_ERROR))
#define RUNNING (S(MODE_EVENT) | S(MODE_CONTINUOUS) | S(MODE_STEP))
#define NOT_ERROR (ANY_MODE & ~S(MODE_ERROR))
#define ME_MODES (S(MODE_EVENT) | S(MODE_CONTINUOUS))
#define SETTABLE (S(MODE_INSTANTIATED) | S(MODE_INITIALIZATION) | RUNNING)

typedef enum {
    F_SetDebugLogging, F_EnterInitializationMode, F_ExitInitializationMode, F_EnterEventMode, F_Terminate,
    F_Reset, F_GetFloat64, F_SetFloat64, F_GetOther, F_SetOther, F_GetBinary, F_SetBinary, F_GetClock, F_SetClock,
    F_GetNumberOfVariableDependencies, F_GetVariableDependencies, F_GetFMUState, F_SetFMUState, F_FreeFMUState,
    F_SerializedFMUStateSize, F_SerializeFMUState, F_DeserializeFMUState, F_GetDirectionalDerivative,
    F_GetAdjointDerivative, F_EnterConfigurationMode, F_ExitConfigurationMode, F_Interval, F_EvaluateDiscreteStates,
    F_UpdateDiscreteStates, F_EnterContinuousTimeMode, F_CompletedIntegratorStep, F_SetTime,
    F_SetContinuousStates, F_GetContinuousStateDerivatives, F_GetEventIndicators, F_GetContinuousStates,
    F_GetNominalsOfContinuousStates, F_GetNumberOfEventIndicators, F_GetNumberOfContinuousStates, F_EnterStepMode,
    F_GetOutputDerivatives, F_DoStep, F_ActivateModelPartition, F_COUNT
} Function;

static const struct {
    const char *name;
    unsigned allowed; /* bit set of Mode */
} FUNCTIONS[F_COUNT] = {
    [F_SetDebugLogging] = {"fmi3SetDebugLogging", ANY_MODE},
    [F_EnterInitializationMode] = {"fmi3EnterInitializationMode", S(MODE_INSTANTIATED)},
    [F_ExitInitializationMode] = {"fmi3ExitInitializationMode", S(MODE_INITIALIZATION)},
    [F_EnterEventMode] = {"fmi3EnterEventMode", ME_MODES},
    [F_Terminate] = {"fmi3Terminate", RUNNING | S(MODE_TERMINATED) | S(MODE_ERROR)},
    [F_Reset] = {"fmi3Reset", ANY_MODE},
    [F_GetFloat64] = {"fmi3GetFloat64", ANY_MODE},
    [F_SetFloat64] = {"fmi3SetFloat64", SETTABLE},
    [F_GetOther] = {"fmi3Get (a type other than Float64)", ANY_MODE},
    [F_SetOther] = {"fmi3Set (a type other than Float64)", SETTABLE},
    [F_GetBinary] = {"fmi3GetBinary", ANY_MODE},
    [F_SetBinary] = {"fmi3SetBinary", SETTABLE},
    [F_GetClock] = {"fmi3GetClock", ANY_MODE},
    [F_SetClock] = {"fmi3SetClock", ANY_MODE},
    [F_GetNumberOfVariableDependencies] = {"fmi3GetNumberOfVariableDependencies", ANY_MODE},
    [F_GetVariableDependencies] = {"fmi3GetVariableDependencies", ANY_MODE},
    [F_GetFMUState] = {"fmi3GetFMUState", NOT_ERROR},
    [F_SetFMUState] = {"fmi3SetFMUState", ANY_MODE},
    [F_FreeFMUState] = {"fmi3FreeFMUState", ANY_MODE},
    [F_SerializedFMUStateSize] = {"fmi3SerializedFMUStateSize", ANY_MODE},
    [F_SerializeFMUState] = {"fmi3SerializeFMUState", ANY_MODE},
    [F_DeserializeFMUState] = {"fmi3DeserializeFMUState", ANY_MODE},
    [F_GetDirectionalDerivative] = {"fmi3GetDirectionalDerivative", S(MODE_INITIALIZATION) | RUNNING},
    [F_GetAdjointDerivative] = {"fmi3GetAdjointDerivative", ANY_MODE},
    [F_EnterConfigurationMode] = {"fmi3EnterConfigurationMode", ANY_MODE},
    [F_ExitConfigurationMode] = {"fmi3ExitConfigurationMode", ANY_MODE},
    [F_Interval] = {"fmi3 interval and shift functions", ANY_MODE},
    [F_EvaluateDiscreteStates] = {"fmi3EvaluateDiscreteStates", S(MODE_INITIALIZATION) | S(MODE_EVENT)},
    [F_UpdateDiscreteStates] = {"fmi3UpdateDiscreteStates", S(MODE_EVENT)},
    [F_EnterContinuousTimeMode] = {"fmi3EnterContinuousTimeMode", S(MODE_EVENT)},
    [F_CompletedIntegratorStep] = {"fmi3CompletedIntegratorStep", S(MODE_CONTINUOUS)},
    [F_SetTime] = {"fmi3SetTime", ME_MODES},
    [F_SetContinuousStates] = {"fmi3SetContinuousStates", ME_MODES},
    [F_GetContinuousStateDerivatives] = {"fmi3GetContinuousStateDerivatives",
                                         S(MODE_INITIALIZATION) | ME_MODES | S(MODE_TERMINATED)},
    [F_GetEventIndicators] = {"fmi3GetEventIndicators", NOT_ERROR},
    [F_GetContinuousStates] = {"fmi3GetContinuousStates", NOT_ERROR},
    [F_GetNominalsOfContinuousStates] = {"fmi3GetNominalsOfContinuousStates", NOT_ERROR},
    [F_GetNumberOfEventIndicators] = {"fmi3GetNumberOfEventIndicators", ANY_MODE},
    [F_GetNumberOfContinuousStates] = {"fmi3GetNumberOfContinuousStates", ANY_MODE},
    [F_EnterStepMode] = {"fmi3EnterStepMode", S(MODE_INITIALIZATION) | S(MODE_EVENT)},
    [F_GetOutputDerivatives] = {"fmi3GetOutputDerivatives", ANY_MODE},
    [F_DoStep] = {"fmi3DoStep", S(MODE_STEP)},
    [F_ActivateModelPartition] = {"fmi3ActivateModelPartition", ANY_MODE},
};

/* The independent variable: a Float64 after the runtime's statistics (fmubuild.description3). */
static unsigned int time_vr(void) { return (unsigned int)n_real(); }

static const char *function_name(int f) { return f >= 0 && f < F_COUNT ? FUNCTIONS[f].name : "fmi3?"; }

/* The host's logger and environment, kept with the instance. */
typedef struct {
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log_message;
} Host;

static void log_instance(const Instance *c, Status status, const char *category, const char *text) {
    const Host *host = c->layer_data;
    if (host && host->log_message) host->log_message(host->environment, (fmi3Status)status, category, text);
}

static const Layer FMI3 = {function_name, log_instance};

static void *allocate(size_t n, size_t size) { return calloc(n, size); }

/* The instance behind a handle, if it may call f in its state; NULL otherwise. */
static Instance *enter(fmi3Instance instance, Function f) {
    Instance *c = instance;
    if (!c) return NULL;
    if (c->mode < 0 || c->mode >= MODE_COUNT || !(FUNCTIONS[f].allowed & S(c->mode))) {
        rc_fail(c, f, REJECTED, "not allowed in the %s state", rc_mode_name(c->mode));
        return NULL;
    }
    return c;
}

#define ENTER(F)                      \
    Instance *c = enter(instance, F); \
    if (!c) return fmi3Error

/* A call for something this FMU does not provide: refused, naming what. */
#define NOT_PROVIDED(F, what) \
    ENTER(F);                 \
    return (fmi3Status)rc_fail(c, F, REJECTED, "%s", what)

/* ---- common functions ------------------------------------------------------------------- */
const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    ENTER(F_SetDebugLogging);
    return (fmi3Status)rc_set_debug_logging(c, F_SetDebugLogging, loggingOn, nCategories, categories);
}

static fmi3Instance instantiate(const char *function, Kind kind, fmi3String instanceName, fmi3String token,
                                fmi3Boolean loggingOn, fmi3InstanceEnvironment environment,
                                fmi3LogMessageCallback logMessage) {
    char text[512];
    if (!instanceName || !instanceName[0]) {
        if (logMessage) {
            snprintf(text, sizeof text, "%s: the instance name is empty", function);
            logMessage(environment, fmi3Error, "logStatusError", text);
        }
        return NULL;
    }
    if (!token || strcmp(token, model_info.guid) != 0) {
        if (logMessage) {
            snprintf(text, sizeof text, "%s: instantiation token %.200s does not match this binary of %s (%s)",
                     function, token ? token : "(null)", model_info.identifier, model_info.guid);
            logMessage(environment, fmi3Error, "logStatusError", text);
        }
        return NULL;
    }
    Host *host = calloc(1, sizeof *host);
    if (!host) return NULL;
    host->environment = environment;
    host->log_message = logMessage;
    Instance *c = rc_new(instanceName, kind, loggingOn, &FMI3, host, allocate, free);
    if (!c) {
        if (logMessage) {
            snprintf(text, sizeof text, "%s: out of memory", function);
            logMessage(environment, fmi3Error, "logStatusError", text);
        }
        free(host);
        return NULL;
    }
    return c;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
    (void)resourcePath; (void)visible;
    return instantiate("fmi3InstantiateModelExchange", KIND_MODEL_EXCHANGE, instanceName, instantiationToken,
                       loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath; (void)visible; (void)earlyReturnAllowed; (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    if (eventModeUsed) {
        if (logMessage)
            logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                       "fmi3InstantiateCoSimulation: eventModeUsed: this FMU has no event mode in Co-Simulation "
                       "(hasEventMode = false)");
        return NULL;
    }
    return instantiate("fmi3InstantiateCoSimulation", KIND_CO_SIMULATION, instanceName, instantiationToken,
                       loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage,
                                               fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage)
        logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                   "fmi3InstantiateScheduledExecution: this FMU provides Model Exchange and Co-Simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Instance *c = instance;
    if (!c) return;
    void *host = c->layer_data;
    rc_free(c);
    free(host);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    ENTER(F_EnterInitializationMode);
    if (rc_setup(c, F_EnterInitializationMode, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime) !=
        STATUS_OK)
        return fmi3Error;
    return (fmi3Status)rc_enter_initialization(c);
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    ENTER(F_ExitInitializationMode);
    return (fmi3Status)rc_exit_initialization(c, F_ExitInitializationMode);
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    ENTER(F_EnterEventMode);
    c->mode = MODE_EVENT;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    ENTER(F_Terminate);
    return (fmi3Status)rc_terminate(c);
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    ENTER(F_Reset);
    rc_reset(c);
    return fmi3OK;
}

/* ---- values ----------------------------------------------------------------------------- */
static fmi3Status check_counts(Instance *c, Function f, size_t nValueReferences, size_t nValues) {
    if (nValues != nValueReferences)
        return (fmi3Status)rc_fail(c, f, REJECTED, "nValues = %zu: expected %zu (one per scalar variable)", nValues,
                                   nValueReferences);
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
    ENTER(F_GetFloat64);
    if (check_counts(c, F_GetFloat64, nValueReferences, nValues) != fmi3OK) return fmi3Error;
    NOT_NULL(F_GetFloat64, valueReferences, nValueReferences);
    NOT_NULL(F_GetFloat64, values, nValues);
    for (size_t i = 0; i < nValueReferences; i++) {  /* the model's variables, each run of them at once */
        if (valueReferences[i] == time_vr()) { values[i] = c->t; continue; }
        size_t n = 1;
        while (i + n < nValueReferences && valueReferences[i + n] != time_vr()) n++;
        if (rc_get_real(c, F_GetFloat64, valueReferences + i, n, values + i) == STATUS_ERROR) return fmi3Error;
        i += n - 1;
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
    ENTER(F_SetFloat64);
    if (check_counts(c, F_SetFloat64, nValueReferences, nValues) != fmi3OK) return fmi3Error;
    NOT_NULL(F_SetFloat64, valueReferences, nValueReferences);
    NOT_NULL(F_SetFloat64, values, nValues);
    for (size_t i = 0; i < nValueReferences; i++)
        if (valueReferences[i] == time_vr())
            return (fmi3Status)rc_fail(c, F_SetFloat64, REJECTED, "time is the independent variable: it cannot be set");
    return (fmi3Status)rc_set_real(c, F_SetFloat64, valueReferences, nValueReferences, values);
}

/* The model has Float64 variables only: the other types' get/set accept empty requests. */
static fmi3Status no_variables(fmi3Instance instance, Function f, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const char *type_name) {
    ENTER(f);
    NOT_NULL(f, valueReferences, nValueReferences);
    if (nValueReferences == 0) return fmi3OK;
    return (fmi3Status)rc_fail(c, f, REJECTED, "value reference %u: this model has no %s variables",
                               valueReferences[0], type_name);
}

#define NO_VARIABLES_OF_TYPE(name, F, type_name, value_type)                                                   \
    fmi3Status name(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    value_type values[], size_t nValues) {                                                     \
        (void)values; (void)nValues;                                                                           \
        return no_variables(instance, F, valueReferences, nValueReferences, type_name);                        \
    }
NO_VARIABLES_OF_TYPE(fmi3GetFloat32, F_GetOther, "Float32", fmi3Float32)
NO_VARIABLES_OF_TYPE(fmi3GetInt8, F_GetOther, "Int8", fmi3Int8)
NO_VARIABLES_OF_TYPE(fmi3GetUInt8, F_GetOther, "UInt8", fmi3UInt8)
NO_VARIABLES_OF_TYPE(fmi3GetInt16, F_GetOther, "Int16", fmi3Int16)
NO_VARIABLES_OF_TYPE(fmi3GetUInt16, F_GetOther, "UInt16", fmi3UInt16)
NO_VARIABLES_OF_TYPE(fmi3GetInt32, F_GetOther, "Int32", fmi3Int32)
NO_VARIABLES_OF_TYPE(fmi3GetUInt32, F_GetOther, "UInt32", fmi3UInt32)
NO_VARIABLES_OF_TYPE(fmi3GetInt64, F_GetOther, "Int64", fmi3Int64)
NO_VARIABLES_OF_TYPE(fmi3GetUInt64, F_GetOther, "UInt64", fmi3UInt64)
NO_VARIABLES_OF_TYPE(fmi3GetBoolean, F_GetOther, "Boolean", fmi3Boolean)
NO_VARIABLES_OF_TYPE(fmi3GetString, F_GetOther, "String", fmi3String)
NO_VARIABLES_OF_TYPE(fmi3SetFloat32, F_SetOther, "Float32", const fmi3Float32)
NO_VARIABLES_OF_TYPE(fmi3SetInt8, F_SetOther, "Int8", const fmi3Int8)
NO_VARIABLES_OF_TYPE(fmi3SetUInt8, F_SetOther, "UInt8", const fmi3UInt8)
NO_VARIABLES_OF_TYPE(fmi3SetInt16, F_SetOther, "Int16", const fmi3Int16)
NO_VARIABLES_OF_TYPE(fmi3SetUInt16, F_SetOther, "UInt16", const fmi3UInt16)
NO_VARIABLES_OF_TYPE(fmi3SetInt32, F_SetOther, "Int32", const fmi3Int32)
NO_VARIABLES_OF_TYPE(fmi3SetUInt32, F_SetOther, "UInt32", const fmi3UInt32)
NO_VARIABLES_OF_TYPE(fmi3SetInt64, F_SetOther, "Int64", const fmi3Int64)
NO_VARIABLES_OF_TYPE(fmi3SetUInt64, F_SetOther, "UInt64", const fmi3UInt64)
NO_VARIABLES_OF_TYPE(fmi3SetBoolean, F_SetOther, "Boolean", const fmi3Boolean)
NO_VARIABLES_OF_TYPE(fmi3SetString, F_SetOther, "String", const fmi3String)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueSizes; (void)values; (void)nValues;
    return no_variables(instance, F_GetBinary, valueReferences, nValueReferences, "Binary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)valueSizes; (void)values; (void)nValues;
    return no_variables(instance, F_SetBinary, valueReferences, nValueReferences, "Binary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[]) {
    (void)values;
    return no_variables(instance, F_GetClock, valueReferences, nValueReferences, "Clock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[]) {
    (void)values;
    return no_variables(instance, F_SetClock, valueReferences, nValueReferences, "Clock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies) {
    (void)valueReference; (void)nDependencies;
    NOT_PROVIDED(F_GetNumberOfVariableDependencies,
                 "not provided (providesPerElementDependencies = false): see the model description's ModelStructure");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    NOT_PROVIDED(F_GetVariableDependencies,
                 "not provided (providesPerElementDependencies = false): see the model description's ModelStructure");
}

/* ---- FMU state -------------------------------------------------------------------------- */
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    ENTER(F_GetFMUState);
    return (fmi3Status)rc_get_state(c, F_GetFMUState, FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
    ENTER(F_SetFMUState);
    return (fmi3Status)rc_set_state(c, F_SetFMUState, FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) {
    ENTER(F_FreeFMUState);
    rc_free_state(c, FMUState);
    return fmi3OK;
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    ENTER(F_SerializedFMUStateSize);
    NOT_NULL(F_SerializedFMUStateSize, FMUState, 1);
    NOT_NULL(F_SerializedFMUStateSize, size, 1);
    *size = rc_serialized_size(FMUState);
    return fmi3OK;
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size) {
    ENTER(F_SerializeFMUState);
    return (fmi3Status)rc_serialize(c, F_SerializeFMUState, FMUState, serializedState, size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState) {
    ENTER(F_DeserializeFMUState);
    return (fmi3Status)rc_deserialize(c, F_DeserializeFMUState, serializedState, size, FMUState);
}

/* ---- derivatives ------------------------------------------------------------------------ */
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    ENTER(F_GetDirectionalDerivative);
    if (nSeed != nKnowns || nSensitivity != nUnknowns)
        return (fmi3Status)rc_fail(c, F_GetDirectionalDerivative, REJECTED,
                                   "nSeed = %zu, nSensitivity = %zu: expected nKnowns = %zu and nUnknowns = %zu "
                                   "(scalar variables)", nSeed, nSensitivity, nKnowns, nUnknowns);
    return (fmi3Status)rc_directional(c, F_GetDirectionalDerivative, unknowns, nUnknowns, knowns, nKnowns, seed,
                                      sensitivity);
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    NOT_PROVIDED(F_GetAdjointDerivative,
                 "not provided (providesAdjointDerivatives = false): use fmi3GetDirectionalDerivative");
}

/* ---- configuration, clocks -------------------------------------------------------------- */
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    NOT_PROVIDED(F_EnterConfigurationMode, "this model has no structural parameters");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    NOT_PROVIDED(F_ExitConfigurationMode, "this model has no structural parameters");
}

#define NO_CLOCKS "this model has no clocks"
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    NOT_PROVIDED(F_Interval, NO_CLOCKS);
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    NOT_PROVIDED(F_ActivateModelPartition, "this FMU provides no Scheduled Execution");
}

/* ---- events (none: the model is continuous) ------------------------------------------- */
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    ENTER(F_EvaluateDiscreteStates);
    return fmi3OK;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    ENTER(F_UpdateDiscreteStates);
    /* Each output may be NULL (FMI 3.0: the importer is not interested in it). */
    if (discreteStatesNeedUpdate) *discreteStatesNeedUpdate = fmi3False;
    if (terminateSimulation) *terminateSimulation = fmi3False;
    if (nominalsOfContinuousStatesChanged) *nominalsOfContinuousStatesChanged = fmi3False;
    if (valuesOfContinuousStatesChanged) *valuesOfContinuousStatesChanged = fmi3False;
    if (nextEventTimeDefined) *nextEventTimeDefined = fmi3False;
    if (nextEventTime) *nextEventTime = 0.0;
    return fmi3OK;
}

/* ---- Model Exchange --------------------------------------------------------------------- */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    ENTER(F_EnterContinuousTimeMode);
    c->mode = MODE_CONTINUOUS;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(F_CompletedIntegratorStep);
    NOT_NULL(F_CompletedIntegratorStep, enterEventMode, 1);
    NOT_NULL(F_CompletedIntegratorStep, terminateSimulation, 1);
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return (fmi3Status)rc_completed_integrator_step(c, F_CompletedIntegratorStep);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ENTER(F_SetTime);
    return (fmi3Status)rc_set_time(c, F_SetTime, time);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates) {
    ENTER(F_SetContinuousStates);
    return (fmi3Status)rc_set_states(c, F_SetContinuousStates, continuousStates, nContinuousStates);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates) {
    ENTER(F_GetContinuousStateDerivatives);
    return (fmi3Status)rc_get_derivatives(c, F_GetContinuousStateDerivatives, derivatives, nContinuousStates);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    (void)eventIndicators;
    ENTER(F_GetEventIndicators);
    if (nEventIndicators != 0)
        return (fmi3Status)rc_fail(c, F_GetEventIndicators, REJECTED,
                                   "nEventIndicators = %zu: this model has no event indicators", nEventIndicators);
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
    ENTER(F_GetContinuousStates);
    return (fmi3Status)rc_get_states(c, F_GetContinuousStates, continuousStates, nContinuousStates);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates) {
    ENTER(F_GetNominalsOfContinuousStates);
    return (fmi3Status)rc_get_nominals(c, F_GetNominalsOfContinuousStates, nominals, nContinuousStates);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    ENTER(F_GetNumberOfEventIndicators);
    NOT_NULL(F_GetNumberOfEventIndicators, nEventIndicators, 1);
    *nEventIndicators = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    ENTER(F_GetNumberOfContinuousStates);
    NOT_NULL(F_GetNumberOfContinuousStates, nContinuousStates, 1);
    *nContinuousStates = (size_t)model_info.nx;
    return fmi3OK;
}

/* ---- Co-Simulation ---------------------------------------------------------------------- */
fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    ENTER(F_EnterStepMode);
    if (c->kind != KIND_CO_SIMULATION)
        return (fmi3Status)rc_fail(c, F_EnterStepMode, REJECTED, "a Model Exchange instance has no step mode");
    c->mode = MODE_STEP;
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)valueReferences; (void)orders; (void)values; (void)nValues;
    ENTER(F_GetOutputDerivatives);
    if (nValueReferences == 0) return fmi3OK;
    return (fmi3Status)rc_fail(c, F_GetOutputDerivatives, REJECTED,
                               "output derivatives are not provided (maxOutputDerivativeOrder = 0)");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(F_DoStep);
    NOT_NULL(F_DoStep, eventHandlingNeeded, 1);
    NOT_NULL(F_DoStep, terminateSimulation, 1);
    NOT_NULL(F_DoStep, earlyReturn, 1);
    NOT_NULL(F_DoStep, lastSuccessfulTime, 1);
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    fmi3Status status = (fmi3Status)rc_do_step(c, F_DoStep, currentCommunicationPoint, communicationStepSize);
    *lastSuccessfulTime = c->t;
    return status;
}
