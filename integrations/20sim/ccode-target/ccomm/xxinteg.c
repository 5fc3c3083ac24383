/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Fixed-step integration for submodel %SUBMODEL_NAME% (method %INTEGRATION_METHOD_NAME%),
 * the methods of 20-sim's simulator as its documentation defines them. Each step starts
 * from the rates the dynamic equations left at the end of the previous step (or at
 * initialization), advances states and time by one step, and ends by evaluating the
 * dynamic equations at the new time (major step), which gives the next step's rates.
 * Only the chosen method is generated; scratch arrays are static (no allocation).
 */
#include "xxinteg.h"
#include "xxmodel.h"

#define XX_NSTATES %NUMBER_STATES%
#define XX_S %VARPREFIX%%XX_STATE_ARRAY_NAME%
#define XX_R %VARPREFIX%%XX_RATE_ARRAY_NAME%
#define XX_T %VARPREFIX%%XX_TIME%
#define XX_H %VARPREFIX%step_size

%IF%%EQ(INTEGRATION_METHOD_NAME,Discrete)%
/* Discrete models: the dynamic equations compute the next value of each state. */
void %FUNCTIONPREFIX%DiscreteInitialize(void) {}
void %FUNCTIONPREFIX%DiscreteTerminate(void) {}
void %FUNCTIONPREFIX%DiscreteStep(void) {
  int i;
  for (i = 0; i < XX_NSTATES; i++) XX_S[i] = XX_R[i];
  XX_T += XX_H;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}
%ENDIF%
%IF%%EQ(INTEGRATION_METHOD_NAME,Euler)%
/* Forward Euler: x(t + h) = x(t) + h f(x(t), t). */
void %FUNCTIONPREFIX%EulerInitialize(void) {}
void %FUNCTIONPREFIX%EulerTerminate(void) {}
void %FUNCTIONPREFIX%EulerStep(void) {
  int i;
  for (i = 0; i < XX_NSTATES; i++) XX_S[i] = XX_S[i] + XX_R[i] * XX_H;
  XX_T += XX_H;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}
%ENDIF%
%IF%%EQ(INTEGRATION_METHOD_NAME,RungeKutta2)%
/* Midpoint rule: k1 = f(x, t); x(t + h) = x + h f(x + h/2 k1, t + h/2). */
static XXDouble xx_x0[XX_NSTATES + 1];

void %FUNCTIONPREFIX%RungeKutta2Initialize(void) {}
void %FUNCTIONPREFIX%RungeKutta2Terminate(void) {}
void %FUNCTIONPREFIX%RungeKutta2Step(void) {
  int i;
  const XXDouble t0 = XX_T;
  for (i = 0; i < XX_NSTATES; i++) {
    xx_x0[i] = XX_S[i];
    XX_S[i] = xx_x0[i] + XX_R[i] * 0.5 * XX_H;
  }
  XX_T = t0 + 0.5 * XX_H;
  %VARPREFIX%major = XXFALSE; /* minor step: delay()/event functions keep their values */
  %FUNCTIONPREFIX%CalculateDynamic();
  for (i = 0; i < XX_NSTATES; i++) XX_S[i] = xx_x0[i] + XX_R[i] * XX_H;
  XX_T = t0 + XX_H;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}
%ENDIF%
%IF%%EQ(INTEGRATION_METHOD_NAME,RungeKutta4)%
/* Classic Runge-Kutta: increments q1..q4 = h f(.) at t, t + h/2, t + h/2, t + h;
 * x(t + h) = x + (q1 + 2 q2 + 2 q3 + q4) / 6. */
static XXDouble xx_x0[XX_NSTATES + 1];
static XXDouble xx_q[4][XX_NSTATES + 1];

void %FUNCTIONPREFIX%RungeKutta4Initialize(void) {}
void %FUNCTIONPREFIX%RungeKutta4Terminate(void) {}
void %FUNCTIONPREFIX%RungeKutta4Step(void) {
  int i, stage;
  /* Where stage k+1 evaluates f: fraction of q_k added to x0, fraction of h added to t. */
  static const XXDouble along[3] = {0.5, 0.5, 1.0};
  const XXDouble t0 = XX_T;
  for (i = 0; i < XX_NSTATES; i++) {
    xx_x0[i] = XX_S[i];
    xx_q[0][i] = XX_R[i] * XX_H;
  }
  %VARPREFIX%major = XXFALSE;
  for (stage = 0; stage < 3; stage++) {
    for (i = 0; i < XX_NSTATES; i++) XX_S[i] = xx_x0[i] + xx_q[stage][i] * along[stage];
    XX_T = t0 + along[stage] * XX_H;
    %FUNCTIONPREFIX%CalculateDynamic();
    for (i = 0; i < XX_NSTATES; i++) xx_q[stage + 1][i] = XX_R[i] * XX_H;
  }
  for (i = 0; i < XX_NSTATES; i++)
    XX_S[i] = xx_x0[i] + (xx_q[0][i] + 2.0 * xx_q[1][i] + 2.0 * xx_q[2][i] + xx_q[3][i]) / 6.0;
  XX_T = t0 + XX_H;
  %VARPREFIX%major = XXTRUE;
  %FUNCTIONPREFIX%CalculateDynamic();
}
%ENDIF%
%IF%%NOT(OR(EQ(INTEGRATION_METHOD_NAME,Discrete),EQ(INTEGRATION_METHOD_NAME,Euler),EQ(INTEGRATION_METHOD_NAME,RungeKutta2),EQ(INTEGRATION_METHOD_NAME,RungeKutta4)))%
#error "ccomm target: integration method %INTEGRATION_METHOD_NAME% is not supported (use Discrete, Euler, RungeKutta2 or RungeKutta4)"
%ENDIF%
