/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Checks the ccomm target's matrix helpers (the generated xxmatrix.c) against values
 * worked out by hand: inverse, division, determinant, power, linear solve, aliased
 * product and transpose, singular input, element access and reductions.
 * Build: cc -I<generated dir> matrix_check.c <generated dir>/xxmatrix.c -lm. Exit 0 if all pass.
 */
#include <math.h>
#include <stdio.h>

#include "xxmatrix.h"

static int failures = 0, checks = 0;

static void expect(const char* what, const XXDouble* got, const XXDouble* want, int n) {
  int i;
  checks++;
  for (i = 0; i < n; i++) {
    if (!(fabs(got[i] - want[i]) <= 1e-12 * (1.0 + fabs(want[i])))) {
      printf("FAIL %s: element %d is %.17g, expected %.17g\n", what, i, got[i], want[i]);
      failures++;
      return;
    }
  }
}

static XXMatrix view(XXDouble* m, int rows, int columns) {
  XXMatrix x;
  x.mat = m;
  x.rows = rows;
  x.columns = columns;
  return x;
}

int main(void) {
  XXDouble work[64];
  /* A = [2 1 0; 1 3 1; 0 1 4]: det 18, inverse (1/18)[11 -4 1; -4 8 -2; 1 -2 5]. */
  XXDouble a[9] = {2, 1, 0, 1, 3, 1, 0, 1, 4}, inv[9], prod[9], tmp[9];
  const XXDouble inv_want[9] = {11 / 18.0, -4 / 18.0, 1 / 18.0, -4 / 18.0, 8 / 18.0, -2 / 18.0,
                                1 / 18.0, -2 / 18.0, 5 / 18.0};
  const XXDouble eye[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  XXMatrix A = view(a, 3, 3), INV = view(inv, 3, 3), P = view(prod, 3, 3), T = view(tmp, 3, 3);
  XXMatrixInverse(&INV, &A, work);
  expect("inverse", inv, inv_want, 9);
  XXMatrixMul(&P, &A, &INV);
  expect("A * inverse(A)", prod, eye, 9);
  XXDouble det = XXMatrixDeterminant(&A, work), det_want = 18.0;
  expect("determinant", &det, &det_want, 1);
  XXMatrixDiv(&P, &A, &A, work); /* A / A = I */
  expect("A / A", prod, eye, 9);
  /* A^2 = [5 5 1; 5 11 7; 1 7 17]; A^-1 = inverse. */
  const XXDouble a2[9] = {5, 5, 1, 5, 11, 7, 1, 7, 17};
  XXMatrixPow(&P, &A, 2.0, work);
  expect("A^2", prod, a2, 9);
  XXMatrixPow(&P, &A, -1.0, work);
  expect("A^-1", prod, inv_want, 9);
  /* Solve A x = b for b = A [1 2 3]' = [4 10 14]'. */
  XXDouble b[3] = {4, 10, 14}, x[3];
  const XXDouble x_want[3] = {1, 2, 3};
  XXMatrix B = view(b, 3, 1), X = view(x, 3, 1);
  XXLinearSolve(&X, &A, &B, "", 0, work);
  expect("linear solve", x, x_want, 3);
  /* Aliased product (dest is a source) and in-place transpose. */
  XXMatrixMov(&T, &A);
  XXMatrixMul(&T, &T, &T);
  expect("aliased A * A", tmp, a2, 9);
  XXDouble r[6] = {1, 2, 3, 4, 5, 6}, rt[6];
  const XXDouble rt_want[6] = {1, 4, 2, 5, 3, 6};
  XXMatrix R = view(r, 2, 3), RT = view(rt, 3, 2);
  XXMatrixTranspose(&RT, &R);
  expect("transpose 2x3", rt, rt_want, 6);
  XXDouble sq[4] = {1, 2, 3, 4};
  const XXDouble sq_t[4] = {1, 3, 2, 4};
  XXMatrix SQ = view(sq, 2, 2);
  XXMatrixTranspose(&SQ, &SQ);
  expect("in-place transpose", sq, sq_t, 4);
  /* Singular: NaN, not a crash or garbage that looks valid. */
  XXDouble s[4] = {1, 2, 2, 4}, si[4];
  XXMatrix S = view(s, 2, 2), SI = view(si, 2, 2);
  XXMatrixInverse(&SI, &S, work);
  checks++;
  if (!(isnan(si[0]) && isnan(si[3]))) { printf("FAIL singular inverse: %g %g\n", si[0], si[3]); failures++; }
  /* Element access (1-based in the model text), rows, columns, diag, eye. */
  XXDouble v = 0.0, want = 6.0;
  XXMatrixMovAbsRel(&v, &R, 6.0);
  expect("M[6]", &v, &want, 1);
  XXMatrixMovRelAbs(&R, 2.0, -7.0);
  want = -7.0;
  expect("M[2] = -7", &r[1], &want, 1);
  XXDouble row[3], col[2];
  const XXDouble row_want[3] = {4, 5, 6}, col_want[2] = {3, 6};
  XXMatrix ROW = view(row, 1, 3), COL = view(col, 2, 1);
  XXMatrixGetRow(&ROW, &R, 1);
  expect("row 2", row, row_want, 3);
  XXMatrixGetColumn(&COL, &R, 2);
  expect("column 3", col, col_want, 2);
  XXDouble d[9];
  XXMatrix D = view(d, 3, 3), V3 = view(b, 3, 1);
  XXMatrixDiag(&D, &V3);
  const XXDouble d_want[9] = {4, 0, 0, 0, 10, 0, 0, 0, 14};
  expect("diag", d, d_want, 9);
  XXMatrixEye(&D);
  expect("eye", d, eye, 9);
  /* Reductions and vector products. */
  XXDouble sum, mn, mx, tr, nrm, ninf, ip;
  XXMatrixSum(&sum, &A);
  XXMatrixMinimum(&mn, &R);
  XXMatrixMaximum(&mx, &A);
  tr = XXMatrixTrace(&A);
  XXDouble u3[3] = {3, 0, -4}, w3[3] = {0, 1, 0}, c3[3], sk[9];
  XXMatrix U3 = view(u3, 3, 1), W3 = view(w3, 3, 1), C3 = view(c3, 3, 1), SK = view(sk, 3, 3);
  XXMatrixNorm(&nrm, &U3);
  XXMatrixNormInf(&ninf, &U3);
  XXMatrixInnerProduct(&ip, &U3, &B);
  const XXDouble red[7] = {sum, mn, mx, tr, nrm, ninf, ip};
  const XXDouble red_want[7] = {13, -7, 4, 9, 5, 4, 12 - 56};
  expect("sum, min, max, trace, norm, norm_inf, inner", red, red_want, 7);
  XXMatrixCrossProduct(&C3, &U3, &W3);
  const XXDouble c3_want[3] = {4, 0, 3};
  expect("cross", c3, c3_want, 3);
  XXMatrixSkew(&SK, &U3);
  XXMatrixMul(&C3, &SK, &W3); /* skew(u) * w = u x w */
  expect("skew(u) * w", c3, c3_want, 3);
  printf("%s matrix helpers: %d checks, %d failed\n", failures ? "FAIL" : "PASS", checks, failures);
  return failures ? 1 : 0;
}
