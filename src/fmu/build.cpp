// SPDX-License-Identifier: Apache-2.0
// `ccomm-fmu build`: compiles a source FMU for the board it will run on. FMI 3.0 FMUs
// describe their sources in sources/buildDescription.xml, FMI 2.0 FMUs list them in
// modelDescription.xml (CoSimulation/SourceFiles). The binary goes to
// binaries/<platform>/<modelIdentifier>.so for the compiler's target (`CC -dumpmachine`):
// FMI 2.0 has no ARM platform name, so 32-bit ARM uses linux32, which ccomm-fmu loads there.
#include <getopt.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "model_description.h"
#include "runner.h"

extern char** environ;

namespace ccomm::fmu {
namespace {

bool Spawn(const std::vector<std::string>& args, const char* dir) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (dir != nullptr) posix_spawn_file_actions_addchdir_np(&actions, dir);
  pid_t pid;
  int status = 0;
  bool ok = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ) == 0 &&
            waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  posix_spawn_file_actions_destroy(&actions);
  return ok;
}

// The FMI platform directory for the compiler's target triple; nullptr if unknown.
const char* TargetPlatform(const std::string& cc, int major) {
  std::string cmd = cc + " -dumpmachine 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  char buf[128] = "";
  if (p == nullptr) return nullptr;
  if (std::fgets(buf, sizeof buf, p) == nullptr) buf[0] = '\0';
  pclose(p);
  const std::string triple = buf;
  if (triple.rfind("x86_64-", 0) == 0) return major == 3 ? "x86_64-linux" : "linux64";
  if (triple.rfind("aarch64-", 0) == 0) return major == 3 ? "aarch64-linux" : "linux64";
  if (triple.rfind("arm", 0) == 0) return major == 3 ? "aarch32-linux" : "linux32";
  if (triple.rfind("i686-", 0) == 0 || triple.rfind("i386-", 0) == 0) return major == 3 ? "x86-linux" : "linux32";
  return nullptr;
}

}  // namespace

int BuildSourceFmu(const std::string& fmu_path, int argc, char** argv) {
  std::string cc = std::getenv("CC") != nullptr ? std::getenv("CC") : "cc", out, fmi_include;
  static const option kLong[] = {{"cc", required_argument, nullptr, 'c'},
                                 {"out", required_argument, nullptr, 'o'},
                                 {"fmi-include", required_argument, nullptr, 'I'},
                                 {nullptr, 0, nullptr, 0}};
  optind = 1;
  int ch;
  while ((ch = getopt_long(argc, argv, "", kLong, nullptr)) != -1) {
    if (ch == 'c') cc = optarg;
    else if (ch == 'o') out = optarg;
    else if (ch == 'I') fmi_include = optarg;
    else {
      std::fputs("usage: ccomm-fmu build FMU [--cc CC] [--fmi-include DIR] [--out FILE.fmu]\n", stderr);
      return 1;
    }
  }
  struct stat st;
  const bool is_dir = stat(fmu_path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
  if (!is_dir && out.empty()) out = fmu_path;  // a .fmu gets its binary added in place
  UnpackedFmu unpacked;
  std::string error;
  if (!unpacked.Open(fmu_path, &error)) {
    std::fprintf(stderr, "ccomm-fmu build: %s\n", error.c_str());
    return 1;
  }
  const std::string dir = unpacked.dir();
  ModelDescription md;
  if (!LoadModelDescription(dir + "/modelDescription.xml", &md, &error)) {
    std::fprintf(stderr, "ccomm-fmu build: %s\n", error.c_str());
    return 1;
  }
  BuildDescription bd;
  if (md.fmi_major == 3) {
    if (!LoadBuildDescription(dir + "/sources/buildDescription.xml", md.model_identifier, &bd, &error)) {
      std::fprintf(stderr, "ccomm-fmu build: %s\n", error.c_str());
      return 1;
    }
  } else {
    bd.sources = md.source_files;
    if (bd.sources.empty()) {
      std::fprintf(stderr, "ccomm-fmu build: %s lists no <SourceFiles>: not a source FMU\n", fmu_path.c_str());
      return 1;
    }
  }
  const char* platform = TargetPlatform(cc, md.fmi_major);
  if (platform == nullptr) {
    std::fprintf(stderr, "ccomm-fmu build: cannot tell the target of compiler '%s' (-dumpmachine)\n", cc.c_str());
    return 1;
  }
  const std::string bin_dir = dir + "/binaries/" + platform;
  if (!Spawn({"mkdir", "-p", bin_dir}, nullptr)) {
    std::fprintf(stderr, "ccomm-fmu build: cannot create %s\n", bin_dir.c_str());
    return 1;
  }
  std::vector<std::string> args = {cc, "-shared", "-fPIC", "-O2", "-fvisibility=default", "-I", dir + "/sources"};
  if (!fmi_include.empty()) args.insert(args.end(), {"-I", fmi_include});
  for (const std::string& i : bd.include_dirs) args.insert(args.end(), {"-I", dir + "/sources/" + i});
  for (const std::string& d : bd.defines) args.push_back("-D" + d);
  for (const std::string& s : bd.sources) args.push_back(dir + "/sources/" + s);
  args.insert(args.end(), {"-o", bin_dir + "/" + md.model_identifier + ".so", "-lm"});
  std::string shown;
  for (const std::string& a : args) shown += " " + a;
  std::fprintf(stderr, "ccomm-fmu build:%s\n", shown.c_str());
  if (!Spawn(args, nullptr)) {
    std::fprintf(stderr, "ccomm-fmu build: the compiler failed (FMI headers missing? give --fmi-include DIR)\n");
    return 1;
  }
  if (!out.empty()) {
    char* real = realpath(out.c_str(), nullptr);
    char cwd[4096] = ".";
    if (getcwd(cwd, sizeof cwd) == nullptr) cwd[0] = 0;
    std::string target = real != nullptr ? real : (out[0] == '/' ? out : std::string(cwd) + "/" + out);
    std::free(real);
    if (!is_dir) std::remove(target.c_str());
    if (!Spawn({"zip", "-q", "-r", target, "."}, dir.c_str())) {
      std::fprintf(stderr, "ccomm-fmu build: cannot write %s (zip missing?)\n", target.c_str());
      return 1;
    }
    std::fprintf(stderr, "ccomm-fmu build: wrote %s (binaries/%s)\n", target.c_str(), platform);
  } else {
    std::fprintf(stderr, "ccomm-fmu build: built %s/%s.so\n", bin_dir.c_str(), md.model_identifier.c_str());
  }
  return 0;
}

}  // namespace ccomm::fmu
