/* What the participants' C twins share (ground_block.c, soil_block.c): fmi2SetReal- and
 * fmi2GetReal-shaped copies between the value references and a block's inputs and outputs, with
 * the error of a reference out of range in ``message``. */
#ifndef ROVER_COSIM_BLOCK_IO_H
#define ROVER_COSIM_BLOCK_IO_H

#include <stddef.h>
#include <stdio.h>

#define OK 0
#define ERROR 3

static int block_set(double *in, unsigned int n_inputs, char *message, size_t size, const unsigned int *vr, size_t n,
                     const double *value) {
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= n_inputs) {
            snprintf(message, size, "set_real: no such input");
            return ERROR;
        }
        in[vr[k]] = value[k];
    }
    return OK;
}

static int block_get(const double *out, unsigned int n_outputs, char *message, size_t size, const unsigned int *vr,
                     size_t n, double *value) {
    for (size_t k = 0; k < n; k++) {
        if (vr[k] >= n_outputs) {
            snprintf(message, size, "get_real: no such output");
            return ERROR;
        }
        value[k] = out[vr[k]];
    }
    return OK;
}

#endif
