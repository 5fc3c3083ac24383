/* SPDX-License-Identifier: Apache-2.0 */
/*
 * What sfun_ccomm_read.c and sfun_ccomm_write.c share: their parameters (signal name,
 * sample time, width, node, data type, timeout, status output; the first four alone in
 * models made before the masked library ccomm_lib.mdl), checked, fixed and handed to code
 * generation the same way, and the open/close of the block in mdlStart/mdlTerminate. Each S-function
 * defines S_FUNCTION_NAME, CCOMM_SFUN_WHAT ("ccomm read") and CCOMM_SFUN_WRITES (0/1)
 * and includes this after simstruc.h; it keeps its ports (mdlInitializeSizes, which
 * starts with sfun_ccomm_init_params) and mdlOutputs.
 */
#ifndef SFUN_CCOMM_COMMON_H
#define SFUN_CCOMM_COMMON_H

#include <stdio.h>

#define P_NAME 0
#define P_TS 1
#define P_WIDTH 2
#define P_NODE 3
#define P_DTYPE 4   /* 'double' (default), 'single', 'int32', 'uint32', 'boolean' */
#define P_TIMEOUT 5 /* read: seconds after which a value counts as stale, 0 = signals.xml only */
#define P_STATUS 6  /* 1: the block has its status (read) / result (write) output port */
#define N_PARAMS 7
#define N_PARAMS_V1 4 /* models made before the library: name, sample time, width, node */
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

static int param_scalar(SimStruct* S, int p, double* v) {
  const mxArray* a = ssGetSFcnParam(S, p);
  if (!mxIsDouble(a) || mxGetNumberOfElements(a) != 1) return 0;
  *v = mxGetScalar(a);
  return 1;
}

static int param_width(SimStruct* S) {
  double w;
  if (!param_scalar(S, P_WIDTH, &w) || w < 1.0 || w > 1024.0 || w != (double)(int)w) return -1;
  return (int)w;
}

static int has_v2_params(SimStruct* S) { return ssGetSFcnParamsCount(S) == N_PARAMS; }

/* The port's data type (CCOMM_BLK_* = Simulink DTypeId), -1 if the parameter is bad. */
static int param_dtype(SimStruct* S) {
  char buf[16];
  if (!has_v2_params(S)) return CCOMM_BLK_DOUBLE;
  if (!param_string(S, P_DTYPE, buf, (int)sizeof buf)) return -1;
  return ccomm_blk_dtype(buf);
}

static double param_timeout(SimStruct* S) {
  double t = 0.0;
  if (has_v2_params(S) && (!param_scalar(S, P_TIMEOUT, &t) || !(t >= 0.0))) return -1.0;
  return t;
}

/* 1/0, or -1 if the parameter is bad; models with four parameters have the port. */
static int param_status(SimStruct* S) {
  double v = 1.0;
  if (has_v2_params(S) && (!param_scalar(S, P_STATUS, &v) || (v != 0.0 && v != 1.0))) return -1;
  return v != 0.0;
}

#define MDL_CHECK_PARAMETERS
#if defined(MDL_CHECK_PARAMETERS) && defined(MATLAB_MEX_FILE)
static void mdlCheckParameters(SimStruct* S) {
  char buf[NAME_LEN];
  double ts;
  int n = ssGetSFcnParamsCount(S);
  if (n != N_PARAMS && n != N_PARAMS_V1) {
    snprintf(msg, sizeof msg, CCOMM_SFUN_WHAT ": %d parameters; expected 7 (signal, sample time, width, node, "
             "data type, timeout, status output; the ccomm_lib block mask sets them) or the 4 of older models", n);
    ssSetErrorStatus(S, msg);
    return;
  }
  if (!param_string(S, P_NAME, buf, NAME_LEN) || buf[0] == '\0') {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 1 (signal) must be the signal name");
    return;
  }
  if (!param_scalar(S, P_TS, &ts) || (ts <= 0.0 && ts != -1.0)) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 2 (sample time) must be > 0, or -1 (inherited)");
    return;
  }
  if (param_width(S) < 0) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 3 (width) must be an integer 1..1024");
    return;
  }
  if (!param_string(S, P_NODE, buf, NAME_LEN)) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 4 (node) must be the node name ('' for the default)");
    return;
  }
  if (param_dtype(S) < 0) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 5 (data type) must be 'double', 'single', 'int32', 'uint32' or 'boolean'");
    return;
  }
  if (param_timeout(S) < 0.0) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 6 (timeout) must be 0 (signals.xml decides) or seconds > 0");
    return;
  }
  if (param_status(S) < 0) {
    ssSetErrorStatus(S, CCOMM_SFUN_WHAT ": parameter 7 (status output) must be 0 or 1");
    return;
  }
}
#endif

/* The start of mdlInitializeSizes: declares and checks the parameters (MEX), fixes
 * them; returns the width, or 0 when Simulink reported a problem. */
static int sfun_ccomm_init_params(SimStruct* S) {
  int width, p;
  /* 7 parameters, or 4 in models saved before the masked library: a variable count. */
  ssSetNumSFcnParams(S, -1);
#if defined(MATLAB_MEX_FILE)
  mdlCheckParameters(S);
  if (ssGetErrorStatus(S) != NULL) return 0;
#endif
  /* Every parameter fixes the block's interface or its connection: not tunable. */
  for (p = 0; p < ssGetSFcnParamsCount(S); p++) ssSetSFcnParamTunable(S, p, 0);
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
  ssGetPWork(S)[0] = ccomm_blk_open_typed(node, name, param_width(S), CCOMM_SFUN_WRITES, param_dtype(S),
                                          param_timeout(S), msg, sizeof msg);
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
  if (!ssWriteRTWParamSettings(S, 6, SSWRITE_VALUE_QSTR, "SignalName", name,
                               SSWRITE_VALUE_QSTR, "Node", node,
                               SSWRITE_VALUE_NUM, "Width", (real_T)param_width(S),
                               SSWRITE_VALUE_NUM, "DataType", (real_T)param_dtype(S),
                               SSWRITE_VALUE_NUM, "Timeout", (real_T)param_timeout(S),
                               SSWRITE_VALUE_NUM, "StatusOutput", (real_T)param_status(S))) {
    return;
  }
}
#endif

#endif /* SFUN_CCOMM_COMMON_H */
