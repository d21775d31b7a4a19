/* The inner loop of the Jacobi and Gauss-Seidel masters in C (rover_cosim.orchestrator.native).
 *
 * The Python master spends ~35 us per FMU and communication step around the FMU's own work
 * (argument conversion, status checks, slicing the value vector). Here, for the FMU
 * participants only, one call does what the Python master does for them: gather each unit's
 * inputs from the value vector, fmi2SetReal, fmi2DoStep, fmi2GetReal, scatter the outputs into
 * the value vector, check that they are finite. Units of one group step at the same time on the
 * stepper's threads (the six wheels after the body); the calls each FMU sees, and so the results,
 * are those of the Python master, in the same order per FMU.
 *
 * Ramps (the interpolated Gauss-Seidel master): a unit may take some of its inputs as the line
 * from their value at the step's start to the value they hold when it steps (another participant
 * before it moved them to t + h): it is set the start values, and fmi2SetRealInputDerivatives the
 * line's slopes (0 for its other inputs), as the Python master does (stepper_ramp).
 *
 * Errors: a call that returns more than fmi2Warning stops the stepping; the unit, the call and
 * the status are left for the caller (which reports it with the FMU's logged message). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef void *Component;
typedef unsigned int ValueReference;
typedef int (*SetRealFunction)(Component, const ValueReference *, size_t, const double *);
typedef int (*GetRealFunction)(Component, const ValueReference *, size_t, double *);
typedef int (*DoStepFunction)(Component, double, double, int);
typedef int (*SetDerivativesFunction)(Component, const ValueReference *, size_t, const int *, const double *);

/* Hand-offs between the threads spin this long before sleeping on a condition variable: waking
 * a sleeping thread costs tens of microseconds on a virtual machine, a step of six wheels on two
 * threads is ~150 us. */
#define SPIN_SECONDS 2e-4

static void relax(void) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#elif defined(__aarch64__)
    __asm__ __volatile__("yield");
#endif
}

enum { CALL_SET_REAL = 1, CALL_DO_STEP = 2, CALL_GET_REAL = 3, CALL_NOT_FINITE = 4, CALL_SET_DERIVATIVES = 5 };
#define WARNING 1

typedef struct {
    Component component;
    SetRealFunction set_real;
    GetRealFunction get_real;
    DoStepFunction do_step;
    int n_in, n_out;
    const ValueReference *in_vr, *out_vr;
    const long long *in_slot, *out_slot;
    double *in, *out;   /* gathered inputs, outputs read */
    /* ramps (stepper_ramp): which inputs ramp (NULL: none), their values at the step's start, the
     * slopes of all inputs [1/s] and their orders (1) for fmi2SetRealInputDerivatives */
    SetDerivativesFunction set_derivatives;
    int *ramped, *orders;
    double *start, *slope;
    double seconds;     /* time inside this unit's FMI calls */
    double last;        /* ... in its last step, to order the next one */
    int failed_call, status;
} Unit;

typedef struct Stepper Stepper;

typedef struct {
    Stepper *stepper;
    int index;
    pthread_t thread;
} Helper;

struct Stepper {
    int n_units, n_groups, jacobi, threads;
    Unit *units;
    const int *group_start; /* [n_groups + 1]: units group_start[g] .. group_start[g + 1] - 1 */
    Helper *helpers;        /* threads - 1 */
    pthread_mutex_t lock;
    pthread_cond_t wake, done;
    long long generation;   /* bumped for each piece of work handed out (atomic) */
    int pending, stop;      /* helpers still working on it (atomic); shutting down */
    int work_begin, work_end; /* the units of the piece of work */
    int next;                 /* the next unit of it to take (atomic) */
    int *order;               /* the units of the piece of work, the costliest of the last step first */
    double t, h;
};

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The inputs now; a ramped input its value at the step's start, its slope to the value now over h. */
static void gather(Unit *u, const double *values, double h) {
    if (!u->ramped) {
        for (int i = 0; i < u->n_in; i++) u->in[i] = values[u->in_slot[i]];
        return;
    }
    for (int i = 0; i < u->n_in; i++) {
        double value = values[u->in_slot[i]];
        u->in[i] = u->ramped[i] ? u->start[i] : value;
        u->slope[i] = u->ramped[i] ? (value - u->start[i]) / h : 0.0;
    }
}

/* The ramped inputs' values at the step's start (before any unit steps). */
static void mark_start(Stepper *s, const double *values) {
    for (int k = 0; k < s->n_units; k++) {
        Unit *u = &s->units[k];
        if (!u->ramped) continue;
        for (int i = 0; i < u->n_in; i++)
            if (u->ramped[i]) u->start[i] = values[u->in_slot[i]];
    }
}

static void scatter(const Unit *u, double *values) {
    for (int i = 0; i < u->n_out; i++) values[u->out_slot[i]] = u->out[i];
}

/* fmi2SetReal, fmi2DoStep, fmi2GetReal of one unit (inputs already gathered). */
static void advance(Unit *u, double t, double h) {
    double begin = now();
    int status = 0;
    u->failed_call = 0;
    if (u->n_in && (status = u->set_real(u->component, u->in_vr, (size_t)u->n_in, u->in)) > WARNING)
        u->failed_call = CALL_SET_REAL;
    else if (u->ramped &&
             (status = u->set_derivatives(u->component, u->in_vr, (size_t)u->n_in, u->orders, u->slope)) > WARNING)
        u->failed_call = CALL_SET_DERIVATIVES;
    else if ((status = u->do_step(u->component, t, h, 1)) > WARNING)
        u->failed_call = CALL_DO_STEP;
    else if (u->n_out && (status = u->get_real(u->component, u->out_vr, (size_t)u->n_out, u->out)) > WARNING)
        u->failed_call = CALL_GET_REAL;
    else
        for (int i = 0; i < u->n_out; i++)
            if (!isfinite(u->out[i])) { u->failed_call = CALL_NOT_FINITE; break; }
    u->status = status;
    u->last = now() - begin;
    u->seconds += u->last;
}

/* The threads take the units of the piece of work one at a time, the next free one each (their
 * costs differ from step to step: rejected integrator steps, Jacobians), the costliest of the
 * last step first, so that the cheap ones fill the gaps at the end (longest processing time
 * first). Which thread steps a unit does not change its results. */
static void advance_share(Stepper *s) {
    for (;;) {
        int k = __atomic_fetch_add(&s->next, 1, __ATOMIC_ACQ_REL);
        if (k >= s->work_end) return;
        advance(&s->units[s->order[k]], s->t, s->h);
    }
}

/* order[begin..end-1]: units begin..end-1 by decreasing cost in their last step. */
static void order_by_cost(Stepper *s, int begin, int end) {
    for (int k = begin; k < end; k++) {
        int unit = k, j = k;
        for (; j > begin && s->units[s->order[j - 1]].last < s->units[unit].last; j--) s->order[j] = s->order[j - 1];
        s->order[j] = unit;
    }
}

/* Spin until ``*flag`` differs from ``value`` (1) or SPIN_SECONDS passed (0). */
static int spin_while_equal(const long long *flag, long long value) {
    double until = now() + SPIN_SECONDS;
    for (int k = 1;; k++) {
        if (__atomic_load_n(flag, __ATOMIC_ACQUIRE) != value) return 1;
        relax();
        if ((k & 63) == 0 && now() > until) return 0;
    }
}

static void *serve(void *argument) {
    Helper *helper = argument;
    Stepper *s = helper->stepper;
    long long seen = 0;
    for (;;) {
        if (!spin_while_equal(&s->generation, seen)) {
            pthread_mutex_lock(&s->lock);
            while (!s->stop && __atomic_load_n(&s->generation, __ATOMIC_ACQUIRE) == seen)
                pthread_cond_wait(&s->wake, &s->lock);
            pthread_mutex_unlock(&s->lock);
        }
        if (__atomic_load_n(&s->stop, __ATOMIC_ACQUIRE)) break;
        seen = __atomic_load_n(&s->generation, __ATOMIC_ACQUIRE);
        advance_share(s);
        if (__atomic_sub_fetch(&s->pending, 1, __ATOMIC_ACQ_REL) == 0) {
            pthread_mutex_lock(&s->lock);
            pthread_cond_signal(&s->done);
            pthread_mutex_unlock(&s->lock);
        }
    }
    return NULL;
}

static int all_done(Stepper *s) {
    double until = now() + SPIN_SECONDS;
    for (int k = 1;; k++) {
        if (__atomic_load_n(&s->pending, __ATOMIC_ACQUIRE) == 0) return 1;
        relax();
        if ((k & 63) == 0 && now() > until) return 0;
    }
}

/* Step units begin..end-1 (inputs gathered), on all threads when there are several. */
static void advance_units(Stepper *s, int begin, int end, double t, double h) {
    if (s->threads < 2 || end - begin < 2) {
        for (int i = begin; i < end; i++) advance(&s->units[i], t, h);
        return;
    }
    s->work_begin = begin; s->work_end = end; s->t = t; s->h = h;
    order_by_cost(s, begin, end);
    __atomic_store_n(&s->next, begin, __ATOMIC_RELEASE);
    __atomic_store_n(&s->pending, s->threads - 1, __ATOMIC_RELEASE);
    __atomic_add_fetch(&s->generation, 1, __ATOMIC_ACQ_REL); /* publishes the work above */
    pthread_mutex_lock(&s->lock);
    pthread_cond_broadcast(&s->wake); /* for helpers that went to sleep */
    pthread_mutex_unlock(&s->lock);
    advance_share(s);
    if (all_done(s)) return;
    pthread_mutex_lock(&s->lock);
    while (__atomic_load_n(&s->pending, __ATOMIC_ACQUIRE) > 0) pthread_cond_wait(&s->done, &s->lock);
    pthread_mutex_unlock(&s->lock);
}

/* The first failed unit of begin..end-1, or -1. Non-finite outputs are scattered all the same,
 * for the caller to name. */
static int first_failure(const Stepper *s, double *values, int begin, int end) {
    for (int i = begin; i < end; i++) {
        if (!s->units[i].failed_call) continue;
        if (s->units[i].failed_call == CALL_NOT_FINITE) scatter(&s->units[i], values);
        return i;
    }
    return -1;
}

/* Group g: gather, step (in parallel), scatter. Returns -1, or the unit that failed. (Ramps: the
 * step's start values marked first, by stepper_mark.) */
int stepper_group(Stepper *s, double *values, int g, double t, double h) {
    int begin = s->group_start[g], end = s->group_start[g + 1];
    for (int i = begin; i < end; i++) gather(&s->units[i], values, h);
    advance_units(s, begin, end, t, h);
    int failed = first_failure(s, values, begin, end);
    if (failed >= 0) return failed;
    for (int i = begin; i < end; i++) scatter(&s->units[i], values);
    return -1;
}

/* One communication step of all units, as JacobiMaster/GaussSeidelMaster do for FMUs: Jacobi
 * gathers every input from the values at t first; Gauss-Seidel group after group, each seeing
 * the outputs of the groups before it. Returns -1, or the index of the unit that failed. */
int stepper_step(Stepper *s, double *values, double t, double h) {
    if (s->jacobi) {
        for (int i = 0; i < s->n_units; i++) gather(&s->units[i], values, h);
        advance_units(s, 0, s->n_units, t, h);
        int failed = first_failure(s, values, 0, s->n_units);
        if (failed >= 0) return failed;
        for (int i = 0; i < s->n_units; i++) scatter(&s->units[i], values);
        return -1;
    }
    mark_start(s, values);
    for (int g = 0; g < s->n_groups; g++) {
        int failed = stepper_group(s, values, g, t, h);
        if (failed >= 0) return failed;
    }
    return -1;
}

/* Steps k = first .. last - 1 from times[k] to times[k + 1] (``h`` > 0: steps of h from times[k],
 * as a caller stepping by a fixed size does), recording the slots ``record`` of the value vector
 * after step k into row k + 1 of ``rows``. Returns -1, or the failed unit; the step reached is in
 * *reached (the number of steps completed). */
int stepper_run(Stepper *s, double *values, const double *times, int first, int last, double h,
                const long long *record, int n_record, double *rows, int *reached) {
    for (int k = first; k < last; k++) {
        int failed = stepper_step(s, values, times[k], h > 0.0 ? h : times[k + 1] - times[k]);
        *reached = k;
        if (failed >= 0) return failed;
        double *row = rows + (size_t)(k + 1) * (size_t)n_record;
        for (int j = 0; j < n_record; j++) row[j] = values[record[j]];
    }
    *reached = last;
    return -1;
}

/* The values at the step's start of the ramped inputs, for a step made group by group (stepper_group). */
void stepper_mark(Stepper *s, const double *values) { mark_start(s, values); }

/* Unit ``unit`` ramps the inputs flagged in ``ramped`` (one per input, copied) with
 * ``set_derivatives`` (fmi2SetRealInputDerivatives). 0 on success, -1 when out of memory. */
int stepper_ramp(Stepper *s, int unit, void *set_derivatives, const int *ramped) {
    Unit *u = &s->units[unit];
    size_t n = (size_t)(u->n_in ? u->n_in : 1);
    u->ramped = calloc(n, sizeof *u->ramped);
    u->orders = calloc(n, sizeof *u->orders);
    u->start = calloc(n, sizeof *u->start);
    u->slope = calloc(n, sizeof *u->slope);
    if (!u->ramped || !u->orders || !u->start || !u->slope) {
        free(u->ramped); free(u->orders); free(u->start); free(u->slope);
        u->ramped = u->orders = NULL; u->start = u->slope = NULL;
        return -1;
    }
    for (int i = 0; i < u->n_in; i++) { u->ramped[i] = ramped[i] != 0; u->orders[i] = 1; }
    u->set_derivatives = (SetDerivativesFunction)set_derivatives;
    return 0;
}

int stepper_failed_call(const Stepper *s, int unit) { return s->units[unit].failed_call; }
int stepper_status(const Stepper *s, int unit) { return s->units[unit].status; }
double stepper_seconds(const Stepper *s, int unit) { return s->units[unit].seconds; }

void stepper_free(Stepper *s);

/* A stepper over ``n_units`` FMU instances. Per unit: component, the three FMI functions, and
 * its inputs and outputs as value references with their slots in the value vector (flattened,
 * n_in[i] and n_out[i] each). Units are listed group after group (group_start, n_groups + 1
 * entries). The arrays must outlive the stepper; NULL when out of memory or a thread failed. */
Stepper *stepper_new(int n_units, Component *components, void **set_real, void **get_real, void **do_step,
                     const int *n_in, const ValueReference *in_vr, const long long *in_slot, const int *n_out,
                     const ValueReference *out_vr, const long long *out_slot, int n_groups, const int *group_start,
                     int jacobi, int threads) {
    Stepper *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->n_units = n_units; s->n_groups = n_groups; s->group_start = group_start;
    s->jacobi = jacobi; s->threads = threads < 1 ? 1 : threads;
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->wake, NULL);
    pthread_cond_init(&s->done, NULL);
    s->units = calloc((size_t)(n_units ? n_units : 1), sizeof *s->units);
    s->order = calloc((size_t)(n_units ? n_units : 1), sizeof *s->order);
    if (!s->units || !s->order) { s->threads = 1; s->n_units = s->units ? n_units : 0; stepper_free(s); return NULL; }
    size_t offset_in = 0, offset_out = 0;
    for (int i = 0; i < n_units; i++) {
        Unit *u = &s->units[i];
        u->component = components[i];
        u->set_real = (SetRealFunction)set_real[i];
        u->get_real = (GetRealFunction)get_real[i];
        u->do_step = (DoStepFunction)do_step[i];
        u->n_in = n_in[i]; u->n_out = n_out[i];
        u->in_vr = in_vr + offset_in; u->in_slot = in_slot + offset_in;
        u->out_vr = out_vr + offset_out; u->out_slot = out_slot + offset_out;
        offset_in += (size_t)n_in[i]; offset_out += (size_t)n_out[i];
        u->in = calloc((size_t)(u->n_in ? u->n_in : 1), sizeof(double));
        u->out = calloc((size_t)(u->n_out ? u->n_out : 1), sizeof(double));
        if (!u->in || !u->out) { s->threads = 1; stepper_free(s); return NULL; }
    }
    if (s->threads > 1) {
        s->helpers = calloc((size_t)(s->threads - 1), sizeof *s->helpers);
        int started = 0;
        for (; s->helpers && started < s->threads - 1; started++) {
            s->helpers[started].stepper = s;
            s->helpers[started].index = started;
            if (pthread_create(&s->helpers[started].thread, NULL, serve, &s->helpers[started])) break;
        }
        if (!s->helpers || started < s->threads - 1) { s->threads = started + 1; stepper_free(s); return NULL; }
    }
    return s;
}

void stepper_free(Stepper *s) {
    if (!s) return;
    if (s->helpers) {
        pthread_mutex_lock(&s->lock);
        __atomic_store_n(&s->stop, 1, __ATOMIC_RELEASE);
        __atomic_add_fetch(&s->generation, 1, __ATOMIC_ACQ_REL);
        pthread_cond_broadcast(&s->wake);
        pthread_mutex_unlock(&s->lock);
        for (int k = 0; k < s->threads - 1; k++) pthread_join(s->helpers[k].thread, NULL);
        free(s->helpers);
    }
    for (int i = 0; i < s->n_units; i++) {
        Unit *u = &s->units[i];
        free(u->in); free(u->out); free(u->ramped); free(u->orders); free(u->start); free(u->slope);
    }
    free(s->units);
    free(s->order);
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->wake);
    pthread_cond_destroy(&s->done);
    free(s);
}
