/* SPDX-License-Identifier: Apache-2.0 */
/*
 * What sfun_ccomm_read.c and sfun_ccomm_write.c share: their four parameters (signal
 * name, sample time, width, node), checked, fixed and handed to code generation the
 * same way, and the open/close of the block in mdlStart/mdlTerminate. Each S-function
 * defines S_FUNCTION_NAME, CCOMM_SFUN_WHAT ("ccomm read") and CCOMM_SFUN_WRITES (0/1)
 * and includes this after simstruc.h; it keeps its ports (mdlInitializeSizes, which
 * starts with sfun_ccomm_init_params) and mdlOutputs.
 */
#ifndef SFUN_CCOMM_COMMON_H
#define SFUN_CCOMM_COMMON_H

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
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 1 must be the signal name");
    return;
  }
  if (!mxIsDouble(ts) || mxGetNumberOfElements(ts) != 1 ||
      (mxGetScalar(ts) <= 0.0 && mxGetScalar(ts) != -1.0)) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 2 must be a sample time > 0, or -1 (inherited)");
    return;
  }
  if (param_width(S) < 0) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 3 must be the width, an integer 1..1024");
    return;
  }
  if (!param_string(S, P_NODE, buf, NAME_LEN)) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 4 must be the node name ('' for the default)");
    return;
  }
}
#endif

/* The start of mdlInitializeSizes: declares and checks the parameters (MEX), fixes
 * them; returns the width, or 0 when Simulink reported a problem. */
static int sfun_ccomm_init_params(SimStruct* S) {
  int width;
  ssSetNumSFcnParams(S, N_PARAMS);
#if defined(MATLAB_MEX_FILE)
  if (ssGetNumSFcnParams(S) != ssGetSFcnParamsCount(S)) return 0;
  mdlCheckParameters(S);
  if (ssGetErrorStatus(S) != NULL) return 0;
#endif
  /* Name, sample time, width and node fix the block's interface: not tunable. */
  ssSetSFcnParamTunable(S, P_NAME, 0);
  ssSetSFcnParamTunable(S, P_TS, 0);
  ssSetSFcnParamTunable(S, P_WIDTH, 0);
  ssSetSFcnParamTunable(S, P_NODE, 0);
  width = param_width(S);
  return width < 1 ? 1 : width;
}

/* The end of mdlInitializeSizes: one sample time, the ccomm_blk in the pointer work
 * vector, no states. */
static void sfun_ccomm_init_work(SimStruct* S) {
  ssSetNumContStates(S, 0);
  ssSetNumDiscStates(S, 0);
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
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": bad parameters");
    return;
  }
  ssGetPWork(S)[0] = ccomm_blk_open(node, name, param_width(S), CCOMM_SFUN_WRITES, msg, sizeof msg);
  if (ssGetPWork(S)[0] == NULL) ssSetErrorStatus(S, msg);
}
#endif

static void mdlTerminate(SimStruct* S) {
  ccomm_blk_close((ccomm_blk*)ssGetPWork(S)[0]);
  ssGetPWork(S)[0] = NULL;
}

#define MDL_RTW
#if defined(MDL_RTW) && defined(MATLAB_MEX_FILE)
/* Hands the parameters to the block's .tlc as SFcnParamSettings. */
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

#endif /* SFUN_CCOMM_COMMON_H */
