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

#include <cerrno>
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

// CC as make and the shell take it: words split at blanks ("cc -O2", "ccache gcc"), so
// that CC=... with flags works; quotes are not interpreted (the compiler's path has none).
std::vector<std::string> Words(const std::string& s) {
  std::vector<std::string> words;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\n')) ++i;
    const size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\n') ++i;
    if (i > start) words.push_back(s.substr(start, i - start));
  }
  return words;
}

// Runs args (in dir, if given); its stdout and stderr go to *output when given (so that a
// failure can show what the compiler said), else to ours. False with why in *why.
bool Spawn(const std::vector<std::string>& args, const char* dir, std::string* output = nullptr,
           std::string* why = nullptr) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (dir != nullptr) posix_spawn_file_actions_addchdir_np(&actions, dir);
  int fds[2] = {-1, -1};
  if (output != nullptr && pipe(fds) == 0) {
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addclose(&actions, fds[1]);
  }
  pid_t pid;
  int status = 0;
  const int rc = posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (fds[1] >= 0) close(fds[1]);
  if (rc == 0 && fds[0] >= 0) {
    char buf[4096];
    ssize_t n;
    while ((n = read(fds[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR))
      if (n > 0) output->append(buf, static_cast<size_t>(n));
  }
  if (fds[0] >= 0) close(fds[0]);
  if (rc != 0) {
    if (why != nullptr) *why = std::string("cannot run ") + argv[0] + ": " + std::strerror(rc);
    return false;
  }
  if (waitpid(pid, &status, 0) != pid) {
    if (why != nullptr) *why = std::string("waitpid: ") + std::strerror(errno);
    return false;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return true;
  if (why != nullptr)
    *why = WIFEXITED(status) ? "exit status " + std::to_string(WEXITSTATUS(status))
                             : "killed by signal " + std::to_string(WTERMSIG(status));
  return false;
}

// The FMI platform directory for the compiler's target triple; nullptr if unknown, with
// what the compiler said (or why it did not run) in *why.
const char* TargetPlatform(const std::vector<std::string>& cc, int major, std::string* why) {
  std::vector<std::string> args = cc;
  args.push_back("-dumpmachine");
  std::string out;
  if (!Spawn(args, nullptr, &out, why)) {
    *why += out.empty() ? "" : ": " + out;
    return nullptr;
  }
  *why = "target " + out;
  const std::string triple = out;
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
    std::fprintf(stderr, "ccomm-fmu build: %s\n", unpacked.Unpacked(error).c_str());
    return 1;
  }
  BuildDescription bd;
  if (md.fmi_major == 3) {
    if (!LoadBuildDescription(dir + "/sources/buildDescription.xml", md.model_identifier, &bd, &error)) {
      std::fprintf(stderr, "ccomm-fmu build: %s\n", unpacked.Unpacked(error).c_str());
      return 1;
    }
  } else {
    bd.sources = md.source_files;
    if (bd.sources.empty()) {
      std::fprintf(stderr, "ccomm-fmu build: %s lists no <SourceFiles>: not a source FMU\n", fmu_path.c_str());
      return 1;
    }
  }
  const std::vector<std::string> cc_words = Words(cc);
  if (cc_words.empty()) {
    std::fputs("ccomm-fmu build: the compiler (--cc or $CC) is empty\n", stderr);
    return 1;
  }
  std::string cc_target;
  const char* platform = TargetPlatform(cc_words, md.fmi_major, &cc_target);
  if (platform == nullptr) {
    while (!cc_target.empty() && cc_target.back() == '\n') cc_target.pop_back();
    std::fprintf(stderr, "ccomm-fmu build: cannot tell the target of compiler '%s' (-dumpmachine: %s)\n",
                 cc.c_str(), cc_target.c_str());
    return 1;
  }
  const std::string bin_dir = dir + "/binaries/" + platform;
  if (!Spawn({"mkdir", "-p", bin_dir}, nullptr)) {
    std::fprintf(stderr, "ccomm-fmu build: cannot create %s\n", bin_dir.c_str());
    return 1;
  }
  std::vector<std::string> args = cc_words;
  args.insert(args.end(), {"-shared", "-fPIC", "-O2", "-fvisibility=default", "-I", dir + "/sources"});
  // FMI 3.0 (2.4.x, source code FMUs): an importer that compiles the sources into a shared
  // library defines FMI3_OVERRIDE_FUNCTION_PREFIX, so that the sources do not give their
  // functions the model's prefix (VanDerPol_fmi3DoStep): a binary FMU exports fmi3DoStep.
  if (md.fmi_major == 3) args.push_back("-DFMI3_OVERRIDE_FUNCTION_PREFIX");
  if (!fmi_include.empty()) args.insert(args.end(), {"-I", fmi_include});
  for (const std::string& i : bd.include_dirs) args.insert(args.end(), {"-I", dir + "/sources/" + i});
  for (const std::string& d : bd.defines) args.push_back("-D" + d);
  for (const std::string& s : bd.sources) args.push_back(dir + "/sources/" + s);
  args.insert(args.end(), {"-o", bin_dir + "/" + md.model_identifier + ".so", "-lm"});
  std::string shown;
  for (const std::string& a : args) shown += " " + a;
  std::fprintf(stderr, "ccomm-fmu build:%s\n", shown.c_str());
  std::string compiler_output, why;
  const bool compiled = Spawn(args, nullptr, &compiler_output, &why);
  std::fputs(unpacked.Unpacked(compiler_output).c_str(), stderr);  // its warnings too, and on failure what it says
  if (!compiled) {
    std::fprintf(stderr, "ccomm-fmu build: the compiler failed (%s)%s\n", why.c_str(),
                 compiler_output.find("fmi") != std::string::npos && fmi_include.empty()
                     ? "; FMI headers missing? give --fmi-include DIR" : "");
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
