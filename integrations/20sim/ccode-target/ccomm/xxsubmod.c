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

/* 20-sim's submodel protocol, which every generated target follows so that the code
 * computes the sample sequence 20-sim's simulator computes:
 *   initialize: initial, static, input, dynamic, output equations once at t0, so the
 *               first outputs and the rates of the first step exist;
 *   each step:  inputs -> input equations -> integration step (advances the states with
 *               the rates evaluated at the end of the previous step, then evaluates the
 *               dynamic equations at the new time with this step's inputs) -> output
 *               equations -> outputs.
 * The rates of a step are those of the previous sample: evaluating the dynamic equations
 * again before the step would integrate this step's inputs one sample early. */
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

/* One period: y = outputs at t + step, after advancing the model from t with inputs u. */
void %FUNCTIONPREFIX%CalculateSubmodel(XXDouble* u, XXDouble* y, XXDouble t) {
  %VARPREFIX%%XX_TIME% = t;
  XXCopyInputsToVariables(u);
  /* Static equations depend on parameters only: recomputing them each step is what
   * 20-sim does after a parameter change and changes nothing otherwise. */
  %FUNCTIONPREFIX%CalculateStatic();
  %FUNCTIONPREFIX%CalculateInput();
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
