// SPDX-License-Identifier: Apache-2.0
// Test FMU (FMI 3.0): counts its steps on output "beat" until input "fault" asks it to fail:
// 1 doStep returns Error, 2 Discard, 3 asks to terminate, 4 dereferences NULL (SIGSEGV),
// 5 never returns (a hang). Output "big" is an Int64 past 2^53 (9007199254740992 + steps):
// a double cannot hold it, so --record shows whether ccomm-fmu keeps Int64 exact.
#include <stdlib.h>

#define MODEL_IDENTIFIER faulty3

#include "fmi3_trivial.h"

enum { VR_FAULT = 1, VR_BEAT = 2, VR_BIG = 3 };
typedef struct {
  int fault;
  double beat;
  long long big;
  fmi3LogMessageCallback log;
  fmi3InstanceEnvironment env;
} Faulty;

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                         fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,
                                         const fmi3ValueReference required[], size_t n_required,
                                         fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
                                         fmi3IntermediateUpdateCallback update) {
  (void)name; (void)token; (void)resources; (void)visible; (void)logging; (void)event_mode; (void)early_return;
  (void)required; (void)n_required; (void)update;
  Faulty* f = calloc(1, sizeof *f);
  f->log = log;
  f->env = env;
  f->big = 9007199254740992LL;  /* 2^53: every other value after it is not a double */
  return f;
}

fmi3Status fmi3DoStep(fmi3Instance i, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_set_prior, fmi3Boolean* event,
                      fmi3Boolean* terminate, fmi3Boolean* early, fmi3Float64* last) {
  Faulty* f = i;
  (void)no_set_prior;
  *event = *terminate = *early = fmi3False;
  *last = t + h;
  switch (f->fault) {
    case 1:
      f->log(f->env, fmi3Error, "logStatusError", "faulty3: the model failed on purpose");
      return fmi3Error;
    case 2: return fmi3Discard;
    case 3: *terminate = fmi3True; break;
    case 4: { volatile int* volatile nowhere = NULL; *nowhere = 1; break; }
    case 5: { volatile unsigned spin = 0; for (;;) spin = spin + 1; }
    default: break;
  }
  f->beat += 1;
  f->big += 1;
  return fmi3OK;
}
fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 v[], size_t nv) {
  if (nvr != 1 || nv != 1 || vr[0] != VR_BEAT) return fmi3Error;
  v[0] = ((Faulty*)i)->beat;
  return fmi3OK;
}
fmi3Status fmi3GetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Int32 v[], size_t nv) {
  if (nvr != 1 || nv != 1 || vr[0] != VR_FAULT) return fmi3Error;
  v[0] = ((Faulty*)i)->fault;
  return fmi3OK;
}
fmi3Status fmi3SetInt32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Int32 v[], size_t nv) {
  if (nvr != 1 || nv != 1 || vr[0] != VR_FAULT) return fmi3Error;
  ((Faulty*)i)->fault = v[0];
  return fmi3OK;
}
fmi3Status fmi3GetInt64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Int64 v[], size_t nv) {
  if (nvr != 1 || nv != 1 || vr[0] != VR_BIG) return fmi3Error;
  v[0] = ((Faulty*)i)->big;
  return fmi3OK;
}
