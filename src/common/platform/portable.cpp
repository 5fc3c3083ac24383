// SPDX-License-Identifier: Apache-2.0
// The part of the platform layer (common/platform.h) that is plain standard C++ and so
// the same for every platform unit: logging and stack prefaulting.
#include <stdarg.h>
#include <stdio.h>

#include <string>

#include "common/platform.h"

namespace ccomm {
namespace platform {

void PrefaultStack(size_t bytes) {
  volatile unsigned char buf[64 * 1024];
  size_t n = bytes < sizeof buf ? bytes : sizeof buf;
  for (size_t i = 0; i < n; i += 4096) buf[i] = 0;
}

}  // namespace platform

static LogLevel g_max_level = LogLevel::kInfo;
static bool g_sd_prefixes = false;
static FILE* g_log_file = nullptr;  // nullptr: stderr

void SetLogVerbosity(LogLevel max_level) { g_max_level = max_level; }
void SetLogPrefixes(bool sd_prefixes) { g_sd_prefixes = sd_prefixes; }
bool SetLogFile(const char* path) {
  FILE* f = fopen(path, "a");
  if (!f) return false;
  setvbuf(f, nullptr, _IOLBF, 1024);
  g_log_file = f;
  return true;
}

void Log(LogLevel level, const char* fmt, ...) {
  if (static_cast<int>(level) > static_cast<int>(g_max_level)) return;
  char line[1024];
  int off = 0;
  if (g_sd_prefixes) off = snprintf(line, sizeof line, "<%d>", static_cast<int>(level));
  va_list ap, again;
  va_start(ap, fmt);
  va_copy(again, ap);
  const int n = vsnprintf(line + off, sizeof line - static_cast<size_t>(off), fmt, ap);
  va_end(ap);
  FILE* out = g_log_file ? g_log_file : stderr;
  if (n >= 0 && static_cast<size_t>(n) >= sizeof line - static_cast<size_t>(off)) {
    // Longer than the buffer (a "no node ... is this board" listing many interfaces and
    // nodes): whole, not cut; logging is never on a hot path.
    std::string whole(static_cast<size_t>(n) + 1, '\0');
    vsnprintf(&whole[0], whole.size(), fmt, again);
    whole.resize(static_cast<size_t>(n));
    fprintf(out, "%.*s%s\n", off, line, whole.c_str());
  } else {
    fprintf(out, "%s\n", line);
  }
  va_end(again);
}

void LogText(LogLevel level, const std::string& text) {
  size_t i = 0;
  while (i < text.size()) {
    size_t j = text.find('\n', i);
    if (j == std::string::npos) j = text.size();
    if (j > i) Log(level, "%.*s", static_cast<int>(j - i), text.c_str() + i);
    i = j + 1;
  }
}

}  // namespace ccomm
