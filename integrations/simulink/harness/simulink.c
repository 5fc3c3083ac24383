/* SPDX-License-Identifier: Apache-2.0 */
/* Stand-in for MATLAB's simulink.c (the MEX build of an S-function): registers the
 * callbacks for the harness instead of the MEX entry point. */
#define HARNESS_SUFFIX _mex
#include "harness_register.h"
