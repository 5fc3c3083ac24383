/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Matrix helpers that 20-sim's generated equations call for models with matrices
 * (submodel %SUBMODEL_NAME%), written for the ccomm target against 20-sim's documented
 * interface: an XXMatrix points into the model's arrays (row-major, `mat[r * columns + c]`),
 * 20-sim sets the pointers and sizes in ModelInitialize (its INITIALIZE_MATRICES).
 *
 * Real-time rules: nothing allocates; functions that need scratch space take 20-sim's
 * `workarray` (%WORK_ARRAY_SIZE% doubles for this model, sized by 20-sim). Destination and
 * sources may be the same matrix. Sizes are not checked at run time: 20-sim checks them
 * when it generates the code.
 */
#ifndef XX_MATRIX_H
#define XX_MATRIX_H

#include "xxtypes.h"

/* Copies and element access (row/column numbers are 0-based, as 20-sim emits them). */
void XXMatrixMov(XXMatrix* mat_dest, XXMatrix* mat_source);
void XXMatrixScalarMov(XXMatrix* mat_dest, XXDouble s);
void XXMatrixGetRow(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger row);
void XXMatrixSetRow(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger row);
void XXMatrixGetColumn(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger column);
void XXMatrixSetColumn(XXMatrix* mat_dest, XXMatrix* mat_source, XXInteger column);
/* 1-based linear index s1 (or s2), as in the model text: M[i] = s2; dest = M[s2]. */
void XXMatrixMovRelAbs(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);
void XXMatrixMovAbsRel(XXDouble* dest, XXMatrix* mat_source1, XXDouble s2);
void XXMatrixDiag(XXMatrix* mat_dest, XXMatrix* mat_source);
void XXMatrixEye(XXMatrix* mat_dest);

/* Element-wise arithmetic; a scalar operand applies to every element. */
void XXMatrixAdd(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixScalarAdd(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2);
void XXScalarMatrixAdd(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2);
void XXScalarScalarAdd(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);
void XXMatrixSub(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixScalarSub(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2);
void XXScalarMatrixSub(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2);
void XXScalarScalarSub(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);
void XXMatrixScalarMul(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2);
void XXScalarMatrixMul(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2);
void XXScalarScalarMul(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);
void XXMatrixScalarDiv(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2);
void XXScalarScalarDiv(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);
void XXMatrixMulElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixDivElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixScalarPowElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2);
void XXMatrixPowElement(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixInv(XXMatrix* mat_dest, XXMatrix* mat_source); /* negation: -A */
void XXScalarScalarPow(XXMatrix* mat_dest, XXDouble s1, XXDouble s2);

/* Linear algebra. Products and transposes go through the workarray-free path only when
 * the destination is not a source; otherwise they use a static scratch of
 * XX_MATRIX_SCRATCH doubles (20-sim never emits an aliased product). */
void XXMatrixMul(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXScalarMatrixMatrixMul(XXDouble* dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixTranspose(XXMatrix* mat_dest, XXMatrix* mat_source);
/* Inverse by Gauss-Jordan elimination with partial pivoting; workarray >= 2 n^2 + n.
 * A singular matrix gives a matrix of NaN (the equations propagate it visibly). */
void XXMatrixInverse(XXMatrix* mat_dest, XXMatrix* mat_source, XXDouble* workarray);
/* A / B = A * inverse(B); workarray >= 3 n^2 + n (n: size of B). */
void XXMatrixDiv(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2, XXDouble* workarray);
void XXScalarMatrixDiv(XXMatrix* mat_dest, XXDouble s1, XXMatrix* mat_source2, XXDouble* workarray);
/* A^k for integer k (negative: inverse first); workarray >= 4 n^2 + n. */
void XXMatrixPow(XXMatrix* mat_dest, XXMatrix* mat_source1, XXDouble s2, XXDouble* workarray);
XXDouble XXMatrixDeterminant(XXMatrix* mat_source, XXDouble* workarray); /* >= n^2 */
/* Solves A x = b as x = inverse(A) b (20-sim's generated code does the same). */
void XXLinearSolve(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2,
                   XXString method, XXInteger id, XXDouble* workarray);

/* Reductions and vector products. */
void XXMatrixSum(XXDouble* dest, XXMatrix* mat_source);
void XXMatrixMinimum(XXDouble* dest, XXMatrix* mat_source);
void XXMatrixMaximum(XXDouble* dest, XXMatrix* mat_source);
XXDouble XXMatrixTrace(XXMatrix* mat_source);
void XXMatrixNorm(XXDouble* dest, XXMatrix* mat_source);    /* 2-norm of a vector */
void XXMatrixNormInf(XXDouble* dest, XXMatrix* mat_source); /* largest |element| */
void XXMatrixInnerProduct(XXDouble* dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixCrossProduct(XXMatrix* mat_dest, XXMatrix* mat_source1, XXMatrix* mat_source2);
void XXMatrixSkew(XXMatrix* mat_dest, XXMatrix* mat_source); /* 3x1 -> 3x3 */

#endif
