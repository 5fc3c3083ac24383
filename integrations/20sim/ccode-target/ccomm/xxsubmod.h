/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Submodel %SUBMODEL_NAME%: the three calls a task makes (20-sim's submodel interface).
 * u has XX_NUMBER_INPUTS elements, y has XX_NUMBER_OUTPUTS (pass arrays of at least one).
 */
#ifndef XX_SUBMOD_H
#define XX_SUBMOD_H

#include "xxtypes.h"

void %FUNCTIONPREFIX%InitializeSubmodel(XXDouble* u, XXDouble* y, XXDouble t);
void %FUNCTIONPREFIX%CalculateSubmodel(XXDouble* u, XXDouble* y, XXDouble t);
void %FUNCTIONPREFIX%TerminateSubmodel(XXDouble* u, XXDouble* y, XXDouble t);

/* Provided by the task (ccomm_main.c): applies --param overrides after the model
 * sets its own parameter values. */
void ccomm_xx_apply_parameters(void);

#endif
