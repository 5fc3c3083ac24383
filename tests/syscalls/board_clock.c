/* SPDX-License-Identifier: Apache-2.0 */
/*
 * board_clock.so (LD_PRELOAD): every clock_gettime() becomes a real system call, as on
 * a board whose kernel has no vDSO clock. 32-bit ARM Linux serves clock_gettime from
 * the vDSO only with the ARMv7 architected timer (arch/arm/kernel/vdso.c removes
 * __vdso_clock_gettime otherwise); the RaMstix's Cortex-A8 (OMAP3) has none, so there
 * each clock reading enters the kernel. syscount --board-clock runs under it and counts
 * those readings as the syscalls they are on the board.
 */
#define _GNU_SOURCE
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

int clock_gettime(clockid_t clock, struct timespec* ts) { return (int)syscall(SYS_clock_gettime, clock, ts); }
