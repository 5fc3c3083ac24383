// SPDX-License-Identifier: Apache-2.0
// The platform layer (zenoh-pico style): every OS call of the store, the client library
// and ccommd's threads (clock, futex, shared memory, scheduling, sleeping, logging) goes
// through this header and common/public/platform_app.h, its part the programs of the public API
// use too (real-time set-up, sleeping, the exclusive lock, segment names). It has one set
// of units per platform, whole files chosen by CMake (src/common/CMakeLists.txt), never
// #ifdefs inside functions:
//   platform/posix/     Linux (glibc; Xenomai's POSIX skin wraps it)
//   platform/windows/   Windows x64 (named file mappings, named events)
// A port (another RTOS) of what runs inside the applications adds one folder. The daemon's
// own OS code (sockets, interfaces, privileges, the key file, ptp4l, stop requests) has
// one whole file per platform in src/daemon (daemon/sources.cmake, docs/design.md), and
// config.cpp reads signals.xml through ReadRegularFile. Functions marked [rt] are safe on
// a real-time path: no allocation, no locks, and no syscall except where stated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <atomic>
#include <string>

#include "common/public/platform_app.h"
#if defined(_MSC_VER)
#include <intrin.h>  // _mm_pause
#endif

// printf-style checking where the compiler has it (GCC, Clang; MinGW's printf is the
// C99 one, __USE_MINGW_ANSI_STDIO), nothing for MSVC.
#if defined(__MINGW32__)
#define CCOMM_PRINTF_FORMAT(f, a) __attribute__((format(gnu_printf, f, a)))
#elif defined(__GNUC__)
#define CCOMM_PRINTF_FORMAT(f, a) __attribute__((format(printf, f, a)))
#else
#define CCOMM_PRINTF_FORMAT(f, a)
#endif

namespace ccomm {
namespace platform {

// MonotonicNs, the sleeps, SetUpRealtime, LockExclusive and SegmentName: platform_app.h.
/// CLOCK_REALTIME in ns since 1970 (the clock ptp4l disciplines with software
/// timestamping): the common time base between boards when their clocks are synced.
uint64_t RealtimeNs();
/// RealtimeNs() - MonotonicNs() now, read with the monotonic clock on both sides of the
/// realtime one (their mean): what maps a monotonic stamp of this board to common time.
/// It changes only when the realtime clock is stepped (both are slewed alike).
int64_t RealtimeOffsetNs();

/// [rt] Hint to the CPU inside a spin loop.
inline void CpuRelax() {
#if defined(_MSC_VER) && (defined(_M_X64) || defined(_M_IX86))
  _mm_pause();
#elif defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__) || (defined(__arm__) && (__ARM_ARCH >= 7))
  __asm__ __volatile__("yield");
#endif
}

/// [rt] Wakes up to `n` waiters on a futex word in shared memory (one non-blocking syscall).
void FutexWake(std::atomic<uint32_t>* word, int n);
/// Blocks while *word == expected, at most timeout_ns (<0 = forever). Returns false on timeout.
bool FutexWait(std::atomic<uint32_t>* word, uint32_t expected, int64_t timeout_ns);
/// Readies `word` (in memory from MapShared) for FutexWake/FutexWait before the real-time
/// path uses it: nothing on Linux; on Windows it opens the word's named event, so that
/// no wake or wait creates one. Not [rt]: called when a segment is opened.
void FutexPrepare(std::atomic<uint32_t>* word);

/// [rt] This process's pid, cached (refreshed after fork); no syscall.
uint32_t ProcessId();
/// False only if no process `pid` exists (kill(pid, 0) == ESRCH). Not [rt].
bool ProcessAlive(uint32_t pid);

/// Shared memory. Names are POSIX shm names ("/ccomm.node"); the Windows unit makes them
/// named file mappings ("Local\\ccomm.node", see docs/install.md).
int ShmOpen(const char* name, bool create_exclusive, int mode);  // fd or -errno
int ShmOpenReadOnly(const char* name);                             // fd or -errno
int ShmUnlink(const char* name);                                   // 0 or -errno
void* MapShared(int fd, size_t size);                              // nullptr on error (errno set)
const void* MapSharedReadOnly(int fd, size_t size);                // nullptr on error (errno set)
/// Gives an object made by ShmOpen to group `gid` (its members may map it); 0 or -errno.
int ShmSetGroup(int fd, int gid);
void Unmap(void* p, size_t size);
int FileSize(int fd, size_t* size);                                // 0 or -errno
/// Sizes a new shm object and allocates its backing (posix_fallocate): a /dev/shm too
/// small fails here with -ENOSPC instead of a SIGBUS at the first touch. 0 or -errno.
int Truncate(int fd, size_t size);
void CloseFd(int fd);

/// Start-up checks of room for a segment (ccommd: segment_builder.cpp). UINT64_MAX means
/// "no limit known". ShmRoom: free bytes where shm objects live (/dev/shm);
/// CgroupMemoryRoom: left under memory.max of this process's cgroup and its ancestors;
/// AddressSpaceRoom: left under RLIMIT_AS.
uint64_t ShmRoom();
uint64_t CgroupMemoryRoom();
uint64_t AddressSpaceRoom();
/// Packets the kernel dropped at socket `fd` since it was opened (receive buffer full;
/// SO_MEMINFO, the `d` that `ss -m` shows). Returns 0 or -errno. Not [rt]: supervision.
int SocketDrops(int fd, uint32_t* drops);
/// Touches `bytes` of stack so page faults happen at start-up, not in the loop.
void PrefaultStack(size_t bytes);
/// Names the calling thread (at most 15 characters shown), so that ps -L, top -H and
/// /proc/PID/task/TID/comm tell ccommd's threads apart. Start-up only.
void NameThisThread(const char* name);

/// POSIX shm objects whose names start with `prefix` (without the leading '/'): how many,
/// and the rest of the first one's name in `first` (`cap` bytes). Start-up only.
int ListShm(const char* prefix, char* first, size_t cap);
/// Reads the regular file `path` whole into `text` (start-up only). 0, -EINVAL if it is
/// not a regular file, -EFBIG if larger than `max_bytes` (its size in `size`), -EIO if
/// a read failed (errno says why), or the -errno of opening it.
int ReadRegularFile(const char* path, uint64_t max_bytes, std::string* text, uint64_t* size);
/// Writes `text` to `path` whole or not at all: a temporary file (`path`.tmp) renamed over
/// it, so a reader sees the old file or the new one, never half of one. 0 or -errno
/// (the temporary file is removed then). Start-up and supervision only.
int WriteFileAtomically(const char* path, const std::string& text);
/// What tells a file apart from the one that replaced it (same name): device, file id,
/// size and last write time. `valid` false if `path` cannot be examined.
struct FileIdentity {
  uint64_t dev = 0, ino = 0, size = 0;
  int64_t mtime_ns = 0;
  bool valid = false;
};
FileIdentity IdentifyFile(const char* path);
/// Both examined and the same file, unchanged.
inline bool SameFile(const FileIdentity& a, const FileIdentity& b) {
  return a.valid && b.valid && a.dev == b.dev && a.ino == b.ino && a.size == b.size && a.mtime_ns == b.mtime_ns;
}
/// True if `name` matches the shell glob `pattern` (* ? [...], as fnmatch with no flags).
bool GlobMatch(const char* pattern, const char* name);
/// Hostname (for the default node name); false on error.
bool HostName(char* buf, size_t cap);
/// Dotted-quad IPv4 text to an address in network byte order (inet_pton); false if
/// `text` is not one. Start-up only (the Windows unit starts Winsock on first use).
bool ParseIpv4(const char* text, uint32_t* network_order);

/// Whether stderr is the journal's stream (systemd sets JOURNAL_STREAM to its
/// "device:inode"; a child whose stderr was redirected inherits the variable but not the
/// stream, so both are compared): then log lines carry sd-daemon priority prefixes.
bool StderrIsJournal();

}  // namespace platform

/// Logging for start-up, shutdown and rare events; never used per message. Lines go to
/// stderr with sd-daemon priority prefixes ("<3>"), which journald understands.
enum class LogLevel { kError = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };
void Log(LogLevel level, const char* fmt, ...) CCOMM_PRINTF_FORMAT(2, 3);
/// Log() for each line of `text` (a multi-line message such as the configuration's
/// FILE:LINE errors): under journald every line then carries `level`.
void LogText(LogLevel level, const std::string& text);
void SetLogVerbosity(LogLevel max_level);
void SetLogPrefixes(bool sd_prefixes);
/// Appends log lines to the file `path` instead of stderr (a Windows service has no
/// stderr: service/windows/service.cpp). False if it cannot be opened.
bool SetLogFile(const char* path);

}  // namespace ccomm
