/* SPDX-License-Identifier: Apache-2.0 */
/* consumer reader|writer: two processes on one node through ccomm.dll (tests/windows/run).
   The writer writes joint_torque_sp[0] = 1..N, one value every 2 ms. The reader first
   finds the signal never written, then sleeps in ccomm_wait (the doorbell across
   processes) until it has read N, then finds it stale once the writer stopped (the
   signal's stale_after_ms is 5). Exit 0 when every check holds. */
#include <ccomm/ccomm.h>
#include <stdio.h>
#include <string.h>
#include <windows.h>

enum { kValues = 200, kCount = 6 };

static int fail(const char* what, int code) {
  fprintf(stderr, "consumer: FAIL: %s: %s\n", what, ccomm_strerror(code));
  return 1;
}

int main(int argc, char** argv) {
  ccomm_client* c = NULL;
  if (argc != 2) return 2;
  int r = ccomm_open("robot", 0, &c);
  if (r != 0) return fail("ccomm_open(robot)", r);
  ccomm_signal s = ccomm_find(c, "joint_torque_sp");
  if (s < 0) return fail("ccomm_find(joint_torque_sp)", s);
  double v[kCount];
  ccomm_info info;
  if (strcmp(argv[1], "writer") == 0) {
    for (int k = 1; k <= kValues; ++k) {
      for (int j = 0; j < kCount; ++j) v[j] = k + j / 10.0;
      if ((r = ccomm_write(c, s, v, sizeof v)) != 0) return fail("ccomm_write", r);
      Sleep(2);
    }
    printf("writer: wrote %d values\n", kValues);
    ccomm_close(c);
    return 0;
  }
  r = ccomm_read(c, s, v, sizeof v, &info);
  if (r != CCOMM_NEVER) {
    fprintf(stderr, "consumer: FAIL: first read %d, want CCOMM_NEVER\n", r);
    return 1;
  }
  printf("reader: ready\n");
  fflush(stdout);
  int wakes = 0, last = 0;
  const ULONGLONG deadline = GetTickCount64() + 60000;
  while (last < kValues && GetTickCount64() < deadline) {
    if (ccomm_wait(c, 1000) > 0) ++wakes;
    r = ccomm_read(c, s, v, sizeof v, &info);
    if (r == CCOMM_FRESH) {
      if ((int)v[0] < last) {
        fprintf(stderr, "consumer: FAIL: read %g after %d\n", v[0], last);
        return 1;
      }
      if (v[5] != v[0] + 0.5) {
        fprintf(stderr, "consumer: FAIL: torn value %g / %g\n", v[0], v[5]);
        return 1;
      }
      last = (int)v[0];
    }
  }
  if (last != kValues) {
    fprintf(stderr, "consumer: FAIL: last value read %d, want %d\n", last, kValues);
    return 1;
  }
  Sleep(50); /* stale_after_ms is 5 */
  r = ccomm_read(c, s, v, sizeof v, &info);
  if (r != CCOMM_STALE) {
    fprintf(stderr, "consumer: FAIL: read %d 50 ms after the last write, want CCOMM_STALE\n", r);
    return 1;
  }
  printf("reader: read up to %d in %d wake-ups, then stale\n", last, wakes);
  ccomm_close(c);
  return 0;
}
