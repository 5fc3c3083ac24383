// SPDX-License-Identifier: Apache-2.0
// `ccomm gen` and `ccomm X` running other programs (main.cpp) on Windows: there is no
// exec, so the program is spawned, waited for, and its exit status passed on. Arguments
// with spaces are quoted for the child's command line.
#include <errno.h>
#include <process.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <string>
#include <vector>

// clang-format off
#include <windows.h>
// clang-format on

int CannotRun(const char* cmd, const char* prog, int err, const char* usage);  // main.cpp

namespace {

// Runs `file` (searched in PATH) with `args` and waits: its exit status, or -1 (errno).
int Spawn(const char* file, const std::vector<std::string>& args) {
  std::vector<std::string> quoted;
  for (const std::string& a : args) quoted.push_back(a.find_first_of(" \t") == std::string::npos ? a : '"' + a + '"');
  std::vector<const char*> argv;
  for (const std::string& q : quoted) argv.push_back(q.c_str());
  argv.push_back(nullptr);
  return static_cast<int>(_spawnvp(_P_WAIT, file, argv.data()));
}

}  // namespace

int RunGenerator(const char* node, std::string path, int argc, char** argv) {
  // It reads signals.xml through `ccommd --check --json`, with the ccommd.exe beside this program.
  char self[MAX_PATH];
  const DWORD len = GetModuleFileNameA(nullptr, self, sizeof self);
  if (!getenv("CCOMM_CCOMMD") && len > 0 && len < sizeof self) {
    std::string beside(self, len);
    beside = beside.substr(0, beside.find_last_of("\\/") + 1) + "ccommd.exe";
    if (GetFileAttributesA(beside.c_str()) != INVALID_FILE_ATTRIBUTES) _putenv_s("CCOMM_CCOMMD", beside.c_str());
  }
  std::vector<std::string> args = {"python", path};
  if (node) {
    args.push_back("--node");
    args.push_back(node);
  }
  for (int i = 2; i < argc; ++i) args.push_back(argv[i]);
  const int r = Spawn("python", args);
  if (r < 0) {
    fprintf(stderr, "ccomm gen: cannot run python %s: %s\n", path.c_str(), strerror(errno));
    return 1;
  }
  return r;
}

int RunExternal(const char* node, const char* cmd, int argc, char** argv, const char* usage) {
  const std::string prog = std::string("ccomm-") + cmd;
  if (node) _putenv_s("CCOMM_NODE", node);
  std::vector<std::string> args = {prog};
  for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
  const int r = Spawn(prog.c_str(), args);
  if (r >= 0) return r;
  return CannotRun(cmd, prog.c_str(), errno, usage);
}
