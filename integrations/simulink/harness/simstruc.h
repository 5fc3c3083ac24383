/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Minimal stand-in for MATLAB's simstruc.h, for testing the ccomm S-functions without
 * MATLAB. It provides only what sfun_ccomm_read.c and sfun_ccomm_write.c use, with the
 * same names and meaning, backed by a plain struct the harness fills in and inspects.
 * It is not MathWorks code and not a Simulink emulation: the harness (harness.c) calls
 * the mdl* callbacks in the order Simulink documents for a fixed-step simulation.
 */
#ifndef CCOMM_HARNESS_SIMSTRUC_H
#define CCOMM_HARNESS_SIMSTRUC_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#if !defined(S_FUNCTION_NAME) || !defined(S_FUNCTION_LEVEL) || S_FUNCTION_LEVEL != 2
#error "define S_FUNCTION_NAME and S_FUNCTION_LEVEL 2 before including simstruc.h"
#endif

typedef double real_T;
typedef double time_T;
typedef int int_T;
typedef unsigned int uint_T;
typedef int int32_T;
typedef unsigned char boolean_T;
typedef char char_T;
typedef float real32_T;
typedef unsigned int uint32_T;

/* Simulink's built-in data type ids (same numbers as MATLAB's simstruc_types.h). */
typedef int DTypeId;
#define SS_DOUBLE 0
#define SS_SINGLE 1
#define SS_INT8 2
#define SS_UINT8 3
#define SS_INT16 4
#define SS_UINT16 5
#define SS_INT32 6
#define SS_UINT32 7
#define SS_BOOLEAN 8

/* Block parameters as the harness makes them: char row vectors or real scalars. */
typedef struct mxArray {
  int is_char;
  size_t n;        /* number of elements */
  const char* str; /* is_char */
  double num;      /* !is_char && n == 1 */
} mxArray;

static inline int mxIsChar(const mxArray* a) { return a && a->is_char; }
static inline int mxIsDouble(const mxArray* a) { return a && !a->is_char; }
static inline size_t mxGetNumberOfElements(const mxArray* a) { return a ? a->n : 0; }
static inline double mxGetScalar(const mxArray* a) { return (a && !a->is_char && a->n) ? a->num : 0.0; }
/* As MATLAB: copies at most len-1 characters; 0 = all fit, 1 = truncated or not char. */
static inline int mxGetString(const mxArray* a, char* buf, int len) {
  size_t n;
  if (!a || !a->is_char || len <= 0) return 1;
  n = strlen(a->str);
  if (n > (size_t)(len - 1)) {
    memcpy(buf, a->str, (size_t)(len - 1));
    buf[len - 1] = '\0';
    return 1;
  }
  memcpy(buf, a->str, n + 1);
  return 0;
}

#define HARNESS_MAX 8

typedef struct SimStruct {
  const char* path;
  int n_params_expected;
  int n_params_given;
  const mxArray* params[HARNESS_MAX];
  int tunable[HARNESS_MAX];
  int n_cont_states, n_disc_states;
  int n_in, n_out;
  int in_width[HARNESS_MAX], out_width[HARNESS_MAX];
  int in_direct_feedthrough[HARNESS_MAX], in_contiguous[HARNESS_MAX];
  DTypeId in_dtype[HARNESS_MAX], out_dtype[HARNESS_MAX]; /* SS_DOUBLE unless set */
  void* in_signal[HARNESS_MAX];  /* contiguous, of the port's data type */
  void* out_signal[HARNESS_MAX];
  double t; /* model time of the current step (ssGetT) */
  int n_sample_times;
  double sample_time[HARNESS_MAX], offset_time[HARNESS_MAX];
  int n_rwork, n_iwork, n_pwork, n_modes, n_zcs;
  void* pwork[HARNESS_MAX];
  unsigned options;
  const char* error;
  char rtw[1024]; /* what mdlRTW wrote, "name=value;" */
} SimStruct;

#define INHERITED_SAMPLE_TIME (-1.0)
#define SS_OPTION_EXCEPTION_FREE_CODE 0x1u
#define SS_OPTION_CALL_TERMINATE_ON_EXIT 0x2u
#define UNUSED_ARG(x) ((void)(x))

#define ssGetPath(S) ((S)->path)
#define ssGetT(S) ((S)->t)
/* -1: a variable number of parameters, which the S-function checks itself. */
#define ssSetNumSFcnParams(S, n) ((S)->n_params_expected = (n))
#define ssGetNumSFcnParams(S) ((S)->n_params_expected)
#define ssGetSFcnParamsCount(S) ((S)->n_params_given)
#define ssGetSFcnParam(S, i) ((S)->params[i])
#define ssSetSFcnParamTunable(S, i, v) ((S)->tunable[i] = (v))
#define ssSetNumContStates(S, n) ((S)->n_cont_states = (n))
#define ssSetNumDiscStates(S, n) ((S)->n_disc_states = (n))
#define ssSetNumInputPorts(S, n) ((S)->n_in = (n), (n) <= HARNESS_MAX)
#define ssSetNumOutputPorts(S, n) ((S)->n_out = (n), (n) <= HARNESS_MAX)
#define ssSetInputPortWidth(S, p, w) ((S)->in_width[p] = (w))
#define ssSetOutputPortWidth(S, p, w) ((S)->out_width[p] = (w))
#define ssGetInputPortWidth(S, p) ((S)->in_width[p])
#define ssGetOutputPortWidth(S, p) ((S)->out_width[p])
#define ssSetInputPortDirectFeedThrough(S, p, v) ((S)->in_direct_feedthrough[p] = (v))
#define ssSetInputPortRequiredContiguous(S, p, v) ((S)->in_contiguous[p] = (v))
#define ssGetInputPortRealSignal(S, p) ((const real_T*)(S)->in_signal[p])
#define ssGetOutputPortRealSignal(S, p) ((real_T*)(S)->out_signal[p])
#define ssGetInputPortSignal(S, p) ((const void*)(S)->in_signal[p])
#define ssGetOutputPortSignal(S, p) ((S)->out_signal[p])
#define ssSetInputPortDataType(S, p, t) ((S)->in_dtype[p] = (t))
#define ssSetOutputPortDataType(S, p, t) ((S)->out_dtype[p] = (t))
#define ssGetNumInputPorts(S) ((S)->n_in)
#define ssGetNumOutputPorts(S) ((S)->n_out)
#define ssSetNumSampleTimes(S, n) ((S)->n_sample_times = (n))
#define ssSetSampleTime(S, i, t) ((S)->sample_time[i] = (t))
#define ssSetOffsetTime(S, i, t) ((S)->offset_time[i] = (t))
#define ssSetNumRWork(S, n) ((S)->n_rwork = (n))
#define ssSetNumIWork(S, n) ((S)->n_iwork = (n))
#define ssSetNumPWork(S, n) ((S)->n_pwork = (n))
#define ssSetNumModes(S, n) ((S)->n_modes = (n))
#define ssSetNumNonsampledZCs(S, n) ((S)->n_zcs = (n))
#define ssGetPWork(S) ((S)->pwork)
#define ssSetOptions(S, o) ((S)->options = (o))
#define ssSetErrorStatus(S, m) ((S)->error = (m))
#define ssGetErrorStatus(S) ((S)->error)

/* mdlRTW: records "name=value;" pairs so the harness can check what TLC would get. */
#define SSWRITE_VALUE_STR 1
#define SSWRITE_VALUE_QSTR 2
#define SSWRITE_VALUE_NUM 3
static inline int ssWriteRTWParamSettings(SimStruct* S, int n, ...) {
  va_list ap;
  int i;
  size_t len = strlen(S->rtw);
  va_start(ap, n);
  for (i = 0; i < n; i++) {
    int kind = va_arg(ap, int);
    const char* name = va_arg(ap, const char*);
    if (kind == SSWRITE_VALUE_NUM) {
      double v = va_arg(ap, double);
      len += (size_t)snprintf(S->rtw + len, sizeof S->rtw - len, "%s=%g;", name, v);
    } else {
      const char* v = va_arg(ap, const char*);
      len += (size_t)snprintf(S->rtw + len, sizeof S->rtw - len,
                              kind == SSWRITE_VALUE_QSTR ? "%s=\"%s\";" : "%s=%s;", name, v);
    }
    if (len >= sizeof S->rtw) break;
  }
  va_end(ap);
  return 1;
}

/* The callbacks of one S-function, registered by the simulink.c / cg_sfun.h stand-ins. */
typedef struct harness_methods {
  const char* name;
  void (*initialize_sizes)(SimStruct*);
  void (*initialize_sample_times)(SimStruct*);
  void (*check_parameters)(SimStruct*); /* NULL if not compiled */
  void (*start)(SimStruct*);            /* NULL if not compiled */
  void (*outputs)(SimStruct*, int_T);
  void (*terminate)(SimStruct*);
  void (*rtw)(SimStruct*); /* NULL if not compiled */
} harness_methods;

#endif
