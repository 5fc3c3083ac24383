/* SPDX-License-Identifier: Apache-2.0 */
/*
 * sfun_ccomm_write: C MEX Level-2 S-function that writes a ccomm signal this node
 * produces.
 *
 * Parameters: 1 signal name (char), 2 sample time in s (-1 = inherited),
 *             3 width (elements of the signal), 4 node name (char, '' = $CCOMM_NODE
 *             or the hostname), 5 data type ('double', 'single', 'int32', 'uint32',
 *             'boolean'), 6 timeout (unused by writes, 0), 7 status output (0/1).
 *             The ccomm_lib.mdl block mask sets them by name; models made before it
 *             give only 1-4 (double port, result output).
 * Input:      1 the value (width elements of the data type; double is converted to the
 *             signal's type: integers rounded and saturated, bool is u != 0; other
 *             types must be the signal's type and are copied).
 * Output:     1 (status output on) the result of this sample's write: 0, or a
 *             negative ccomm error.
 * The signal is opened in mdlStart and closed in mdlTerminate; mdlOutputs makes one
 * non-blocking ccomm write at the step's time (ccomm_blk_step; event signals: only when
 * the value changed). Code
 * generation: sfun_ccomm_write.tlc calls the same ccomm_blk.c functions.
 * Build: mex -I<prefix>/include -L<prefix>/lib -lccomm sfun_ccomm_write.c ccomm_blk.c
 */
#define S_FUNCTION_NAME sfun_ccomm_write
#define S_FUNCTION_LEVEL 2
#define CCOMM_SFUN_WHAT "ccomm write" /* error messages */
#define CCOMM_SFUN_WRITES 1        /* opens the signal for writing */

#include <string.h>

#include "ccomm_blk.h"
#include "simstruc.h"
#include "sfun_ccomm_common.h"

static void mdlInitializeSizes(SimStruct* S) {
  int width = sfun_ccomm_init_params(S);
  int status = param_status(S) == 1;
  if (width == 0) return;
  if (!ssSetNumInputPorts(S, 1)) return;
  ssSetInputPortWidth(S, 0, width);
  ssSetInputPortDataType(S, 0, (DTypeId)param_dtype(S));
  ssSetInputPortDirectFeedThrough(S, 0, 1); /* the write happens in mdlOutputs */
  ssSetInputPortRequiredContiguous(S, 0, 1);
  if (!ssSetNumOutputPorts(S, status ? 1 : 0)) return;
  if (status) {
    ssSetOutputPortWidth(S, 0, 1);
    ssSetOutputPortDataType(S, 0, SS_DOUBLE);
  }
  sfun_ccomm_init_work(S);
}

static void mdlOutputs(SimStruct* S, int_T tid) {
  ccomm_blk* b = (ccomm_blk*)ssGetPWork(S)[0];
  int r;
  ccomm_blk_step(b, ssGetT(S)); /* one clock reading per model step, for all blocks */
  r = ccomm_blk_write_port(b, ssGetInputPortSignal(S, 0));
  UNUSED_ARG(tid);
  if (ssGetNumOutputPorts(S) > 0) ssGetOutputPortRealSignal(S, 0)[0] = (real_T)r;
}

#ifdef MATLAB_MEX_FILE
#include "simulink.c"
#else
#include "cg_sfun.h"
#endif
