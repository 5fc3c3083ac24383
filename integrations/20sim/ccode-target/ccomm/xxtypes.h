/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Basic types of the code 20-sim generates for the ccomm target.
 * Generated for submodel %SUBMODEL_NAME% of model %MODEL_NAME% (%GENERATION_DATE% %GENERATION_TIME%).
 *
 * 20-sim computes in 64-bit doubles; the equations it emits use these names.
 */
#ifndef XX_TYPES_H
#define XX_TYPES_H

typedef double XXDouble;
typedef int XXInteger;
typedef char XXCharacter;
typedef char XXBoolean;
typedef const char* XXString;

/* A matrix: a row-major view into the model arrays (mat[row * columns + column]);
 * 20-sim sets mat, rows and columns in ModelInitialize. Helpers: xxmatrix.h. */
typedef struct {
  XXDouble* mat;
  XXInteger rows;
  XXInteger columns;
} XXMatrix;

#define XXTRUE 1
#define XXFALSE 0

#endif
