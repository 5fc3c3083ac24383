/* SPDX-License-Identifier: Apache-2.0 */
/*
 * ccomm blocks for Simulink: the code both S-functions (simulation, MEX) and the code
 * Embedded Coder generates from their TLC files call, so simulation and the deployed
 * model use the same path to the ccomm C API.
 *
 * ccomm_blk_open / ccomm_blk_close allocate and attach (mdlStart / mdlTerminate, model
 * start / terminate); ccomm_blk_read / ccomm_blk_write are real-time safe (no allocation,
 * no blocking: one ccomm_read or ccomm_write per call, events drained within a bound).
 */
#ifndef CCOMM_BLK_H
#define CCOMM_BLK_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ccomm_blk ccomm_blk;

/* Opens signal `signal` of node `node` (NULL or "": $CCOMM_NODE, else the hostname) for a
 * block with `width` elements; `for_write` = 1 for the write block, which also checks
 * that this node produces the signal. Returns NULL and a message in err on failure. */
ccomm_blk* ccomm_blk_open(const char* node, const char* signal, int width, int for_write,
                          char* err, size_t err_len);

/* Read block, once per sample: y[width] gets the value as doubles. Returns the ccomm
 * status (0 fresh, 1 stale, 2 never received, 3 no new event) or a negative ccomm
 * error. State signals: stale values are the configured safe value if there is one,
 * never-received values are 0. Event signals: y is the newest event of this step;
 * with none (status 3) y keeps the previous event. */
int ccomm_blk_read(ccomm_blk* b, double* y);

/* Write block, once per sample: sends u[width] converted to the signal's type (integers
 * rounded and saturated, bool = u != 0). Event signals are sent only when the value
 * changed. Returns 0 or a negative ccomm error. */
int ccomm_blk_write(ccomm_blk* b, const double* u);

/* Detaches and frees; NULL is allowed. */
void ccomm_blk_close(ccomm_blk* b);

#ifdef __cplusplus
}
#endif
#endif
