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

#include <string.h>

#include "ccomm_blk.h"
#include "simstruc.h"

#define P_NAME 0
#define P_TS 1
#define P_WIDTH 2
#define P_NODE 3
#define N_PARAMS 4
#define NAME_LEN 128

/* Simulink keeps the pointer given to ssSetErrorStatus: messages live here. */
static char msg[512];

static int param_string(SimStruct* S, int p, char* out, int len) {
  const mxArray* a = ssGetSFcnParam(S, p);
  if (!mxIsChar(a)) return 0;
  if (mxGetNumberOfElements(a) == 0) {
    out[0] = '\0';
    return 1;
  }
  return mxGetString(a, out, len) == 0;
}

static int param_width(SimStruct* S) {
  const mxArray* a = ssGetSFcnParam(S, P_WIDTH);
  if (!mxIsDouble(a) || mxGetNumberOfElements(a) != 1) return -1;
  double w = mxGetScalar(a);
  if (w < 1.0 || w > 1024.0 || w != (double)(int)w) return -1;
  return (int)w;
}

#define MDL_CHECK_PARAMETERS
#if defined(MDL_CHECK_PARAMETERS) && defined(MATLAB_MEX_FILE)
static void mdlCheckParameters(SimStruct* S) {
  char buf[NAME_LEN];
  const mxArray* ts = ssGetSFcnParam(S, P_TS);
  if (!param_string(S, P_NAME, buf, NAME_LEN) || buf[0] == '\0') {
    ssSetErrorStatus(S, "ccomm read: parameter 1 must be the signal name");
    return;
  }
  if (!mxIsDouble(ts) || mxGetNumberOfElements(ts) != 1 ||
      (mxGetScalar(ts) <= 0.0 && mxGetScalar(ts) != -1.0)) {
    ssSetErrorStatus(S, "ccomm read: parameter 2 must be a sample time > 0, or -1 (inherited)");
    return;
  }
  if (param_width(S) < 0) {
    ssSetErrorStatus(S, "ccomm read: parameter 3 must be the width, an integer 1..1024");
    return;
  }
  if (!param_string(S, P_NODE, buf, NAME_LEN)) {
    ssSetErrorStatus(S, "ccomm read: parameter 4 must be the node name ('' for the default)");
    return;
  }
}
#endif

static void mdlInitializeSizes(SimStruct* S) {
  int width;
  ssSetNumSFcnParams(S, N_PARAMS);
#if defined(MATLAB_MEX_FILE)
  if (ssGetNumSFcnParams(S) != ssGetSFcnParamsCount(S)) return;
  mdlCheckParameters(S);
  if (ssGetErrorStatus(S) != NULL) return;
#endif
  /* Name, sample time, width and node fix the block's interface: not tunable. */
  ssSetSFcnParamTunable(S, P_NAME, 0);
  ssSetSFcnParamTunable(S, P_TS, 0);
  ssSetSFcnParamTunable(S, P_WIDTH, 0);
  ssSetSFcnParamTunable(S, P_NODE, 0);
  width = param_width(S);
  if (width < 1) width = 1;

  ssSetNumContStates(S, 0);
  ssSetNumDiscStates(S, 0);
  if (!ssSetNumInputPorts(S, 0)) return;
  if (!ssSetNumOutputPorts(S, 2)) return;
  ssSetOutputPortWidth(S, 0, width);
  ssSetOutputPortWidth(S, 1, 1);
  ssSetNumSampleTimes(S, 1);
  ssSetNumRWork(S, 0);
  ssSetNumIWork(S, 0);
  ssSetNumPWork(S, 1); /* the ccomm_blk */
  ssSetNumModes(S, 0);
  ssSetNumNonsampledZCs(S, 0);
  ssSetOptions(S, SS_OPTION_EXCEPTION_FREE_CODE | SS_OPTION_CALL_TERMINATE_ON_EXIT);
}

static void mdlInitializeSampleTimes(SimStruct* S) {
  double ts = mxGetScalar(ssGetSFcnParam(S, P_TS));
  ssSetSampleTime(S, 0, ts > 0.0 ? ts : INHERITED_SAMPLE_TIME);
  ssSetOffsetTime(S, 0, 0.0);
}

#define MDL_START
#if defined(MDL_START)
static void mdlStart(SimStruct* S) {
  char name[NAME_LEN], node[NAME_LEN];
  ssGetPWork(S)[0] = NULL;
  if (!param_string(S, P_NAME, name, NAME_LEN) || !param_string(S, P_NODE, node, NAME_LEN)) {
    ssSetErrorStatus(S, "ccomm read: bad parameters");
    return;
  }
  ssGetPWork(S)[0] = ccomm_blk_open(node, name, param_width(S), 0, msg, sizeof msg);
  if (ssGetPWork(S)[0] == NULL) ssSetErrorStatus(S, msg);
}
#endif

static void mdlOutputs(SimStruct* S, int_T tid) {
  real_T* y = ssGetOutputPortRealSignal(S, 0);
  real_T* status = ssGetOutputPortRealSignal(S, 1);
  UNUSED_ARG(tid);
  status[0] = (real_T)ccomm_blk_read((ccomm_blk*)ssGetPWork(S)[0], y);
}

static void mdlTerminate(SimStruct* S) {
  ccomm_blk_close((ccomm_blk*)ssGetPWork(S)[0]);
  ssGetPWork(S)[0] = NULL;
}

#define MDL_RTW
#if defined(MDL_RTW) && defined(MATLAB_MEX_FILE)
/* Hands the parameters to sfun_ccomm_read.tlc as SFcnParamSettings. */
static void mdlRTW(SimStruct* S) {
  char name[NAME_LEN], node[NAME_LEN];
  if (!param_string(S, P_NAME, name, NAME_LEN) || !param_string(S, P_NODE, node, NAME_LEN)) return;
  if (!ssWriteRTWParamSettings(S, 3, SSWRITE_VALUE_QSTR, "SignalName", name,
                               SSWRITE_VALUE_QSTR, "Node", node,
                               SSWRITE_VALUE_NUM, "Width", (real_T)param_width(S))) {
    return;
  }
}
#endif

#ifdef MATLAB_MEX_FILE
#include "simulink.c"
#else
#include "cg_sfun.h"
#endif
