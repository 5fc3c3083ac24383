/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Integration methods for the ccomm target: Discrete, Euler, RungeKutta2, RungeKutta4
 * (fixed step, as a periodic task needs). Submodel %SUBMODEL_NAME%.
 */
#ifndef XX_INTEG_H
#define XX_INTEG_H

#include "xxtypes.h"

void %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Initialize(void);
void %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Terminate(void);
/* Advances the states and the time by one step and re-evaluates the dynamic equations. */
void %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Step(void);

#endif
