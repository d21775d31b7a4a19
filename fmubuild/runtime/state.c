/* rover-cosim FMU runtime, the core (core.h): FMU states. A state is a block holding its size
 * (size_t), then a header (StateHeader, with a checksum) and the instance's doubles. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core.h"

#define FMU_STATE_MAGIC 0x524f5648u /* layout 6: kind, input derivatives, statistics, h_entry, dfdt's parts */

/* What a saved FMU state holds. */
typedef struct {
    unsigned magic, nx, nu, np, nm;
    int type;           /* Kind: Model Exchange or Co-Simulation: a state is restored into its own kind only */
    int mode;
    int f0_valid, jac_valid, jac_current, jac_age;  /* integrator memory, so a restored run repeats exactly */
    int interpolating;  /* input derivatives set for the next step (u_der follows the inputs) */
    double t, rtol, max_step, h, h_entry, t_step;
    long steps, rejected, jacobians, rhs_calls;    /* the statistics */
    unsigned long long evaluations, reused, updated;
    uint64_t checksum;  /* FNV-1a of the header (this field zero) and the doubles that follow */
    /* followed by x[nx], u[nu], u_der[nu], p[np], x_set[nx], F0[nx], J[nx*nx], t_explicit[nx], dfdu[nx*nu],
     * dfdu_valid[nu], m[nm] (doubles) */
} StateHeader;


/* In memory an FMU state is [size_t payload size | payload]; the payload is what
 * fmi2SerializeFMUstate hands out: a StateHeader and the doubles after it. */
static size_t state_size(void) {
    return sizeof(StateHeader) +
           sizeof(double) * (size_t)(4 * model_info.nx + 3 * model_info.nu + model_info.np +
                                     model_info.nx * model_info.nx + model_info.nx * model_info.nu + model_info.nm);
}

static uint64_t fnv1a(uint64_t hash, const unsigned char *bytes, size_t n) {
    for (size_t i = 0; i < n; i++) hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
    return hash;
}

static uint64_t state_checksum(const unsigned char *payload, size_t size) {
    StateHeader head;
    memcpy(&head, payload, sizeof head);
    head.checksum = 0;
    uint64_t hash = fnv1a(0xcbf29ce484222325ULL, (const unsigned char *)&head, sizeof head);
    return fnv1a(hash, payload + sizeof head, size - sizeof head);
}

static void state_write(const Instance *c, unsigned char *payload) {
    StateHeader head;
    memset(&head, 0, sizeof head); /* padding bytes too: the checksum covers them */
    head.magic = FMU_STATE_MAGIC;
    head.nx = (unsigned)model_info.nx; head.nu = (unsigned)model_info.nu; head.np = (unsigned)model_info.np;
    head.nm = (unsigned)model_info.nm;
    head.type = (int)c->kind;
    head.mode = (int)c->mode;
    head.interpolating = c->interpolating;
    head.t_step = c->t_step;
    head.steps = c->solver.steps; head.rejected = c->solver.rejected;
    head.jacobians = c->solver.jacobians; head.rhs_calls = c->solver.rhs_calls;
    head.evaluations = c->eval.evaluations; head.reused = c->eval.reused; head.updated = c->eval.updated;
    head.f0_valid = c->solver.f0_valid; head.jac_valid = c->solver.jac_valid;
    head.jac_current = c->solver.jac_current; head.jac_age = c->solver.jac_age;
    head.t = c->t; head.rtol = c->rtol; head.max_step = c->max_step; head.h = c->solver.h;
    head.h_entry = c->solver.h_entry;
    memcpy(payload, &head, sizeof head);
    double *v = (double *)(payload + sizeof head);
    memcpy(v, c->x, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->u, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->u_der, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->p, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(v, c->x_set, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.F0, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->solver.J, sizeof(double) * model_info.nx * model_info.nx); v += model_info.nx * model_info.nx;
    memcpy(v, c->t_explicit, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(v, c->dfdu, sizeof(double) * model_info.nx * model_info.nu); v += model_info.nx * model_info.nu;
    memcpy(v, c->dfdu_valid, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(v, c->m, sizeof(double) * model_info.nm);
    head.checksum = state_checksum(payload, state_size());
    memcpy(payload, &head, sizeof head);
}

/* Why ``payload`` of ``size`` bytes is not a state of this model (for an instance of kind
 * ``type``), or NULL if it is one. */
static const char *state_refusal(const unsigned char *payload, size_t size, Kind type) {
    StateHeader head;
    if (size != state_size()) return "its size does not match this model's FMU state";
    memcpy(&head, payload, sizeof head);
    if (head.magic != FMU_STATE_MAGIC || head.nx != (unsigned)model_info.nx || head.nu != (unsigned)model_info.nu ||
        head.np != (unsigned)model_info.np || head.nm != (unsigned)model_info.nm)
        return "it was not saved by this model";
    if (head.checksum != state_checksum(payload, size)) return "its checksum does not match (corrupted)";
    if (head.type != (int)type)
        return head.type == KIND_MODEL_EXCHANGE ? "it was saved by a Model Exchange instance, this one is Co-Simulation"
                                              : "it was saved by a Co-Simulation instance, this one is Model Exchange";
    if (head.mode < 0 || head.mode >= MODE_COUNT || head.jac_age < 0 || !isfinite(head.t) ||
        !(head.rtol > 0.0 && head.rtol < 1.0) || !(head.max_step >= 0.0) || !(head.h >= 0.0) || !isfinite(head.h) ||
        !(head.h_entry >= 0.0) || !isfinite(head.h_entry) ||
        !isfinite(head.t_step) || head.steps < 0 || head.rejected < 0 || head.jacobians < 0 || head.rhs_calls < 0)
        return "its values are out of range";
    return NULL;
}

static void state_read(Instance *c, const unsigned char *payload) {
    StateHeader head;
    memcpy(&head, payload, sizeof head);
    const double *v = (const double *)(payload + sizeof head);
    memcpy(c->x, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->u, v, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(c->u_der, v, sizeof(double) * model_info.nu); v += model_info.nu;
    c->interpolating = head.interpolating != 0;
    c->t_step = head.t_step;
    memcpy(c->p, v, sizeof(double) * model_info.np); v += model_info.np;
    memcpy(c->x_set, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.F0, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->solver.J, v, sizeof(double) * model_info.nx * model_info.nx); v += model_info.nx * model_info.nx;
    memcpy(c->t_explicit, v, sizeof(double) * model_info.nx); v += model_info.nx;
    memcpy(c->dfdu, v, sizeof(double) * model_info.nx * model_info.nu); v += model_info.nx * model_info.nu;
    memcpy(c->dfdu_valid, v, sizeof(double) * model_info.nu); v += model_info.nu;
    memcpy(c->m, v, sizeof(double) * model_info.nm);
    c->mode = (Mode)head.mode;
    c->t = head.t;
    c->rtol = head.rtol;
    c->max_step = head.max_step;
    rc_forget_evaluation(c);
    rc_invalidate(c);
    c->solver.f0_valid = head.f0_valid != 0;
    c->solver.jac_valid = head.jac_valid != 0;
    c->solver.w_valid = 0; /* W's factors are not saved: taken again from the restored J */
    c->solver.jac_current = head.jac_current != 0;
    c->solver.jac_age = head.jac_age;
    c->solver.h = head.h;
    c->solver.h_entry = head.h_entry;
    c->solver.steps = head.steps; c->solver.rejected = head.rejected;
    c->solver.jacobians = head.jacobians; c->solver.rhs_calls = head.rhs_calls;
    c->eval.evaluations = head.evaluations; c->eval.reused = head.reused; c->eval.updated = head.updated;
}

Status rc_get_state(Instance *c, int f, void **state) {
    NOT_NULL(f, state, 1);
    size_t size = state_size();
    unsigned char *buffer = *state;
    if (!buffer) {
        buffer = c->allocate(size + sizeof(size_t), 1);
        if (!buffer) return rc_fail(c, f, REJECTED, "out of memory");
        memcpy(buffer, &size, sizeof size);
    }
    state_write(c, buffer + sizeof(size_t));
    *state = buffer;
    return STATUS_OK;
}

Status rc_set_state(Instance *c, int f, const void *state) {
    NOT_NULL(f, state, 1);
    size_t size;
    memcpy(&size, state, sizeof size);
    const unsigned char *payload = (const unsigned char *)state + sizeof(size_t);
    const char *refusal = state_refusal(payload, size, c->kind);
    if (refusal) return rc_fail(c, f, REJECTED, "not an FMU state of %s: %s", model_info.identifier, refusal);
    state_read(c, payload);
    return STATUS_OK;
}

void rc_free_state(Instance *c, void **state) {
    if (state && *state) { c->release(*state); *state = NULL; }
}

size_t rc_serialized_size(const void *state) {
    size_t size;
    memcpy(&size, state, sizeof size);
    return size;
}

Status rc_serialize(Instance *c, int f, const void *state, unsigned char serialized[], size_t size) {
    NOT_NULL(f, state, 1);
    NOT_NULL(f, serialized, size);
    size_t stored = rc_serialized_size(state);
    if (size < stored) return rc_fail(c, f, REJECTED, "buffer of %zu bytes, %zu needed", size, stored);
    memcpy(serialized, (const unsigned char *)state + sizeof(size_t), stored);
    return STATUS_OK;
}

Status rc_deserialize(Instance *c, int f, const unsigned char serialized[], size_t size, void **state) {
    NOT_NULL(f, serialized, size);
    NOT_NULL(f, state, 1);
    const char *refusal = state_refusal(serialized, size, c->kind);
    if (refusal)
        return rc_fail(c, f, REJECTED, "%zu bytes are not an FMU state of %s: %s", size, model_info.identifier,
                       refusal);
    unsigned char *buffer = *state ? *state : c->allocate(size + sizeof(size_t), 1);
    if (!buffer) return rc_fail(c, f, REJECTED, "out of memory");
    memcpy(buffer, &size, sizeof size);
    memcpy(buffer + sizeof(size_t), serialized, size);
    *state = buffer;
    return STATUS_OK;
}
