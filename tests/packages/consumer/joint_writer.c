/* SPDX-License-Identifier: Apache-2.0 */
/* Built with find_package(ccomm): writes joint_pos = BASE, BASE+1, ... BASE+5 on node
 * 'robot' (examples/local-only.xml) and reads it back. Exit 0 if the read is fresh and
 * equal, 1 otherwise (with the reason on stderr). */
#include <ccomm/ccomm.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: joint_writer BASE\n");
    return 2;
  }
  double base = atof(argv[1]);
  ccomm_client* c;
  int rc = ccomm_open("robot", 0, &c);
  if (rc != 0) {
    fprintf(stderr, "joint_writer: open robot: %s (is ccommd running?)\n", ccomm_strerror(rc));
    return 1;
  }
  ccomm_signal pos = ccomm_find(c, "joint_pos");
  double out[6], in[6];
  for (int i = 0; i < 6; ++i) out[i] = base + i;
  rc = pos < 0 ? pos : ccomm_write(c, pos, out, sizeof out);
  if (rc != 0) {
    fprintf(stderr, "joint_writer: write joint_pos: %s\n", ccomm_strerror(rc));
    return 1;
  }
  ccomm_info info;
  rc = ccomm_read(c, pos, in, sizeof in, &info);
  int ok = rc == CCOMM_FRESH && ccomm_daemon_alive(c);
  for (int i = 0; i < 6; ++i) ok = ok && in[i] == out[i];
  printf("joint_writer: wrote joint_pos [%g..%g], read back %s seq %llu, daemon %s\n", out[0], out[5],
         ccomm_strerror(rc), (unsigned long long)info.seq, ccomm_daemon_alive(c) ? "alive" : "down");
  ccomm_close(c);
  return ok ? 0 : 1;
}
