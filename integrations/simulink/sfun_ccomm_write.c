/* SPDX-License-Identifier: Apache-2.0 */
/*
 * sfun_ccomm_write: C MEX Level-2 S-function that writes a ccomm signal this node
 * produces.
 *
 * Parameters: 1 signal name (char), 2 sample time in s (-1 = inherited),
 *             3 width (elements of the signal), 4 node name (char, '' = $CCOMM_NODE
 *             or the hostname).
 * Input:      1 the value (width doubles; integers are rounded and saturated to the
 *             signal's type, bool is u != 0).
 * Output:     1 the result of this sample's write: 0, or a negative ccomm error.
 * The signal is opened in mdlStart and closed in mdlTerminate; mdlOutputs makes one
 * non-blocking ccomm write (event signals: only when the value changed). Code
 * generation: sfun_ccomm_write.tlc calls the same ccomm_blk.c functions.
 * Build: mex -I<prefix>/include -L<prefix>/lib -lccomm sfun_ccomm_write.c ccomm_blk.c
 */
#define S_FUNCTION_NAME sfun_ccomm_write
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
    ssSetErrorStatus(S, "ccomm write: parameter 1 must be the signal name");
    return;
  }
  if (!mxIsDouble(ts) || mxGetNumberOfElements(ts) != 1 ||
      (mxGetScalar(ts) <= 0.0 && mxGetScalar(ts) != -1.0)) {
    ssSetErrorStatus(S, "ccomm write: parameter 2 must be a sample time > 0, or -1 (inherited)");
    return;
  }
  if (param_width(S) < 0) {
    ssSetErrorStatus(S, "ccomm write: parameter 3 must be the width, an integer 1..1024");
    return;
  }
  if (!param_string(S, P_NODE, buf, NAME_LEN)) {
    ssSetErrorStatus(S, "ccomm write: parameter 4 must be the node name ('' for the default)");
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
  ssSetSFcnParamTunable(S, P_NAME, 0);
  ssSetSFcnParamTunable(S, P_TS, 0);
  ssSetSFcnParamTunable(S, P_WIDTH, 0);
  ssSetSFcnParamTunable(S, P_NODE, 0);
  width = param_width(S);
  if (width < 1) width = 1;

  ssSetNumContStates(S, 0);
  ssSetNumDiscStates(S, 0);
  if (!ssSetNumInputPorts(S, 1)) return;
  ssSetInputPortWidth(S, 0, width);
  ssSetInputPortDirectFeedThrough(S, 0, 1); /* the write happens in mdlOutputs */
  ssSetInputPortRequiredContiguous(S, 0, 1);
  if (!ssSetNumOutputPorts(S, 1)) return;
  ssSetOutputPortWidth(S, 0, 1);
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
    ssSetErrorStatus(S, "ccomm write: bad parameters");
    return;
  }
  ssGetPWork(S)[0] = ccomm_blk_open(node, name, param_width(S), 1, msg, sizeof msg);
  if (ssGetPWork(S)[0] == NULL) ssSetErrorStatus(S, msg);
}
#endif

static void mdlOutputs(SimStruct* S, int_T tid) {
  const real_T* u = ssGetInputPortRealSignal(S, 0);
  real_T* result = ssGetOutputPortRealSignal(S, 0);
  UNUSED_ARG(tid);
  result[0] = (real_T)ccomm_blk_write((ccomm_blk*)ssGetPWork(S)[0], u);
}

static void mdlTerminate(SimStruct* S) {
  ccomm_blk_close((ccomm_blk*)ssGetPWork(S)[0]);
  ssGetPWork(S)[0] = NULL;
}

#define MDL_RTW
#if defined(MDL_RTW) && defined(MATLAB_MEX_FILE)
/* Hands the parameters to sfun_ccomm_write.tlc as SFcnParamSettings. */
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
