/* rover-cosim FMU runtime: the core shared by the FMI 2.0 and FMI 3.0 API layers.
 *
 * The runtime is split by job, after the Modelica Association's Reference-FMUs:
 *   fmi2_api.c  (fmi3_api.c)  the API: its functions, the table of the states each may be called
 *                             in, its types, its logger and its memory functions;
 *   instance.c                an instance: allocation, evaluation of the model (model.h), values,
 *                             asserts, directional derivatives, Model Exchange;
 *   state.c                   FMU states: saving, restoring, serializing, checking;
 *   cosim.c                   the Co-Simulation step (ode23s.c integrates it).
 * The core knows no FMI type: statuses have the values fmi2Status and fmi3Status share, and every
 * message names the API function it comes from through the layer (Layer). */
#ifndef ROVER_COSIM_CORE_H
#define ROVER_COSIM_CORE_H

#include <stddef.h>

#include "model.h"
#include "ode23s.h"

/* The values of fmi2OK/fmi3OK, fmi2Warning/fmi3Warning and fmi2Error/fmi3Error. */
typedef enum { STATUS_OK = 0, STATUS_WARNING = 1, STATUS_ERROR = 3 } Status;

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_EVENT, MODE_CONTINUOUS, MODE_STEP,
               MODE_TERMINATED, MODE_ERROR, MODE_COUNT } Mode;

/* The interface an instance was made for (the values of fmi2ModelExchange and fmi2CoSimulation). */
typedef enum { KIND_MODEL_EXCHANGE = 0, KIND_CO_SIMULATION = 1 } Kind;

/* A refused call changes nothing; a broken instance (a failed evaluation or integration) goes to
 * the error state. */
typedef enum { REJECTED, BROKEN } Severity;

/* Log categories (the model description's LogCategories), in this order; errors always logged. */
#define N_LOG_CATEGORIES 3
#define ALL_CATEGORIES ((1u << N_LOG_CATEGORIES) - 1u)
#define DEFAULT_CATEGORIES 3u /* without debug logging: errors and warnings */

typedef struct Instance Instance;

/* What an API layer gives its instances. */
typedef struct {
    const char *(*function_name)(int f);  /* the API function of index f, for messages */
    /* A message that passed the categories; ``text`` is plain (no format). */
    void (*log)(const Instance *c, Status status, const char *category, const char *text);
} Layer;

/* The last evaluation of the model (model_evaluate) and the exact point (t, x, u) and memories m
 * it was made with: asking again with the same ones reuses it. */
typedef struct {
    int valid;
    double t;
    double *x, *u, *m, *xdot, *y, *holds, *values;
    unsigned long long evaluations, reused;
    int outputs_fresh;  /* y, holds and values are this evaluation's and not yet handed to the instance */
    unsigned long long updated;  /* steps begun from derivatives updated for affine inputs (rc_set_real) */
} Evaluation;

struct Instance {
    const Layer *layer;
    void *layer_data;                       /* the API's own (its callbacks, its environment) */
    void *(*allocate)(size_t n, size_t size);  /* zeroed memory */
    void (*release)(void *block);
    char *name;
    Kind kind;
    unsigned log_mask;  /* bit k: category k is logged (errors always are) */
    Mode mode;
    double t, t_stop;
    int has_stop;
    double *p, *x, *u, *xdot, *y, *x_set;  /* x_set[i] != 0: the start of state i was set by the user */
    double *m;  /* memories: values of the previous step (model.h), e.g. the start of a sinkage solve */
    double *holds, *assert_values;         /* the model's asserts, evaluated with the outputs */
    double rtol, max_step;
    int xdot_valid, y_valid;
    /* Input interpolation over one communication step (input derivatives, order 1):
     * u(t) = u + u_der (t - t_step) while interpolating; cleared after each step. At the end of
     * the step being taken, t_step + h_step, the time elapsed is h_step itself: the inputs end
     * the step at u + u_der h, the arithmetic of the master's u_der = (u_end - u) / h, so that
     * they are the bits it sets next (mostly: see cosim.c). h_step is 0 outside a step. */
    double *u_der, *u_step, t_step, h_step;
    int interpolating;
    /* CasADi work */
    const double **arg;
    double **res;
    casadi_int *iw;
    double *w;
    double *seed_x, *seed_u, *sens_x, *sens_y;
    /* d xdot / d u of the inputs the derivatives are affine in (model_info.u_affine), nx x nu
     * column-major (0 elsewhere), where the other inputs and the parameters are (gain_valid) */
    double *gain;
    int gain_valid;
    /* The integrator's dfdt (solver.T) for the step: the model's explicit time derivative
     * (t_explicit) plus d xdot / d u times the input derivatives while the inputs are interpolated:
     * the right-hand side then moves with time through them too (a Rosenbrock method needs it).
     * dfdu (nx x nu, column-major) holds the columns of the inputs that ramped when the Jacobian
     * was taken (by forward differences: dfdu_valid[j] != 0), an input that starts to ramp
     * later takes a new Jacobian. u_fd, fd_*: the differences' scratch. */
    double *t_explicit, *dfdu, *dfdu_valid, *u_fd, *fd_xdot, *fd_y, *fd_holds, *fd_values;
    int f0_updated;  /* the integrator's derivatives were updated for such inputs since the last step */
    Evaluation eval;
    Ode23s solver;
};

/* ---- value references: one array of Reals (model.h) ------------------------------------- */
static inline int off_x(void) { return model_info.np; }
static inline int off_dx(void) { return model_info.np + model_info.nx; }
static inline int off_u(void) { return model_info.np + 2 * model_info.nx; }
static inline int off_y(void) { return model_info.np + 2 * model_info.nx + model_info.nu; }
static inline int off_m(void) { return off_y() + model_info.ny; }
static inline int vr_rtol(void) { return off_m() + model_info.nm; }
static inline int vr_max_step(void) { return vr_rtol() + 1; }
static inline int vr_statistics(void) { return vr_max_step() + 1; }
#define N_STATISTICS 6 /* codegen.STATISTICS */
static inline int n_real(void) { return vr_statistics() + N_STATISTICS; }

/* A value reference as an index, or -1 when it is no Real variable (compared unsigned, so
 * 0xFFFFFFFF and values >= 2^31 are out of range, not negative). */
static inline int real_index(unsigned int vr) { return vr < (unsigned int)n_real() ? (int)vr : -1; }

static inline const char *real_name(unsigned int vr) {
    int r = real_index(vr);
    return r >= 0 ? model_info.real_names[r] : "?";
}

/* Arrays of n elements must not be NULL when n > 0 (in a function with ``Instance *c``). */
#define NOT_NULL(F, array, n) \
    if ((n) > 0 && !(array)) return (int)rc_fail(c, F, REJECTED, "%s is NULL (%zu elements expected)", #array, (size_t)(n))

/* ---- logging and the one error path (instance.c) ------------------------------------------ */
const char *rc_mode_name(Mode mode);
int rc_log_category(const char *name);            /* its index, or -1 */
void rc_log(Instance *c, Status status, const char *category, const char *format, ...);
Status rc_fail(Instance *c, int f, Severity severity, const char *format, ...);
/* The categories of fmi2SetDebugLogging / fmi3SetDebugLogging (an unknown one is refused). */
Status rc_set_debug_logging(Instance *c, int f, int on, size_t n, const char *const categories[]);

/* ---- an instance (instance.c) ------------------------------------------------------------- */
/* A new instance, or NULL when out of memory (nothing left allocated). */
Instance *rc_new(const char *name, Kind kind, int logging, const Layer *layer, void *layer_data,
                 void *(*allocate)(size_t, size_t), void (*release)(void *));
void rc_free(Instance *c);
void rc_reset(Instance *c);
Status rc_setup(Instance *c, int f, int tolerance_defined, double tolerance, double start, int stop_defined,
                double stop);
Status rc_enter_initialization(Instance *c);
Status rc_exit_initialization(Instance *c, int f);
Status rc_terminate(Instance *c);
void rc_invalidate(Instance *c);        /* outputs and derivatives to be evaluated again */
/* The inputs at t: the held values, or their linear interpolation within the step (u_step). */
const double *rc_inputs_at(Instance *c, double t);
void rc_input_rates(Instance *c);       /* solver.T for the input derivatives of the next step */
void rc_forget_evaluation(Instance *c); /* the last evaluation is no longer reused (parameters changed) */
void rc_remember(Instance *c);          /* after a completed step: the memories take their values */
/* Outputs (need_y) and derivatives (need_xdot) at the current point, with the asserts. */
Status rc_update(Instance *c, int f, int need_xdot, int need_y);
Status rc_get_real(Instance *c, int f, const unsigned int vr[], size_t n, double value[]);
Status rc_set_real(Instance *c, int f, const unsigned int vr[], size_t n, const double value[]);
Status rc_directional(Instance *c, int f, const unsigned int unknown[], size_t n_unknown, const unsigned int known[],
                      size_t n_known, const double dv_known[], double dv_unknown[]);

/* Model Exchange */
Status rc_set_time(Instance *c, int f, double time);
Status rc_set_states(Instance *c, int f, const double x[], size_t nx);
Status rc_get_states(Instance *c, int f, double x[], size_t nx);
Status rc_get_nominals(Instance *c, int f, double nominals[], size_t nx);
Status rc_get_derivatives(Instance *c, int f, double xdot[], size_t nx);
Status rc_completed_integrator_step(Instance *c, int f);

/* ---- Co-Simulation (cosim.c) --------------------------------------------------------------- */
Status rc_set_input_derivatives(Instance *c, int f, const unsigned int vr[], size_t n, const int order[],
                                const double value[]);
Status rc_do_step(Instance *c, int f, double current, double step);

/* ---- FMU states (state.c): a block of rc_state_size() bytes after its size_t length ------------ */
Status rc_get_state(Instance *c, int f, void **state);
Status rc_set_state(Instance *c, int f, const void *state);
void rc_free_state(Instance *c, void **state);
size_t rc_serialized_size(const void *state);
Status rc_serialize(Instance *c, int f, const void *state, unsigned char serialized[], size_t size);
Status rc_deserialize(Instance *c, int f, const unsigned char serialized[], size_t size, void **state);

#endif
