/* SPDX-License-Identifier: Apache-2.0 */
/*
 * sfun_ccomm_read: C MEX Level-2 S-function that reads a ccomm signal.
 *
 * Parameters: 1 signal name (char), 2 sample time in s (-1 = inherited),
 *             3 width (elements of the signal), 4 node name (char, '' = $CCOMM_NODE
 *             or the hostname), 5 data type ('double', 'single', 'int32', 'uint32',
 *             'boolean'), 6 timeout in s (0 = signals.xml decides), 7 status output
 *             (0/1). The ccomm_lib.mdl block mask sets them by name; models made
 *             before it give only 1-4 (double port, status output).
 * Outputs:    1 the value (width elements of the data type; double converts from any
 *             signal type, other types must be the signal's), 2 (status output on)
 *             the status of this sample: 0 fresh, 1 stale (the safe value if one is
 *             configured; or older than the timeout), 2 never received, 3 no new
 *             event; negative = a ccomm error (see ccomm.h).
 * The signal is opened in mdlStart and closed in mdlTerminate; mdlOutputs makes one
 * non-blocking ccomm read, at the step's time (ccomm_blk_step). Code generation: sfun_ccomm_read.tlc calls the same
 * ccomm_blk.c functions.
 * Build: mex -I<prefix>/include -L<prefix>/lib -lccomm sfun_ccomm_read.c ccomm_blk.c
 */
#define S_FUNCTION_NAME sfun_ccomm_read
#define S_FUNCTION_LEVEL 2
#define CCOMM_SFUN_WHAT "ccomm read" /* error messages */
#define CCOMM_SFUN_WRITES 0        /* opens the signal for reading */

#include <string.h>

#include "ccomm_blk.h"
#include "simstruc.h"
#include "sfun_ccomm_common.h"

static void mdlInitializeSizes(SimStruct* S) {
  int width = sfun_ccomm_init_params(S);
  int status = param_status(S) == 1;
  if (width == 0) return;
  if (!ssSetNumInputPorts(S, 0)) return;
  if (!ssSetNumOutputPorts(S, status ? 2 : 1)) return;
  ssSetOutputPortWidth(S, 0, width);
  ssSetOutputPortDataType(S, 0, (DTypeId)param_dtype(S));
  if (status) {
    ssSetOutputPortWidth(S, 1, 1);
    ssSetOutputPortDataType(S, 1, SS_DOUBLE);
  }
  sfun_ccomm_init_work(S);
}

static void mdlOutputs(SimStruct* S, int_T tid) {
  ccomm_blk* b = (ccomm_blk*)ssGetPWork(S)[0];
  int r;
  ccomm_blk_step(b, ssGetT(S)); /* one clock reading per model step, for all blocks */
  r = ccomm_blk_read_port(b, ssGetOutputPortSignal(S, 0));
  UNUSED_ARG(tid);
  if (ssGetNumOutputPorts(S) > 1) ssGetOutputPortRealSignal(S, 1)[0] = (real_T)r;
}

#ifdef MATLAB_MEX_FILE
#include "simulink.c"
#else
#include "cg_sfun.h"
#endif
