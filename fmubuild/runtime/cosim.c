/* rover-cosim FMU runtime, the core (core.h): the Co-Simulation step, integrated by ode23s.c,
 * with inputs held or interpolated linearly over it. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core.h"

/* First derivatives of inputs for the next step (canInterpolateInputs): the input is
 * interpolated linearly from its value at the communication point; after the step it holds its
 * value at the step's end and the derivatives are cleared. */
Status rc_set_input_derivatives(Instance *c, int f, const unsigned int vr[], size_t nvr, const int order[],
                                const double value[]) {
    const int F = f;
    if (c->kind != KIND_CO_SIMULATION && nvr > 0)
        return rc_fail(c, F, REJECTED, "input derivatives are for Co-Simulation only");
    NOT_NULL(F, vr, nvr);
    NOT_NULL(F, order, nvr);
    NOT_NULL(F, value, nvr);
    for (size_t i = 0; i < nvr; i++) {
        int r = real_index(vr[i]);
        if (r < off_u() || r >= off_y())
            return rc_fail(c, F, REJECTED, "value reference %u: not an input", vr[i]);
        if (order[i] != 1)
            return rc_fail(c, F, REJECTED, "%s: derivative order %d; only order 1 is supported", real_name(vr[i]),
                        (int)order[i]);
        if (!isfinite(value[i]))
            return rc_fail(c, F, REJECTED, "%s: derivative %g: expected a finite value", real_name(vr[i]), value[i]);
    }
    for (size_t i = 0; i < nvr; i++) c->u_der[real_index(vr[i]) - off_u()] = value[i];
    c->t_step = c->t;  /* the inputs' values hold at the current time (the start time before the first step) */
    c->interpolating = 0;
    for (int i = 0; i < model_info.nu; i++) c->interpolating |= c->u_der[i] != 0.0;
    /* The inputs' values at the current point are unchanged: so are the derivatives and outputs
     * known there (the integrator's first stage among them). */
    return STATUS_OK;
}

Status rc_do_step(Instance *c, int f, double currentCommunicationPoint, double communicationStepSize) {
    const int F = f;
    if (!(communicationStepSize > 0.0) || !isfinite(communicationStepSize))
        return rc_fail(c, F, REJECTED, "communication step size %g: expected > 0", communicationStepSize);
    if (!isfinite(currentCommunicationPoint) || fabs(currentCommunicationPoint - c->t) > 1e-9 * fmax(1.0, fabs(c->t)))
        return rc_fail(c, F, REJECTED, "current communication point %.17g differs from the FMU's time %.17g",
                    currentCommunicationPoint, c->t);
    double t_end = currentCommunicationPoint + communicationStepSize;
    if (!(t_end > currentCommunicationPoint))
        return rc_fail(c, F, REJECTED, "communication step size %g does not advance the time %.17g (t + h == t)",
                    communicationStepSize, currentCommunicationPoint);
    if (c->has_stop && t_end > c->t_stop * (1.0 + 1e-12) + 1e-12)
        return rc_fail(c, F, REJECTED, "step to t = %.17g goes past the stop time %.17g", t_end, c->t_stop);
    c->solver.rtol = c->rtol;
    c->solver.atol = c->rtol;
    c->solver.max_step = c->max_step;
    char message[512];
    double t = currentCommunicationPoint;
    c->t_step = currentCommunicationPoint;
    c->h_step = communicationStepSize;
    if (c->f0_updated && c->solver.f0_valid) c->eval.updated++; /* begun from updated derivatives */
    c->f0_updated = 0;
    rc_input_rates(c); /* dfdt with this step's input derivatives (none: the model's own) */
    int status = ode23s_integrate(&c->solver, &t, c->x, t_end, message, sizeof message);
    c->t = t;
    c->xdot_valid = 0;
    c->y_valid = 0;
    if (c->interpolating) {
        /* The inputs now hold their values at the step's end: those its last stage was evaluated
         * with (rc_inputs_at(t): the same bits), so the integrator's derivatives there stay
         * valid, and an input set next to the bits it has changes nothing (rc_set_real). The
         * gain of the affine inputs may read the inputs that moved: taken again when needed. */
        memcpy(c->u, rc_inputs_at(c, t), sizeof(double) * (size_t)model_info.nu);
        for (int i = 0; i < model_info.nu; i++) c->u_der[i] = 0.0;
        c->interpolating = 0;
        c->gain_valid = 0;
    }
    c->h_step = 0.0;
    if (status != 0) return rc_fail(c, F, BROKEN, "integration failed: %s", message);
    c->t = t_end;
    Status checked = rc_update(c, F, 0, 1); /* the outputs at t_end, and with them the asserts */
    if (checked != STATUS_ERROR) rc_remember(c);
    return checked;
}
