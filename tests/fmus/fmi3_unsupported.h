/* The FMI 3.0 functions the test FMUs do not offer (serialised states, derivatives, clocks,
 * intervals, configuration mode), each refusing with its name: included by ball3.c and arrays3.c
 * after they define refuse() and REFUSED(). */
#ifndef FMI3_UNSUPPORTED_H
#define FMI3_UNSUPPORTED_H

REFUSED(fmi3SerializedFMUStateSize, fmi3FMUState state, size_t *size)
REFUSED(fmi3SerializeFMUState, fmi3FMUState state, fmi3Byte bytes[], size_t size)
REFUSED(fmi3DeserializeFMUState, const fmi3Byte bytes[], size_t size, fmi3FMUState *state)
REFUSED(fmi3GetDirectionalDerivative, const fmi3ValueReference unknowns[], size_t n_unknowns,
        const fmi3ValueReference knowns[], size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
        fmi3Float64 sensitivity[], size_t n_sensitivity)
REFUSED(fmi3GetAdjointDerivative, const fmi3ValueReference unknowns[], size_t n_unknowns,
        const fmi3ValueReference knowns[], size_t n_knowns, const fmi3Float64 seed[], size_t n_seed,
        fmi3Float64 sensitivity[], size_t n_sensitivity)
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) { return refuse(instance, "no structural parameters"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) { return refuse(instance, "no structural parameters"); }
REFUSED(fmi3GetIntervalDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 intervals[],
        fmi3IntervalQualifier qualifiers[])
REFUSED(fmi3GetIntervalFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
        fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[])
REFUSED(fmi3GetShiftDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 shifts[])
REFUSED(fmi3GetShiftFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
REFUSED(fmi3SetIntervalDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 intervals[])
REFUSED(fmi3SetIntervalFraction, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 counters[],
        const fmi3UInt64 resolutions[])
REFUSED(fmi3SetShiftDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 shifts[])
REFUSED(fmi3SetShiftFraction, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 counters[],
        const fmi3UInt64 resolutions[])
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) { return refuse(instance, "no clocks"); }
REFUSED(fmi3ActivateModelPartition, fmi3ValueReference clock, fmi3Float64 time)
REFUSED(fmi3GetOutputDerivatives, const fmi3ValueReference vr[], size_t n, const fmi3Int32 orders[],
        fmi3Float64 values[], size_t n_values)

#endif
