// SPDX-License-Identifier: Apache-2.0
// ros2_section_check FILE: what `ccomm-ros2 --check --config FILE` does, in every build
// (with or without Cyclone DDS), for the tests that judge whole files
// (src/config/schema_accepts_test.py).
#include <cstdio>

#include "section.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    fputs("usage: ros2_section_check FILE\n", stderr);
    return 2;
  }
  return ccomm_ros2::CheckConfig(argv[1]);
}
