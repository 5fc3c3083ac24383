// SPDX-License-Identifier: Apache-2.0
// Test FMU (FMI 2.0 co-simulation): a discrete PI controller with output saturation, a
// tunable gain, an Integer tick counter and a Boolean "saturated" output.
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

enum { VR_SETPOINT = 0, VR_MEASUREMENT = 1, VR_KP = 2, VR_KI = 3, VR_COMMAND = 4, VR_LIMIT = 5 };
enum { VR_TICKS = 0 };      /* Integer */
enum { VR_SATURATED = 0 };  /* Boolean */
typedef struct {
  double r[6];
  double integral;
  int ticks, saturated;
  fmi2CallbackFunctions cb;
} Controller;

const char* fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char* fmi2GetVersion(void) { return fmi2Version; }
fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions* cb, fmi2Boolean visible, fmi2Boolean logging) {
  (void)resources; (void)visible; (void)logging;
  if (type != fmi2CoSimulation || strcmp(guid, "{5b0c6f1e-8e0a-4c57-9d1e-2f6c2b0a7e21}") != 0) {
    if (cb && cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "logStatusError", "wrong guid or type");
    return NULL;
  }
  Controller* c = calloc(1, sizeof *c);
  c->cb = *cb;
  c->r[VR_KP] = 2.0;
  c->r[VR_KI] = 5.0;
  c->r[VR_LIMIT] = 3.0;
  return c;
}
void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean a, fmi2Real b, fmi2Real t, fmi2Boolean d, fmi2Real e) {
  (void)c; (void)a; (void)b; (void)t; (void)d; (void)e;
  return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { (void)c; return fmi2Error; }

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean no_set_prior) {
  Controller* c = comp;
  (void)t; (void)no_set_prior;
  const double e = c->r[VR_SETPOINT] - c->r[VR_MEASUREMENT];
  double u = c->r[VR_KP] * e + c->integral + c->r[VR_KI] * h * e;
  c->saturated = u > c->r[VR_LIMIT] || u < -c->r[VR_LIMIT];
  if (!c->saturated) c->integral += c->r[VR_KI] * h * e;  /* anti-windup: hold while saturated */
  if (u > c->r[VR_LIMIT]) u = c->r[VR_LIMIT];
  if (u < -c->r[VR_LIMIT]) u = -c->r[VR_LIMIT];
  c->r[VR_COMMAND] = u;
  c->ticks++;
  return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
  Controller* c = comp;
  for (size_t i = 0; i < n; ++i) {
    if (vr[i] > VR_LIMIT) return fmi2Error;
    v[i] = c->r[vr[i]];
  }
  return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
  Controller* c = comp;
  for (size_t i = 0; i < n; ++i) {
    if (vr[i] == VR_COMMAND || vr[i] > VR_LIMIT) return fmi2Error;
    c->r[vr[i]] = v[i];
  }
  return fmi2OK;
}
fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
  Controller* c = comp;
  for (size_t i = 0; i < n; ++i) {
    if (vr[i] != VR_TICKS) return fmi2Error;
    v[i] = c->ticks;
  }
  return fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
  Controller* c = comp;
  for (size_t i = 0; i < n; ++i) {
    if (vr[i] != VR_SATURATED) return fmi2Error;
    v[i] = c->saturated;
  }
  return fmi2OK;
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean* v) {
  (void)c; (void)s;
  *v = fmi2False;
  return fmi2OK;
}
