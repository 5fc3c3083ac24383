// SPDX-License-Identifier: Apache-2.0
// The FMI 3.0 functions a test FMU (plant3, faulty3) has nothing of its own to do in:
// the version, freeing the calloc'ed instance, initialization mode and terminate.
// Included once, by the model's .c file; tests/fmu/common.sh packs it into sources/
// beside it, and gen_unsupported.py sees the definitions through the #include.
#ifndef CCOMM_TEST_FMI3_TRIVIAL_H
#define CCOMM_TEST_FMI3_TRIVIAL_H

#include <stdlib.h>

// As the Reference-FMUs' sources do: the functions carry the model's prefix
// (MODEL_IDENTIFIER_fmi3DoStep), as a source FMU compiled with other code needs, unless
// the importer builds a shared library and says so with FMI3_OVERRIDE_FUNCTION_PREFIX
// (FMI 3.0, source code FMUs). ccomm-fmu build must define it, or run finds no fmi3DoStep.
#ifndef MODEL_IDENTIFIER
#error "the model's .c defines MODEL_IDENTIFIER before including fmi3_trivial.h"
#endif
#ifndef FMI3_OVERRIDE_FUNCTION_PREFIX
#define FMI3_PASTE_(a, b) a##b
#define FMI3_PASTE(a, b) FMI3_PASTE_(a, b)
#define FMI3_FUNCTION_PREFIX FMI3_PASTE(MODEL_IDENTIFIER, _)
#endif
#include "fmi3Functions.h"

const char* fmi3GetVersion(void) { return fmi3Version; }
void fmi3FreeInstance(fmi3Instance i) { free(i); }
fmi3Status fmi3EnterInitializationMode(fmi3Instance i, fmi3Boolean a, fmi3Float64 b, fmi3Float64 c, fmi3Boolean d,
                                       fmi3Float64 e) {
  (void)i; (void)a; (void)b; (void)c; (void)d; (void)e;
  return fmi3OK;
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance i) { (void)i; return fmi3OK; }
fmi3Status fmi3Terminate(fmi3Instance i) { (void)i; return fmi3OK; }

#endif
