/* SPDX-License-Identifier: Apache-2.0 */
/*
 * Functions the 20-sim code generator calls from model equations (the names are the
 * ones 20-sim emits). Implemented in xxfuncs.c for the ccomm target. Functions that
 * need files, tables or the 20-sim GUI (data(), table(), warnings) are not provided:
 * a model that uses them fails to link, which names the missing function.
 */
#ifndef XX_FUNCS_H
#define XX_FUNCS_H

#include "xxtypes.h"

XXDouble XXAbsolute(XXDouble argument);
XXDouble XXArcCosineHyperbolic(XXDouble argument);
XXDouble XXArcSineHyperbolic(XXDouble argument);
XXDouble XXArcTangentHyperbolic(XXDouble argument);
XXDouble XXExponent2(XXDouble argument);
XXDouble XXExponent10(XXDouble argument);
XXDouble XXIntegerDivide(XXDouble argument1, XXDouble argument2);
XXDouble XXIntegerModulo(XXDouble argument1, XXDouble argument2);
XXDouble XXLogarithm2(XXDouble argument);
XXDouble XXLogarithm10(XXDouble argument);
XXDouble XXPow2(XXDouble argument);
XXDouble XXPower(XXDouble argument1, XXDouble argument2);
XXDouble XXRandom(XXDouble argument);
XXDouble XXRamp(XXDouble argument, XXDouble time);
XXDouble XXRound(XXDouble argument);
XXDouble XXSign(XXDouble argument);
XXDouble XXStep(XXDouble argument, XXDouble time);
XXDouble XXImpulse(XXDouble impulsestarttime, XXDouble impulseduration, XXDouble currenttime,
                   XXDouble stepsize);
XXDouble XXXor(XXDouble argument1, XXDouble argument2);

XXInteger XXBitAnd(XXInteger argument1, XXInteger argument2);
XXInteger XXBitOr(XXInteger argument1, XXInteger argument2);
XXInteger XXBitXor(XXInteger argument1, XXInteger argument2);
XXInteger XXBitCmp(XXInteger argument, XXInteger nrBits);
XXInteger XXBitGet(XXInteger argument, XXInteger bitPos);
XXInteger XXBitInv(XXInteger argument);
XXInteger XXBitSet(XXInteger argument, XXInteger bitPos);
XXInteger XXBitClear(XXInteger argument, XXInteger bitPos);
XXInteger XXBitShift(XXInteger argument, XXInteger bitsToShift);
XXInteger XXBitShiftRight(XXInteger argument, XXInteger bitsToShift);
XXInteger XXSwapBytes(XXInteger argument);

/* Wall-clock seconds since the task started (20-sim realtime()). */
XXDouble XXRealTime(void);

#endif
