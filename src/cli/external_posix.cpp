// SPDX-License-Identifier: Apache-2.0
// `ccomm gen` and `ccomm X` running other programs (main.cpp): exec on POSIX.
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <string>
#include <vector>

int CannotRun(const char* cmd, const char* prog, int err, const char* usage);  // main.cpp

int RunGenerator(const char* node, std::string path, int argc, char** argv) {
  // It reads signals.xml through `ccommd --check --json`: in a build tree the ccommd beside
  // this program, installed the one in sbin (the generator looks there).
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (!getenv("CCOMM_CCOMMD") && len > 0) {
    self[len] = '\0';
    std::string beside(self);
    beside = beside.substr(0, beside.rfind('/') + 1) + "ccommd";
    if (access(beside.c_str(), X_OK) == 0) setenv("CCOMM_CCOMMD", beside.c_str(), 1);
  }
  std::vector<char*> args;
  std::string py = "python3";
  args.push_back(&py[0]);
  args.push_back(&path[0]);
  std::string node_opt = "--node";
  std::string node_name = node ? node : "";
  if (node) {
    args.push_back(&node_opt[0]);
    args.push_back(&node_name[0]);
  }
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execvp("python3", args.data());
  fprintf(stderr, "ccomm gen: cannot run python3 %s: %s\n", path.c_str(), strerror(errno));
  return 1;
}

// `ccomm X ARGS` for a command this program does not know runs `ccomm-X ARGS` from PATH
// (git-style), so tools shipped by other packages (Python, the ROS 2 bridge) are one CLI.
int RunExternal(const char* node, const char* cmd, int argc, char** argv, const char* usage) {
  std::string prog = std::string("ccomm-") + cmd;
  if (node) setenv("CCOMM_NODE", node, 1);
  std::vector<char*> args;
  args.push_back(&prog[0]);
  for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  execvp(prog.c_str(), args.data());
  return CannotRun(cmd, prog.c_str(), errno, usage);
}
