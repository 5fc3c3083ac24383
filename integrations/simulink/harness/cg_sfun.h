/* SPDX-License-Identifier: Apache-2.0 */
/* Stand-in for MATLAB's cg_sfun.h (the S-function compiled into generated code, as
 * Simulink Coder does for non-inlined S-functions): registers the callbacks. */
#define HARNESS_SUFFIX _cg
#include "harness_register.h"
