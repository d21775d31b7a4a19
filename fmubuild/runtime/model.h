/* The contract between a generated model and the rover-cosim FMI runtime (one core under the FMI
 * 2.0 and FMI 3.0 API layers).
 *
 * fmubuild generates, per model, model_casadi.c (CasADi's C code of the functions below) and
 * model_data.c (sizes, value-reference layout, defaults: the ModelInfo below). The runtime
 * (core.h: instance.c, state.c, cosim.c, ode23s.c, and the API layers fmi2_api.c, fmi3_api.c) is the same for every model.
 *
 * Real value references are indices into one array laid out as
 *   [parameters | states | derivatives | inputs | observed | memories | tolerance, maxStep | statistics]
 * with the offsets given in ModelInfo.
 */
#ifndef ROVER_COSIM_MODEL_H
#define ROVER_COSIM_MODEL_H

/* FMI2_FUNCTION_PREFIX (several source FMUs in one program): the FMU's other external names get
 * the same prefix (fmu_prefix.h, written with the sources by fmubuild). */
#ifdef FMI2_FUNCTION_PREFIX
#include "fmu_prefix.h"
#endif

typedef long long int casadi_int;

typedef struct {
    const char *identifier;           /* modelIdentifier */
    const char *guid;
    int nx, nu, np, ny;               /* states, inputs, tunable parameters, observed variables */
    const double *p_default;          /* [np] parameter start values */
    const double *u_default;          /* [nu] input start values */
    const double *x_start;            /* [nx] constant state start values */
    const int *x_start_calculated;    /* [nx] 1: start computed from the parameters (model_initial) */
    const char *const *real_names;    /* [n_real] variable names, for messages */
    int n_asserts;                    /* Modelica asserts, checked by the runtime */
    const char *const *assert_messages;    /* [n_asserts] */
    const int *assert_is_error;            /* [n_asserts] 1: error, 0: warning */
    const int *assert_value_start;         /* [n_asserts + 1] offsets into the values of model_evaluate */
    const char *const *assert_value_names; /* names of those values, for the message */
    int nm;                           /* memories: values the runtime keeps from the previous step */
    const double *m_default;          /* [nm] their value before the first step */
    const int *m_source;              /* [nm] index into y of the variable each one remembers */
    const int *y_is_output;           /* [ny] 1: an output (causality output), 0: a local variable */
    const int *u_affine;              /* [nu] 1: the derivatives are affine in this input (d xdot/du a
                                       * function of the parameters and the other inputs only: the
                                       * runtime updates them for its change instead of evaluating
                                       * again, with model_input_gain) */
} ModelInfo;

extern const ModelInfo model_info;

/* Signature of CasADi's generated functions. */
typedef int (*casadi_eval)(const double **arg, double **res, casadi_int *iw, double *w, int mem);
typedef int (*casadi_work)(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);

/* Memories m (fmubuild/memory.py) are an extra argument of the functions below: the start of an
 * iterative solve, which the results do not depend on beyond the solve's tolerance. */
/* model_evaluate(t, x, u, p, m) -> (xdot, y: observed variables, holds [n_asserts]: nonzero where an
 * assert's condition holds, values: the variables each condition reads, for the message) */
int model_evaluate(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int model_evaluate_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
/* model_initial(p) -> x0 */
int model_initial(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int model_initial_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
/* model_ode_jacobian(t, x, u, p, m) -> (dxdot/dx [nx*nx, column-major, dense], dxdot/dt [nx]) */
int model_ode_jacobian(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int model_ode_jacobian_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
/* model_directional(t, x, u, p, m, dx, du) -> (dxdot, dy): forward directional derivatives */
int model_directional(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int model_directional_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);
/* model_input_gain(t, x, u, p, m) -> (gain [nx*nu, column-major, dense]): d xdot / d u in the
 * columns of the inputs marked u_affine, 0 in the others (those columns read neither t, x nor m) */
int model_input_gain(const double **arg, double **res, casadi_int *iw, double *w, int mem);
int model_input_gain_work(casadi_int *sz_arg, casadi_int *sz_res, casadi_int *sz_iw, casadi_int *sz_w);

#endif
