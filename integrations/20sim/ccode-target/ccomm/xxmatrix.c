/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Matrix helpers for submodel %SUBMODEL_NAME% (see xxmatrix.h). Row-major storage;
 * no allocation, no library calls other than <math.h>.
 */
#include <math.h>
#include <stddef.h>

#include "xxmatrix.h"

/* Aliased products/transposes (destination is also a source) go through this scratch. */
#define XX_MATRIX_SCRATCH 4096
static XXDouble xx_matrix_scratch[XX_MATRIX_SCRATCH];

static XXInteger xx_size(const XXMatrix* m) { return m->rows * m->columns; }

static void xx_fill(XXMatrix* d, XXDouble v) {
  XXInteger i, n = xx_size(d);
  for (i = 0; i < n; i++) d->mat[i] = v;
}

void XXMatrixMov(XXMatrix* mat_dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_dest);
  for (i = 0; i < n; i++) mat_dest->mat[i] = mat_source->mat[i];
}

void XXMatrixScalarMov(XXMatrix* mat_dest, XXDouble s) { xx_fill(mat_dest, s); }

void XXMatrixGetRow(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger row) {
  XXInteger c;
  for (c = 0; c < mat_source->columns; c++) mat_dest->mat[c] = mat_source->mat[row * mat_source->columns + c];
}

void XXMatrixSetRow(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger row) {
  XXInteger c;
  for (c = 0; c < mat_dest->columns; c++) mat_dest->mat[row * mat_dest->columns + c] = mat_source->mat[c];
}

void XXMatrixGetColumn(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger column) {
  XXInteger r;
  for (r = 0; r < mat_source->rows; r++) mat_dest->mat[r] = mat_source->mat[r * mat_source->columns + column];
}

void XXMatrixSetColumn(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger column) {
  XXInteger r;
  for (r = 0; r < mat_dest->rows; r++) mat_dest->mat[r * mat_dest->columns + column] = mat_source->mat[r];
}

/* The model text is 1-based; a computed index like 2.9999999 still means element 3. */
static XXInteger xx_index(XXDouble one_based) { return (XXInteger)floor(one_based + 0.5) - 1; }

void XXMatrixMovRelAbs(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { mat_dest->mat[xx_index(s1)] = s2; }

void XXMatrixMovAbsRel(XXDouble* dest, XXMatrix* mat_source1, XXDouble s2) { *dest = mat_source1->mat[xx_index(s2)]; }

void XXMatrixDiag(XXMatrix* mat_dest, XXMatrix* mat_source) {
  XXInteger i;
  xx_fill(mat_dest, 0.0);
  for (i = 0; i < mat_dest->rows && i < mat_dest->columns; i++) mat_dest->mat[i * mat_dest->columns + i] = mat_source->mat[i];
}

void XXMatrixEye(XXMatrix* mat_dest) {
  XXInteger i;
  xx_fill(mat_dest, 0.0);
  for (i = 0; i < mat_dest->rows && i < mat_dest->columns; i++) mat_dest->mat[i * mat_dest->columns + i] = 1.0;
}

/* ---------------------------------------------------------------- element-wise */

#define XX_ELEMENTWISE(expr)                      \
  XXInteger i, n = xx_size(mat_dest);             \
  for (i = 0; i < n; i++) mat_dest->mat[i] = (expr)

void XXMatrixAdd(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) { XX_ELEMENTWISE(mat_source1->mat[i] + mat_source2->mat[i]); }
void XXMatrixScalarAdd(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2) { XX_ELEMENTWISE(mat_source1->mat[i] + s2); }
void XXScalarMatrixAdd(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2) { XX_ELEMENTWISE(s1 + mat_source2->mat[i]); }
void XXScalarScalarAdd(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { XX_ELEMENTWISE(s1 + s2); }
void XXMatrixSub(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) { XX_ELEMENTWISE(mat_source1->mat[i] - mat_source2->mat[i]); }
void XXMatrixScalarSub(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2) { XX_ELEMENTWISE(mat_source1->mat[i] - s2); }
void XXScalarMatrixSub(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2) { XX_ELEMENTWISE(s1 - mat_source2->mat[i]); }
void XXScalarScalarSub(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { XX_ELEMENTWISE(s1 - s2); }
void XXMatrixScalarMul(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2) { XX_ELEMENTWISE(mat_source1->mat[i] * s2); }
void XXScalarMatrixMul(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2) { XX_ELEMENTWISE(s1 * mat_source2->mat[i]); }
void XXScalarScalarMul(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { XX_ELEMENTWISE(s1 * s2); }
void XXMatrixScalarDiv(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2) { XX_ELEMENTWISE(mat_source1->mat[i] / s2); }
void XXScalarScalarDiv(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { XX_ELEMENTWISE(s1 / s2); }
void XXMatrixMulElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) { XX_ELEMENTWISE(mat_source1->mat[i] * mat_source2->mat[i]); }
void XXMatrixDivElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) { XX_ELEMENTWISE(mat_source1->mat[i] / mat_source2->mat[i]); }
void XXMatrixScalarPowElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2) { XX_ELEMENTWISE(pow(mat_source1->mat[i], s2)); }
void XXMatrixPowElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) { XX_ELEMENTWISE(pow(mat_source1->mat[i], mat_source2->mat[i])); }
void XXMatrixInv(XXMatrix* mat_dest, XXMatrix* mat_source) { XX_ELEMENTWISE(-mat_source->mat[i]); }
void XXScalarScalarPow(XXMatrix* mat_dest, XXDouble s1, XXDouble s2) { XX_ELEMENTWISE(pow(s1, s2)); }

/* ---------------------------------------------------------------- linear algebra */

/* Where a result is built: the destination itself, or the scratch if it is a source. */
static XXDouble* xx_target(XXMatrix* d, const XXMatrix* a, const XXMatrix* b) {
  if (d->mat != a->mat && (b == NULL || d->mat != b->mat)) return d->mat;
  return xx_size(d) <= XX_MATRIX_SCRATCH ? xx_matrix_scratch : NULL;
}

static void xx_commit(XXMatrix* d, const XXDouble* built) {
  XXInteger i, n = xx_size(d);
  if (built == NULL) { xx_fill(d, NAN); return; }
  if (built != d->mat)
    for (i = 0; i < n; i++) d->mat[i] = built[i];
}

void XXMatrixMul(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) {
  XXInteger r, c, k, inner = mat_source1->columns;
  XXDouble* out = xx_target(mat_dest, mat_source1, mat_source2);
  if (out != NULL)
    for (r = 0; r < mat_dest->rows; r++)
      for (c = 0; c < mat_dest->columns; c++) {
        XXDouble sum = 0.0;
        for (k = 0; k < inner; k++) sum += mat_source1->mat[r * inner + k] * mat_source2->mat[k * mat_source2->columns + c];
        out[r * mat_dest->columns + c] = sum;
      }
  xx_commit(mat_dest, out);
}

void XXScalarMatrixMatrixMul(XXDouble* dest, XXMatrix* mat_source1, XXMatrix* mat_source2) {
  XXInteger k;
  XXDouble sum = 0.0;
  for (k = 0; k < mat_source1->columns; k++) sum += mat_source1->mat[k] * mat_source2->mat[k];
  *dest = sum;
}

void XXMatrixTranspose(XXMatrix* mat_dest, XXMatrix* mat_source) {
  XXInteger r, c;
  XXDouble* out = xx_target(mat_dest, mat_source, NULL);
  if (out != NULL)
    for (r = 0; r < mat_dest->rows; r++)
      for (c = 0; c < mat_dest->columns; c++) out[r * mat_dest->columns + c] = mat_source->mat[c * mat_source->columns + r];
  xx_commit(mat_dest, out);
}

/* Inverts the n x n matrix a into inv (both row-major, may not overlap), using the
 * n^2 + n doubles at work. Returns 0 if a is singular. */
static int xx_invert(XXDouble* inv, const XXDouble* a, XXInteger n, XXDouble* work) {
  XXDouble* m = work;         /* copy of a, reduced to the identity */
  XXInteger r, c, k;
  for (k = 0; k < n * n; k++) { m[k] = a[k]; inv[k] = 0.0; }
  for (k = 0; k < n; k++) inv[k * n + k] = 1.0;
  for (c = 0; c < n; c++) {
    XXInteger pivot = c;
    for (r = c + 1; r < n; r++)
      if (fabs(m[r * n + c]) > fabs(m[pivot * n + c])) pivot = r;
    if (m[pivot * n + c] == 0.0) return 0;
    if (pivot != c)
      for (k = 0; k < n; k++) {
        XXDouble t = m[c * n + k]; m[c * n + k] = m[pivot * n + k]; m[pivot * n + k] = t;
        t = inv[c * n + k]; inv[c * n + k] = inv[pivot * n + k]; inv[pivot * n + k] = t;
      }
    XXDouble p = m[c * n + c];
    for (k = 0; k < n; k++) { m[c * n + k] /= p; inv[c * n + k] /= p; }
    for (r = 0; r < n; r++) {
      XXDouble f = m[r * n + c];
      if (r == c || f == 0.0) continue;
      for (k = 0; k < n; k++) { m[r * n + k] -= f * m[c * n + k]; inv[r * n + k] -= f * inv[c * n + k]; }
    }
  }
  return 1;
}

void XXMatrixInverse(XXMatrix* mat_dest, XXMatrix* mat_source, XXDouble* workarray) {
  XXInteger n = mat_source->rows, k;
  XXDouble* inv = workarray + n * n + n;
  if (!xx_invert(inv, mat_source->mat, n, workarray)) { xx_fill(mat_dest, NAN); return; }
  for (k = 0; k < n * n; k++) mat_dest->mat[k] = inv[k];
}

void XXMatrixDiv(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2, XXDouble* workarray) {
  XXInteger n = mat_source2->rows;
  XXMatrix inv;
  inv.mat = workarray + 2 * n * n + n;
  inv.rows = n;
  inv.columns = n;
  XXMatrixInverse(&inv, mat_source2, workarray);
  XXMatrixMul(mat_dest, mat_source1, &inv);
}

void XXScalarMatrixDiv(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2, XXDouble* workarray) {
  XXMatrixInverse(mat_dest, mat_source2, workarray);
  XXMatrixScalarMul(mat_dest, mat_dest, s1);
}

void XXMatrixPow(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2, XXDouble* workarray) {
  XXInteger n = mat_source1->rows, k, e = (XXInteger)floor(fabs(s2) + 0.5);
  XXMatrix base, acc;
  base.rows = acc.rows = base.columns = acc.columns = n;
  base.mat = workarray + 2 * n * n + n; /* after XXMatrixInverse's scratch */
  acc.mat = base.mat + n * n;
  if (s2 < 0.0) XXMatrixInverse(&base, mat_source1, workarray);
  else XXMatrixMov(&base, mat_source1);
  XXMatrixEye(mat_dest);
  for (k = 0; k < e; k++) {
    XXMatrixMul(&acc, mat_dest, &base);
    XXMatrixMov(mat_dest, &acc);
  }
}

XXDouble XXMatrixDeterminant(XXMatrix* mat_source, XXDouble* workarray) {
  XXInteger n = mat_source->rows, r, c, k;
  XXDouble det = 1.0, *m = workarray;
  for (k = 0; k < n * n; k++) m[k] = mat_source->mat[k];
  for (c = 0; c < n; c++) {
    XXInteger pivot = c;
    for (r = c + 1; r < n; r++)
      if (fabs(m[r * n + c]) > fabs(m[pivot * n + c])) pivot = r;
    if (m[pivot * n + c] == 0.0) return 0.0;
    if (pivot != c) {
      det = -det;
      for (k = 0; k < n; k++) { XXDouble t = m[c * n + k]; m[c * n + k] = m[pivot * n + k]; m[pivot * n + k] = t; }
    }
    det *= m[c * n + c];
    for (r = c + 1; r < n; r++) {
      XXDouble f = m[r * n + c] / m[c * n + c];
      for (k = c; k < n; k++) m[r * n + k] -= f * m[c * n + k];
    }
  }
  return det;
}

void XXLinearSolve(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2,
                   XXString method, XXInteger id, XXDouble* workarray) {
  XXInteger n = mat_source1->rows;
  XXMatrix inv;
  (void)method; /* 20-sim's solver choice; generated code always uses the inverse */
  (void)id;
  inv.mat = workarray + 2 * n * n + n;
  inv.rows = n;
  inv.columns = n;
  XXMatrixInverse(&inv, mat_source1, workarray);
  XXMatrixMul(mat_dest, &inv, mat_source2);
}

/* ---------------------------------------------------------------- reductions */

void XXMatrixSum(XXDouble* dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_source);
  XXDouble s = 0.0;
  for (i = 0; i < n; i++) s += mat_source->mat[i];
  *dest = s;
}

void XXMatrixMinimum(XXDouble* dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_source);
  XXDouble v = mat_source->mat[0];
  for (i = 1; i < n; i++) if (mat_source->mat[i] < v) v = mat_source->mat[i];
  *dest = v;
}

void XXMatrixMaximum(XXDouble* dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_source);
  XXDouble v = mat_source->mat[0];
  for (i = 1; i < n; i++) if (mat_source->mat[i] > v) v = mat_source->mat[i];
  *dest = v;
}

XXDouble XXMatrixTrace(XXMatrix* mat_source) {
  XXInteger i;
  XXDouble s = 0.0;
  for (i = 0; i < mat_source->rows && i < mat_source->columns; i++) s += mat_source->mat[i * mat_source->columns + i];
  return s;
}

void XXMatrixNorm(XXDouble* dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_source);
  XXDouble s = 0.0;
  for (i = 0; i < n; i++) s += mat_source->mat[i] * mat_source->mat[i];
  *dest = sqrt(s);
}

void XXMatrixNormInf(XXDouble* dest, XXMatrix* mat_source) {
  XXInteger i, n = xx_size(mat_source);
  XXDouble v = 0.0;
  for (i = 0; i < n; i++) if (fabs(mat_source->mat[i]) > v) v = fabs(mat_source->mat[i]);
  *dest = v;
}

void XXMatrixInnerProduct(XXDouble* dest, XXMatrix* mat_source1, XXMatrix* mat_source2) {
  XXInteger i, n = xx_size(mat_source1);
  XXDouble s = 0.0;
  for (i = 0; i < n; i++) s += mat_source1->mat[i] * mat_source2->mat[i];
  *dest = s;
}

void XXMatrixCrossProduct(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2) {
  const XXDouble* a = mat_source1->mat;
  const XXDouble* b = mat_source2->mat;
  XXDouble x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
  mat_dest->mat[0] = x;
  mat_dest->mat[1] = y;
  mat_dest->mat[2] = z;
}

void XXMatrixSkew(XXMatrix* mat_dest, XXMatrix* mat_source) {
  XXDouble x = mat_source->mat[0], y = mat_source->mat[1], z = mat_source->mat[2];
  XXDouble* d = mat_dest->mat;
  d[0] = 0.0; d[1] = -z;  d[2] = y;
  d[3] = z;   d[4] = 0.0; d[5] = -x;
  d[6] = -y;  d[7] = x;   d[8] = 0.0;
}
