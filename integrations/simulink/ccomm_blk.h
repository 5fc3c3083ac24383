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

/* Port data types, numbered as Simulink's built-in DTypeId (SS_DOUBLE, ...), so the
 * S-functions and the TLC files pass the port's type id through unchanged. A double port
 * converts to and from any signal type; every other port type must be the signal's own
 * type (its values are copied, never converted). */
enum {
  CCOMM_BLK_DOUBLE = 0,  /* real_T */
  CCOMM_BLK_SINGLE = 1,  /* real32_T <-> float signals */
  CCOMM_BLK_INT32 = 6,   /* int32_T <-> int32 signals */
  CCOMM_BLK_UINT32 = 7,  /* uint32_T <-> uint32 signals */
  CCOMM_BLK_BOOLEAN = 8  /* boolean_T (one byte, 0/1) <-> bool signals */
};

/* Returns the CCOMM_BLK_* id of a type name ("double", "single", "int32", "uint32",
 * "boolean"), or -1. */
int ccomm_blk_dtype(const char* name);

/* Opens signal `signal` of node `node` (NULL or "": $CCOMM_NODE, else the hostname) for a
 * block with `width` elements; `for_write` = 1 for the write block, which also checks
 * that this node produces the signal. Returns NULL and a message in err on failure. */
ccomm_blk* ccomm_blk_open(const char* node, const char* signal, int width, int for_write,
                          char* err, size_t err_len);

/* As ccomm_blk_open, for a port of type `dtype` (CCOMM_BLK_*); the signal's type must
 * be that type unless the port is double. timeout_s > 0 (read blocks): a state value older
 * than that reads as stale (status 1, the value as read) even before the signal's
 * stale_after_ms; 0 = only the configuration decides. */
ccomm_blk* ccomm_blk_open_typed(const char* node, const char* signal, int width, int for_write,
                                int dtype, double timeout_s, char* err, size_t err_len);

/* Read and write for a block opened with ccomm_blk_open_typed: y / u point to `width`
 * elements of the port's type. Same statuses and rules as ccomm_blk_read / _write. */
int ccomm_blk_read_port(ccomm_blk* b, void* y);
int ccomm_blk_write_port(ccomm_blk* b, const void* u);

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

/* Once per sample, before the block's read or write: gives the block the time of this
 * model step. The first block called at a new `model_time` (ssGetT, or the task time in
 * generated code) reads CLOCK_MONOTONIC; the blocks after it in the same step, on the same
 * thread, reuse that reading (ccomm_set_time), so a step makes one clock reading, not one
 * per block: on the RaMstix, whose Linux serves the clock by a system call, a model with
 * 45 blocks makes 1 system call per step instead of 45. Reads then judge freshness, and
 * writes are stamped, at the step's start, as 20-sim's target does. Without this call a
 * block reads the clock in each read or write; once called, call it every step (the
 * block keeps the last step's time). Each thread (task of a multitasking model) keeps its
 * own step time; ccomm_blk_open forgets it (a new run may restart at the same time). */
void ccomm_blk_step(ccomm_blk* b, double model_time);

/* Detaches and frees; NULL is allowed. */
void ccomm_blk_close(ccomm_blk* b);

#ifdef __cplusplus
}
#endif
#endif
