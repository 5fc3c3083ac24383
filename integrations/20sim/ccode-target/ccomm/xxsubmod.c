/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Submodel %SUBMODEL_NAME% of %MODEL_NAME%: initialize, step, terminate.
 * Input order: see ccomm_ports.c (20-sim's INPUT_NAMES order).
 */
#include "xxsubmod.h"
#include "xxinteg.h"
#include "xxmodel.h"

static void XXCopyInputsToVariables(XXDouble* u) {
  (void)u;
%INPUT_TO_VARIABLE_EQUATIONS%
}

static void XXCopyVariablesToOutputs(XXDouble* y) {
  (void)y;
%VARIABLE_TO_OUTPUT_EQUATIONS%
}

void %FUNCTIONPREFIX%InitializeSubmodel(XXDouble* u, XXDouble* y, XXDouble t) {
  %VARPREFIX%%XX_TIME% = t;
  %VARPREFIX%step_size = %TIME_STEP_SIZE%;
  %VARPREFIX%%XX_INITIALIZE% = XXTRUE;
  %VARPREFIX%major = XXTRUE;
  %VARPREFIX%stop_simulation = XXFALSE;
  %FUNCTIONPREFIX%ModelInitialize();
  /* Parameter values given to the task override the model's (ccomm_main.c). */
  ccomm_xx_apply_parameters();
  XXCopyInputsToVariables(u);
  %FUNCTIONPREFIX%CalculateInitial();
  %FUNCTIONPREFIX%CalculateStatic();
  %FUNCTIONPREFIX%CalculateInput();
  %FUNCTIONPREFIX%CalculateDynamic();
  %FUNCTIONPREFIX%CalculateOutput();
  XXCopyVariablesToOutputs(y);
  %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Initialize();
  %VARPREFIX%%XX_INITIALIZE% = XXFALSE;
}

/* One period: y = outputs after advancing the model from t to t + step with inputs u. */
void %FUNCTIONPREFIX%CalculateSubmodel(XXDouble* u, XXDouble* y, XXDouble t) {
  %VARPREFIX%%XX_TIME% = t;
  XXCopyInputsToVariables(u);
  /* Parameters may have been changed between steps (runner --param or a monitor). */
  %FUNCTIONPREFIX%CalculateStatic();
  %FUNCTIONPREFIX%CalculateInput();
  /* Rates for the current inputs before integrating (inputs changed since last step). */
  %FUNCTIONPREFIX%CalculateDynamic();
  %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Step();
  %FUNCTIONPREFIX%CalculateOutput();
  XXCopyVariablesToOutputs(y);
}

void %FUNCTIONPREFIX%TerminateSubmodel(XXDouble* u, XXDouble* y, XXDouble t) {
  %VARPREFIX%%XX_TIME% = t;
  XXCopyInputsToVariables(u);
  %FUNCTIONPREFIX%CalculateFinal();
  XXCopyVariablesToOutputs(y);
  %FUNCTIONPREFIX%%INTEGRATION_METHOD_NAME%Terminate();
  %FUNCTIONPREFIX%ModelTerminate();
}
