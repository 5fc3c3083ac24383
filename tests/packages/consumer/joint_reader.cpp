// SPDX-License-Identifier: Apache-2.0
// Built with `pkg-config --cflags --libs ccomm` and the C++ header: reads joint_pos on
// node 'robot' and expects BASE..BASE+5 (what joint_writer wrote), then writes
// drive_ok = true. Exit 0 if so, 1 otherwise (with the reason on stderr).
#include <ccomm/ccomm.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: joint_reader BASE\n");
    return 2;
  }
  const double base = std::atof(argv[1]);
  ccomm::Client c("robot");
  if (!c.ok()) {
    std::fprintf(stderr, "joint_reader: open robot: %s\n", c.error_text());
    return 1;
  }
  auto pos = c.signal<std::array<double, 6>>("joint_pos");
  auto drive_ok = c.signal<bool>("drive_ok");
  if (!pos.valid() || !drive_ok.valid()) {
    std::fprintf(stderr, "joint_reader: signals: %s\n", ccomm_strerror(c.error()));
    return 1;
  }
  auto r = pos.read();
  bool ok = r.fresh();
  for (size_t i = 0; i < 6; ++i) ok = ok && r.value[i] == base + double(i);
  std::printf("joint_reader: joint_pos %s [%g..%g] seq %llu\n", ccomm_strerror(r.status), r.value[0], r.value[5],
              static_cast<unsigned long long>(r.info.seq));
  int rc = drive_ok.write(true);
  if (rc != 0) std::fprintf(stderr, "joint_reader: write drive_ok: %s\n", ccomm_strerror(rc));
  return ok && rc == 0 ? 0 : 1;
}
