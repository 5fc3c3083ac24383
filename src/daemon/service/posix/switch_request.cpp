// SPDX-License-Identifier: Apache-2.0
// `ccommd -c CONFIG --reload PID --at T` on POSIX (switch_request.h): the requester.
// Run as root (deploy's job), it answers to a ccommd that runs as its own user: before
// asking, its real uid becomes ccommd's (the effective one stays root, for moving the
// files), so that ccommd's answer signals are allowed in.
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "common/platform.h"
#include "config/config.h"
#include "daemon/service/stop_request.h"
#include "daemon/service/switch_request.h"

namespace ccomm {
namespace switch_at {
namespace {

// Writes `text` to `path` whole (platform::WriteFileAtomically); *why names the file.
bool WriteWhole(const std::string& path, const std::string& text, std::string* why) {
  const int r = platform::WriteFileAtomically(path.c_str(), text);
  if (r != 0) *why = path + ": " + strerror(-r);
  return r == 0;
}

// The real uid of process `pid` (/proc/PID/status), -1 if unknown.
long RealUidOf(int pid) {
  char path[64];
  snprintf(path, sizeof path, "/proc/%d/status", pid);
  FILE* f = fopen(path, "r");
  if (!f) return -1;
  char line[256];
  long uid = -1;
  while (fgets(line, sizeof line, f))
    if (sscanf(line, "Uid: %ld", &uid) == 1) break;
  fclose(f);
  return uid;
}

void SayArmed(void* at) {
  printf("armed %llu\n", static_cast<unsigned long long>(*static_cast<uint64_t*>(at)));
  fflush(stdout);
}

}  // namespace

int Request(const std::string& config, int pid, uint64_t at_ns) {
  const std::string staged = StagedPath(config), instant = InstantPath(config);
  SystemConfig next;
  std::string why;
  if (!LoadConfig(staged, &next, &why)) {
    LogText(LogLevel::kError, why);
    Log(LogLevel::kError, "not switched: ccommd (pid %d) keeps running on the configuration it has", pid);
    return 1;
  }
  const uint64_t now = platform::RealtimeNs();
  if (at_ns <= now) {
    Log(LogLevel::kError, "ccommd: --at: the instant is %.3f s past; nothing asked",
        static_cast<double>(now - at_ns) / 1e9);
    return 1;
  }
  char text[32];
  snprintf(text, sizeof text, "%llu.%09llu\n", static_cast<unsigned long long>(at_ns / 1000000000),
           static_cast<unsigned long long>(at_ns % 1000000000));
  if (!WriteWhole(instant, text, &why)) {
    Log(LogLevel::kError, "ccommd: cannot leave the switch instant for ccommd: %s", why.c_str());
    return 1;
  }
  if (geteuid() == 0) {
    const long uid = RealUidOf(pid);
    if (uid > 0 && setresuid(static_cast<uid_t>(uid), static_cast<uid_t>(-1), static_cast<uid_t>(-1)) != 0)
      Log(LogLevel::kWarning, "ccommd: cannot take uid %ld for ccommd's answer: %s", uid, strerror(errno));
  }
  // Armed within 30 s (ccommd parses the file once more), then until the instant and 30 s.
  const uint64_t wait_ms = (at_ns - now) / 1000000 + 30000;
  uint64_t at = at_ns;
  const int r = stop::AskReloadAt(pid, 30000, static_cast<int>(wait_ms), SayArmed, &at);
  const uint64_t applied = platform::RealtimeNs();
  unlink(instant.c_str());
  if (r != 1) {
    if (r == 0)
      Log(LogLevel::kError, "ccommd (pid %d) did not switch to %s (refused, or cancelled: the staged file went "
          "away or changed); its log says why", pid, staged.c_str());
    else
      Log(LogLevel::kError, "cannot ask ccommd (pid %d) to switch: %s", pid,
          r == -ETIMEDOUT ? "no answer in time" : strerror(-r));
    return 1;
  }
  // ccommd runs the staged file now: so must the file in place (old one kept).
  std::string old;
  uint64_t size = 0;
  if (platform::ReadRegularFile(config.c_str(), 16u << 20, &old, &size) == 0 &&
      !WriteWhole(config + ".previous", old, &why))
    Log(LogLevel::kWarning, "ccommd: cannot keep the old file: %s", why.c_str());
  if (rename(staged.c_str(), config.c_str()) != 0) {
    Log(LogLevel::kError, "ccommd (pid %d) switched, but %s cannot replace %s: %s (a restart would read the old "
        "file)", pid, staged.c_str(), config.c_str(), strerror(errno));
    return 1;
  }
  printf("switched %llu %llu\n", static_cast<unsigned long long>(at_ns), static_cast<unsigned long long>(applied));
  fflush(stdout);
  Log(LogLevel::kInfo, "ccommd (pid %d) switched to %s at the instant; the file is in place (the old one: %s.previous)",
      pid, config.c_str(), config.c_str());
  return 0;
}

}  // namespace switch_at
}  // namespace ccomm
