/* SPDX-License-Identifier: Apache-2.0 */
/*
 * sfun_ccomm_read: C MEX Level-2 S-function that reads a ccomm signal.
 *
 * Parameters: 1 signal name (char), 2 sample time in s (-1 = inherited),
 *             3 width (elements of the signal), 4 node name (char, '' = $CCOMM_NODE
 *             or the hostname).
 * Outputs:    1 the value (width doubles), 2 the status of this sample: 0 fresh,
 *             1 stale (the safe value if one is configured), 2 never received,
 *             3 no new event; negative = a ccomm error (see ccomm.h).
 * The signal is opened in mdlStart and closed in mdlTerminate; mdlOutputs makes one
 * non-blocking ccomm read. Code generation: sfun_ccomm_read.tlc calls the same
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
  if (width == 0) return;
  if (!ssSetNumInputPorts(S, 0)) return;
  if (!ssSetNumOutputPorts(S, 2)) return;
  ssSetOutputPortWidth(S, 0, width);
  ssSetOutputPortWidth(S, 1, 1);
  sfun_ccomm_init_work(S);
}

static void mdlOutputs(SimStruct* S, int_T tid) {
  real_T* y = ssGetOutputPortRealSignal(S, 0);
  real_T* status = ssGetOutputPortRealSignal(S, 1);
  UNUSED_ARG(tid);
  status[0] = (real_T)ccomm_blk_read((ccomm_blk*)ssGetPWork(S)[0], y);
}

#ifdef MATLAB_MEX_FILE
#include "simulink.c"
#else
#include "cg_sfun.h"
#endif
