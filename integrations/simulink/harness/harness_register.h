/* SPDX-License-Identifier: Apache-2.0 */
/* Included at the end of an S-function (through the simulink.c or cg_sfun.h stand-in):
 * publishes its callbacks as <S_FUNCTION_NAME>_<HARNESS_SUFFIX>. */
#define HARNESS_CAT2(a, b) a##b
#define HARNESS_CAT(a, b) HARNESS_CAT2(a, b)
#define HARNESS_STR2(a) #a
#define HARNESS_STR(a) HARNESS_STR2(a)

const harness_methods HARNESS_CAT(S_FUNCTION_NAME, HARNESS_SUFFIX) = {
    HARNESS_STR(S_FUNCTION_NAME),
    mdlInitializeSizes,
    mdlInitializeSampleTimes,
#if defined(MDL_CHECK_PARAMETERS) && defined(MATLAB_MEX_FILE)
    mdlCheckParameters,
#else
    NULL,
#endif
#if defined(MDL_START)
    mdlStart,
#else
    NULL,
#endif
    mdlOutputs,
    mdlTerminate,
#if defined(MDL_RTW) && defined(MATLAB_MEX_FILE)
    mdlRTW,
#else
    NULL,
#endif
};
