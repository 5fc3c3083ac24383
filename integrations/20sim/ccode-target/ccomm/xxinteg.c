/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Fixed-step integration for submodel %SUBMODEL_NAME% (method %INTEGRATION_METHOD_NAME%).
 * Only the chosen method is compiled (xxmodel.h defines <method>_METHOD). Scratch arrays
 * are static: no allocation while the task runs.
 */
#include "xxinteg.h"
#include "xxmodel.h"

#define XX_NSTATES %NUMBER_STATES%

#if defined(Discrete_METHOD)
/* Discrete models: the "rates" are the next values of the states. */
void %FUNCTIONPREFIX%DiscreteInitialize(void) {}
void %FUNCTIONPREFIX%DiscreteTerminate(void) {}
void %FUNCTIONPREFIX%DiscreteStep(void) {
  int i;
  for (i = 0; i < XX_NSTATES; i++) %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] = %VARPREFIX%%XX_RATE_ARRAY_NAME%[i];
  %VARPREFIX%%XX_TIME% += %VARPREFIX%step_size;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}

#elif defined(Euler_METHOD)
void %FUNCTIONPREFIX%EulerInitialize(void) {}
void %FUNCTIONPREFIX%EulerTerminate(void) {}
void %FUNCTIONPREFIX%EulerStep(void) {
  int i;
  for (i = 0; i < XX_NSTATES; i++)
    %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] += %VARPREFIX%%XX_RATE_ARRAY_NAME%[i] * %VARPREFIX%step_size;
  %VARPREFIX%%XX_TIME% += %VARPREFIX%step_size;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}

#elif defined(RungeKutta2_METHOD)
static XXDouble xx_q0[XX_NSTATES + 1];

void %FUNCTIONPREFIX%RungeKutta2Initialize(void) {}
void %FUNCTIONPREFIX%RungeKutta2Terminate(void) {}
/* Midpoint rule: rates at the start, then at half a step. */
void %FUNCTIONPREFIX%RungeKutta2Step(void) {
  int i;
  XXDouble h = %VARPREFIX%step_size;
  XXDouble t0 = %VARPREFIX%%XX_TIME%;
  for (i = 0; i < XX_NSTATES; i++) {
    xx_q0[i] = %VARPREFIX%%XX_STATE_ARRAY_NAME%[i];
    %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] = xx_q0[i] + 0.5 * h * %VARPREFIX%%XX_RATE_ARRAY_NAME%[i];
  }
  %VARPREFIX%major = XXFALSE;
  %VARPREFIX%%XX_TIME% = t0 + 0.5 * h;
  %FUNCTIONPREFIX%CalculateDynamic();
  for (i = 0; i < XX_NSTATES; i++)
    %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] = xx_q0[i] + h * %VARPREFIX%%XX_RATE_ARRAY_NAME%[i];
  %VARPREFIX%%XX_TIME% = t0 + h;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}

#elif defined(RungeKutta4_METHOD)
static XXDouble xx_q0[XX_NSTATES + 1];
static XXDouble xx_k[4][XX_NSTATES + 1];

void %FUNCTIONPREFIX%RungeKutta4Initialize(void) {}
void %FUNCTIONPREFIX%RungeKutta4Terminate(void) {}
void %FUNCTIONPREFIX%RungeKutta4Step(void) {
  int i, stage;
  static const XXDouble frac[3] = {0.5, 0.5, 1.0};
  XXDouble h = %VARPREFIX%step_size;
  XXDouble t0 = %VARPREFIX%%XX_TIME%;
  for (i = 0; i < XX_NSTATES; i++) {
    xx_q0[i] = %VARPREFIX%%XX_STATE_ARRAY_NAME%[i];
    xx_k[0][i] = %VARPREFIX%%XX_RATE_ARRAY_NAME%[i];
  }
  %VARPREFIX%major = XXFALSE;
  for (stage = 0; stage < 3; stage++) {
    for (i = 0; i < XX_NSTATES; i++)
      %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] = xx_q0[i] + frac[stage] * h * xx_k[stage][i];
    %VARPREFIX%%XX_TIME% = t0 + frac[stage] * h;
    %FUNCTIONPREFIX%CalculateDynamic();
    for (i = 0; i < XX_NSTATES; i++) xx_k[stage + 1][i] = %VARPREFIX%%XX_RATE_ARRAY_NAME%[i];
  }
  for (i = 0; i < XX_NSTATES; i++)
    %VARPREFIX%%XX_STATE_ARRAY_NAME%[i] =
        xx_q0[i] + h / 6.0 * (xx_k[0][i] + 2.0 * xx_k[1][i] + 2.0 * xx_k[2][i] + xx_k[3][i]);
  %VARPREFIX%%XX_TIME% = t0 + h;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}

#else
#error "ccomm target: integration method %INTEGRATION_METHOD_NAME% is not supported (use Discrete, Euler, RungeKutta2 or RungeKutta4)"
#endif
