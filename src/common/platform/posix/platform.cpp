// SPDX-License-Identifier: Apache-2.0
// The platform layer's POSIX unit (Linux, glibc; see common/platform.h); the clock, sleeps
// and real-time set-up are in realtime.cpp, the exclusive lock in exclusive_lock.cpp.
#include "common/platform.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <arpa/inet.h>
#include <fnmatch.h>
#include <linux/futex.h>
#include <linux/sock_diag.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

namespace ccomm {
namespace platform {

static_assert(sizeof(std::atomic<uint32_t>) == sizeof(uint32_t), "futex word must be a plain u32");

uint64_t RealtimeNs() {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<uint64_t>(ts.tv_nsec);
}

int64_t RealtimeOffsetNs() {
  const uint64_t before = MonotonicNs();
  const uint64_t real = RealtimeNs();
  const uint64_t after = MonotonicNs();
  return static_cast<int64_t>(real - (before + (after - before) / 2));
}

// Shared (not FUTEX_PRIVATE_FLAG): the word lives in a segment mapped by several processes.
void FutexWake(std::atomic<uint32_t>* word, int n) {
  syscall(SYS_futex, reinterpret_cast<uint32_t*>(word), FUTEX_WAKE, n, nullptr, nullptr, 0);
}

bool FutexWait(std::atomic<uint32_t>* word, uint32_t expected, int64_t timeout_ns) {
  struct timespec ts;
  struct timespec* tsp = nullptr;
  if (timeout_ns >= 0) {
    ts.tv_sec = timeout_ns / 1000000000;
    ts.tv_nsec = timeout_ns % 1000000000;
    tsp = &ts;
  }
  long r = syscall(SYS_futex, reinterpret_cast<uint32_t*>(word), FUTEX_WAIT, expected, tsp, nullptr, 0);
  return !(r != 0 && errno == ETIMEDOUT);
}

void FutexPrepare(std::atomic<uint32_t>*) {}  // a futex needs no set-up

namespace {
std::atomic<uint32_t> g_pid{0};
void ResetPid() { g_pid.store(static_cast<uint32_t>(getpid()), std::memory_order_relaxed); }
}  // namespace

uint32_t ProcessId() {
  uint32_t p = g_pid.load(std::memory_order_relaxed);
  if (__builtin_expect(p == 0, 0)) {
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, [] { pthread_atfork(nullptr, nullptr, ResetPid); });
    ResetPid();
    p = g_pid.load(std::memory_order_relaxed);
  }
  return p;
}

bool ProcessAlive(uint32_t pid) {
  if (pid == 0) return false;
  return !(kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH);
}

int ShmOpen(const char* name, bool create_exclusive, int mode) {
  int flags = O_RDWR | O_CLOEXEC | (create_exclusive ? (O_CREAT | O_EXCL) : 0);
  int fd = shm_open(name, flags, static_cast<mode_t>(mode));
  if (fd < 0) return -errno;
  if (create_exclusive) fchmod(fd, static_cast<mode_t>(mode));  // umask must not narrow it
  return fd;
}

int ShmOpenReadOnly(const char* name) {
  int fd = shm_open(name, O_RDONLY | O_CLOEXEC, 0);
  return fd < 0 ? -errno : fd;
}

int ShmSetGroup(int fd, int gid) {
  return fchown(fd, static_cast<uid_t>(-1), static_cast<gid_t>(gid)) == 0 ? 0 : -errno;
}

int ShmUnlink(const char* name) { return shm_unlink(name) == 0 ? 0 : -errno; }

void* MapShared(int fd, size_t size) {
  void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  return p == MAP_FAILED ? nullptr : p;
}

const void* MapSharedReadOnly(int fd, size_t size) {
  void* p = mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, 0);
  return p == MAP_FAILED ? nullptr : p;
}

void Unmap(void* p, size_t size) {
  if (p) munmap(p, size);
}

int FileSize(int fd, size_t* size) {
  struct stat st;
  if (fstat(fd, &st) != 0) return -errno;
  *size = static_cast<size_t>(st.st_size);
  return 0;
}

int Truncate(int fd, size_t size) {
  if (ftruncate(fd, static_cast<off_t>(size)) != 0) return -errno;
  const int e = posix_fallocate(fd, 0, static_cast<off_t>(size));  // tmpfs undoes a failed one
  return e == 0 || e == EOPNOTSUPP ? 0 : -e;
}

void CloseFd(int fd) {
  if (fd >= 0) close(fd);
}

void NameThisThread(const char* name) {
  char shown[16];  // the kernel keeps 15 characters and the terminator
  snprintf(shown, sizeof shown, "%s", name);
  pthread_setname_np(pthread_self(), shown);
}

int SocketDrops(int fd, uint32_t* drops) {
  uint32_t mem[SK_MEMINFO_VARS] = {};
  socklen_t len = sizeof mem;
  if (getsockopt(fd, SOL_SOCKET, SO_MEMINFO, mem, &len) != 0) return -errno;
  if (len < (SK_MEMINFO_DROPS + 1) * sizeof(uint32_t)) return -EPROTO;
  *drops = mem[SK_MEMINFO_DROPS];
  return 0;
}

int ReadRegularFile(const char* path, uint64_t max_bytes, std::string* text, uint64_t* size) {
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return -errno;
  struct stat st;
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    close(fd);
    return -EINVAL;
  }
  *size = static_cast<uint64_t>(st.st_size);
  if (*size > max_bytes) {
    close(fd);
    return -EFBIG;
  }
  text->resize(static_cast<size_t>(st.st_size));
  size_t got = 0;
  while (got < text->size()) {
    ssize_t n = read(fd, &(*text)[got], text->size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      int e = errno;
      close(fd);
      errno = e;
      return -EIO;
    }
    if (n == 0) break;  // file shrank while reading
    got += static_cast<size_t>(n);
  }
  close(fd);
  text->resize(got);
  return 0;
}

bool GlobMatch(const char* pattern, const char* name) { return fnmatch(pattern, name, 0) == 0; }

bool ParseIpv4(const char* text, uint32_t* network_order) {
  struct in_addr a;
  if (inet_pton(AF_INET, text, &a) != 1) return false;
  *network_order = a.s_addr;
  return true;
}

bool HostName(char* buf, size_t cap) {
  if (gethostname(buf, cap) != 0) return false;
  buf[cap - 1] = '\0';
  char* dot = strchr(buf, '.');  // node names are short host names
  if (dot) *dot = '\0';
  return buf[0] != '\0';
}

int ListShm(const char* prefix, char* first, size_t cap) {
  DIR* d = opendir("/dev/shm");  // where glibc keeps POSIX shm objects
  if (!d) return 0;
  const size_t n = strlen(prefix);
  int count = 0;
  while (struct dirent* e = readdir(d)) {
    if (strncmp(e->d_name, prefix, n) != 0 || !e->d_name[n] || strchr(e->d_name + n, '.')) continue;
    if (count++ == 0 && cap) snprintf(first, cap, "%s", e->d_name + n);
  }
  closedir(d);
  return count;
}

bool StderrIsJournal() {
  const char* stream = getenv("JOURNAL_STREAM");
  unsigned long long dev = 0, ino = 0;
  char end = 0;
  if (!stream || sscanf(stream, "%llu:%llu%c", &dev, &ino, &end) != 2) return false;
  struct stat st;
  if (fstat(STDERR_FILENO, &st) != 0) return false;
  return static_cast<unsigned long long>(st.st_dev) == dev && static_cast<unsigned long long>(st.st_ino) == ino;
}

}  // namespace platform

}  // namespace ccomm
