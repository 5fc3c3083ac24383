// SPDX-License-Identifier: Apache-2.0
// Test FMU (FMI 3.0 co-simulation): a mass on a spring and damper, integrated with SUBSTEPS
// (buildDescription.xml: 10) semi-implicit Euler sub-steps per doStep. Scalar and array inputs, a Boolean input fed
// by a freshness mapping, a tunable parameter, scalar and array outputs. The array input w is
// Float32: FMPy's input table needs one shape per type, and it covers a second type.
#include <stdlib.h>
#include <string.h>

#define MODEL_IDENTIFIER plant3
#include "fmi3_trivial.h"

#ifndef SUBSTEPS
#error "SUBSTEPS comes from sources/buildDescription.xml (a PreprocessorDefinition)"
#endif

enum { VR_U = 1, VR_U_FRESH = 2, VR_W = 3, VR_K = 4, VR_X = 5, VR_STATE = 6, VR_C = 7 };
typedef struct {
  double u, k, c, x, v;
  float w[2];
  fmi3Boolean u_fresh;
} Plant;

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                         fmi3Boolean logging, fmi3Boolean event_mode, fmi3Boolean early_return,
                                         const fmi3ValueReference required[], size_t n_required,
                                         fmi3InstanceEnvironment env, fmi3LogMessageCallback log,
                                         fmi3IntermediateUpdateCallback update) {
  (void)name; (void)resources; (void)visible; (void)logging; (void)event_mode; (void)early_return;
  (void)required; (void)n_required; (void)update;
  if (strcmp(token, "{8c4e810f-3df3-4a00-8276-176fa3c9f000}") != 0) {
    if (log) log(env, fmi3Error, "logStatusError", "wrong instantiation token");
    return NULL;
  }
  Plant* p = calloc(1, sizeof *p);
  p->k = 40.0;
  p->c = 0.8;
  p->x = 0.1;
  p->u_fresh = fmi3True;
  return p;
}
fmi3Status fmi3Reset(fmi3Instance i) { (void)i; return fmi3Error; }

fmi3Status fmi3DoStep(fmi3Instance i, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_set_prior, fmi3Boolean* event,
                      fmi3Boolean* terminate, fmi3Boolean* early, fmi3Float64* last) {
  Plant* p = i;
  (void)no_set_prior;
  const double dt = h / SUBSTEPS;
  const double f = (p->u_fresh ? p->u : 0.0) + p->w[0];
  for (int n = 0; n < SUBSTEPS; ++n) {
    const double a = f - p->k * p->x - (p->c + p->w[1]) * p->v;  // unit mass
    p->v += a * dt;
    p->x += p->v * dt;
  }
  *event = fmi3False;
  *terminate = fmi3False;
  *early = fmi3False;
  *last = t + h;
  return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Float64 v[], size_t nv) {
  Plant* p = i;
  size_t k = 0;
  for (size_t n = 0; n < nvr; ++n) {
    switch (vr[n]) {
      case VR_U: if (k + 1 > nv) return fmi3Error; v[k++] = p->u; break;
      case VR_K: if (k + 1 > nv) return fmi3Error; v[k++] = p->k; break;
      case VR_C: if (k + 1 > nv) return fmi3Error; v[k++] = p->c; break;
      case VR_X: if (k + 1 > nv) return fmi3Error; v[k++] = p->x; break;
      case VR_STATE: if (k + 2 > nv) return fmi3Error; v[k++] = p->x; v[k++] = p->v; break;
      default: return fmi3Error;
    }
  }
  return k == nv ? fmi3OK : fmi3Error;
}
fmi3Status fmi3SetFloat64(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Float64 v[],
                          size_t nv) {
  Plant* p = i;
  size_t k = 0;
  for (size_t n = 0; n < nvr; ++n) {
    switch (vr[n]) {
      case VR_U: if (k + 1 > nv) return fmi3Error; p->u = v[k++]; break;
      case VR_K: if (k + 1 > nv) return fmi3Error; p->k = v[k++]; break;
      case VR_C: if (k + 1 > nv) return fmi3Error; p->c = v[k++]; break;
      default: return fmi3Error;
    }
  }
  return k == nv ? fmi3OK : fmi3Error;
}
fmi3Status fmi3GetFloat32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Float32 v[], size_t nv) {
  Plant* p = i;
  if (nvr != 1 || nv != 2 || vr[0] != VR_W) return fmi3Error;
  v[0] = p->w[0];
  v[1] = p->w[1];
  return fmi3OK;
}
fmi3Status fmi3SetFloat32(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Float32 v[],
                          size_t nv) {
  Plant* p = i;
  if (nvr != 1 || nv != 2 || vr[0] != VR_W) return fmi3Error;
  p->w[0] = v[0];
  p->w[1] = v[1];
  return fmi3OK;
}
fmi3Status fmi3GetBoolean(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, fmi3Boolean v[], size_t nv) {
  Plant* p = i;
  if (nvr != 1 || nv != 1 || vr[0] != VR_U_FRESH) return fmi3Error;
  v[0] = p->u_fresh;
  return fmi3OK;
}
fmi3Status fmi3SetBoolean(fmi3Instance i, const fmi3ValueReference vr[], size_t nvr, const fmi3Boolean v[], size_t nv) {
  Plant* p = i;
  if (nvr != 1 || nv != 1 || vr[0] != VR_U_FRESH) return fmi3Error;
  p->u_fresh = v[0];
  return fmi3OK;
}
