// SPDX-License-Identifier: Apache-2.0
// The platform layer's Windows unit (Windows 10 x64; built with mingw-w64 or MSVC; see
// common/platform.h). What differs from POSIX, and why:
// - Shared memory is a named file mapping backed by the paging file, named
//   "<namespace><name without '/'>" with the namespace from CCOMM_SHM_NAMESPACE
//   ("Local\" by default: the session's; "Global\" for a ccommd running as a service,
//   which needs SeCreateGlobalPrivilege). A mapping's size is rounded to pages by
//   Windows, so each mapping starts with one page of its own holding the exact size
//   (what fstat gives on POSIX); callers see the memory after it. A name lives while
//   some process holds the mapping: ShmUnlink has nothing to remove.
// - A futex word in shared memory gets a named auto-reset event
//   ("<mapping name>.futex.<offset>"), opened by FutexPrepare when a segment is mapped;
//   FutexWake sets it, FutexWait waits on it and re-checks the word. A waiter that wakes
//   to a changed word sets the event again, so every waiter of a wake-all wakes in turn.
//   A word outside shared memory gets an unnamed event the same way.
// - No per-socket drop counter: -ENOSYS. The clock, sleeps and real-time set-up are in
//   realtime.cpp, the exclusive lock in exclusive_lock.cpp.
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// clang-format off
#include <winsock2.h>  // before windows.h
#include <ws2tcpip.h>
#include <windows.h>
// clang-format on

#include "common/platform.h"
#include "common/platform/windows/errno_of.h"

namespace ccomm {
namespace platform {

namespace {

constexpr size_t kSizePage = 4096;  // the page before the data: the exact size
constexpr int kMaxObjects = 64;     // shared memory objects open (fds) at once
constexpr int kMaxMappings = 64;    // mappings alive at once
constexpr int kMaxFutexes = 64;     // futex words with an event
constexpr size_t kNameCap = 160;

struct ShmObject {  // what a POSIX fd is for the callers
  bool in_use;
  bool create_pending;  // ShmOpen(create_exclusive): the mapping is made by Truncate
  bool read_only;
  HANDLE section;
  char name[kNameCap];
};

struct Mapping {
  std::atomic<char*> data;  // what the caller got; null = free entry
  size_t size;
  HANDLE section;  // held while mapped: a named object's name lives with its handles
  char name[kNameCap];
};

struct FutexEvent {
  std::atomic<uintptr_t> word;  // 0 = free entry
  HANDLE event;
};

SRWLOCK g_lock = SRWLOCK_INIT;  // set-up and tear-down only; wakes and waits read lock-free
ShmObject g_objects[kMaxObjects];
Mapping g_mappings[kMaxMappings];
FutexEvent g_futexes[kMaxFutexes];

struct Locked {
  Locked() { AcquireSRWLockExclusive(&g_lock); }
  ~Locked() { ReleaseSRWLockExclusive(&g_lock); }
};

bool WindowsName(const char* posix_name, char* out, size_t cap) {
  const char* ns = getenv("CCOMM_SHM_NAMESPACE");
  if (!ns || !*ns) ns = "Local\\";
  while (*posix_name == '/') ++posix_name;
  const int n = snprintf(out, cap, "%s%s", ns, posix_name);
  return n > 0 && static_cast<size_t>(n) < cap;
}

ShmObject* Object(int fd) {
  return fd >= 0 && fd < kMaxObjects && g_objects[fd].in_use ? &g_objects[fd] : nullptr;
}

int NewObject(const char* windows_name, HANDLE section, bool create_pending, bool read_only) {
  Locked lock;
  for (int fd = 0; fd < kMaxObjects; ++fd) {
    ShmObject& o = g_objects[fd];
    if (o.in_use) continue;
    o.in_use = true;
    o.create_pending = create_pending;
    o.read_only = read_only;
    o.section = section;
    snprintf(o.name, sizeof o.name, "%s", windows_name);
    return fd;
  }
  if (section) CloseHandle(section);
  return -EMFILE;
}

int OpenExisting(const char* name, bool read_only) {
  char wname[kNameCap];
  if (!WindowsName(name, wname, sizeof wname)) return -ENAMETOOLONG;
  HANDLE h = OpenFileMappingA(read_only ? FILE_MAP_READ : FILE_MAP_READ | FILE_MAP_WRITE, FALSE, wname);
  if (!h) return -ErrnoOf(GetLastError());
  return NewObject(wname, h, false, read_only);
}

// Maps the object, records the mapping (for the futex events' names) and returns the
// memory after the size page.
char* MapObject(int fd, size_t size, bool read_only) {
  ShmObject* o = Object(fd);
  if (!o || !o->section) {
    errno = EBADF;
    return nullptr;
  }
  Locked lock;
  Mapping* m = nullptr;
  for (Mapping& candidate : g_mappings)
    if (!candidate.data.load(std::memory_order_relaxed)) {
      m = &candidate;
      break;
    }
  if (!m) {
    errno = EMFILE;
    return nullptr;
  }
  const DWORD access = read_only ? FILE_MAP_READ : FILE_MAP_READ | FILE_MAP_WRITE;
  void* base = MapViewOfFile(o->section, access, 0, 0, size + kSizePage);
  if (!base) {
    errno = ErrnoOf(GetLastError());
    return nullptr;
  }
  HANDLE held = nullptr;
  DuplicateHandle(GetCurrentProcess(), o->section, GetCurrentProcess(), &held, 0, FALSE, DUPLICATE_SAME_ACCESS);
  m->size = size;
  m->section = held;
  snprintf(m->name, sizeof m->name, "%s", o->name);
  char* data = static_cast<char*>(base) + kSizePage;
  m->data.store(data, std::memory_order_release);
  return data;
}

// The futex event of `word`, or null if FutexPrepare never saw it. Lock-free.
HANDLE FindEvent(const std::atomic<uint32_t>* word) {
  const uintptr_t key = reinterpret_cast<uintptr_t>(word);
  for (FutexEvent& f : g_futexes)
    if (f.word.load(std::memory_order_acquire) == key) return f.event;
  return nullptr;
}

HANDLE EventOf(std::atomic<uint32_t>* word) {
  HANDLE e = FindEvent(word);
  if (e) return e;
  FutexPrepare(word);  // a word nobody prepared: set up now (not real-time)
  return FindEvent(word);
}

}  // namespace

uint64_t RealtimeNs() {
  FILETIME ft;
  GetSystemTimePreciseAsFileTime(&ft);  // 100 ns units since 1601
  const uint64_t t = (uint64_t{ft.dwHighDateTime} << 32) | ft.dwLowDateTime;
  return (t - 116444736000000000ull) * 100;
}

int64_t RealtimeOffsetNs() {
  const uint64_t before = MonotonicNs();
  const uint64_t real = RealtimeNs();
  const uint64_t after = MonotonicNs();
  return static_cast<int64_t>(real - (before + (after - before) / 2));
}

void FutexPrepare(std::atomic<uint32_t>* word) {
  Locked lock;
  const uintptr_t key = reinterpret_cast<uintptr_t>(word);
  FutexEvent* free_entry = nullptr;
  for (FutexEvent& f : g_futexes) {
    const uintptr_t w = f.word.load(std::memory_order_relaxed);
    if (w == key) return;
    if (!w && !free_entry) free_entry = &f;
  }
  if (!free_entry) {
    Log(LogLevel::kError, "platform: more than %d futex words", kMaxFutexes);
    return;
  }
  char name[kNameCap + 32];
  const char* event_name = nullptr;
  for (Mapping& m : g_mappings) {
    const char* data = m.data.load(std::memory_order_acquire);
    const char* p = reinterpret_cast<const char*>(word);
    if (data && p >= data && p < data + m.size) {
      snprintf(name, sizeof name, "%s.futex.%llu", m.name, static_cast<unsigned long long>(p - data));
      event_name = name;
      break;
    }
  }
  HANDLE e = CreateEventA(nullptr, FALSE, FALSE, event_name);  // auto-reset; opens an existing one
  if (!e) {
    Log(LogLevel::kError, "platform: cannot create event %s: error %lu", event_name ? event_name : "(unnamed)",
        static_cast<unsigned long>(GetLastError()));
    return;
  }
  free_entry->event = e;
  free_entry->word.store(key, std::memory_order_release);
}

void FutexWake(std::atomic<uint32_t>* word, int /*n: every waiter passes the wake on*/) {
  HANDLE e = EventOf(word);
  if (e) SetEvent(e);
}

bool FutexWait(std::atomic<uint32_t>* word, uint32_t expected, int64_t timeout_ns) {
  HANDLE e = EventOf(word);
  const uint64_t deadline = timeout_ns >= 0 ? MonotonicNs() + static_cast<uint64_t>(timeout_ns) : 0;
  for (;;) {
    if (word->load(std::memory_order_seq_cst) != expected) return true;
    DWORD ms = INFINITE;
    if (timeout_ns >= 0) {
      const uint64_t now = MonotonicNs();
      if (now >= deadline) return false;
      ms = static_cast<DWORD>((deadline - now + 999999) / 1000000);
    }
    if (!e) {  // no event could be made: poll
      Sleep(1);
      continue;
    }
    const DWORD r = WaitForSingleObject(e, ms);
    if (r == WAIT_OBJECT_0 && word->load(std::memory_order_seq_cst) != expected) {
      SetEvent(e);  // pass the wake on to the next waiter, if any
      return true;
    }
    if (r != WAIT_OBJECT_0 && r != WAIT_TIMEOUT) return true;  // a failed wait: the caller re-checks
  }
}

uint32_t ProcessId() { return static_cast<uint32_t>(GetCurrentProcessId()); }  // read from the TEB

bool ProcessAlive(uint32_t pid) {
  if (pid == 0) return false;
  HANDLE h = OpenProcess(SYNCHRONIZE | PROCESS_QUERY_LIMITED_INFORMATION, FALSE, pid);
  if (!h) return GetLastError() != ERROR_INVALID_PARAMETER;  // access denied: it exists
  const bool alive = WaitForSingleObject(h, 0) == WAIT_TIMEOUT;
  CloseHandle(h);
  return alive;
}

int ShmOpen(const char* name, bool create_exclusive, int /*mode: the session's default DACL*/) {
  if (!create_exclusive) return OpenExisting(name, false);
  char wname[kNameCap];
  if (!WindowsName(name, wname, sizeof wname)) return -ENAMETOOLONG;
  HANDLE existing = OpenFileMappingA(FILE_MAP_READ, FALSE, wname);
  if (existing) {
    CloseHandle(existing);
    return -EEXIST;
  }
  return NewObject(wname, nullptr, true, false);
}

int ShmOpenReadOnly(const char* name) { return OpenExisting(name, true); }

int ShmSetGroup(int fd, int /*gid*/) { return Object(fd) ? 0 : -EBADF; }  // no groups: the DACL decides

int ShmUnlink(const char* /*name*/) { return 0; }

void* MapShared(int fd, size_t size) { return MapObject(fd, size, false); }

const void* MapSharedReadOnly(int fd, size_t size) { return MapObject(fd, size, true); }

void Unmap(void* p, size_t /*size*/) {
  if (!p) return;
  Locked lock;
  for (Mapping& m : g_mappings) {
    char* data = m.data.load(std::memory_order_relaxed);
    if (data != p) continue;
    for (FutexEvent& f : g_futexes) {
      const uintptr_t w = f.word.load(std::memory_order_relaxed);
      if (w >= reinterpret_cast<uintptr_t>(data) && w < reinterpret_cast<uintptr_t>(data + m.size)) {
        f.word.store(0, std::memory_order_release);
        CloseHandle(f.event);
        f.event = nullptr;
      }
    }
    m.data.store(nullptr, std::memory_order_release);
    if (m.section) CloseHandle(m.section);
    m.section = nullptr;
    UnmapViewOfFile(data - kSizePage);
    return;
  }
}

int FileSize(int fd, size_t* size) {
  ShmObject* o = Object(fd);
  if (!o) return -EBADF;
  if (!o->section) {  // created, not yet sized
    *size = 0;
    return 0;
  }
  const void* page = MapViewOfFile(o->section, FILE_MAP_READ, 0, 0, kSizePage);
  if (!page) return -ErrnoOf(GetLastError());
  uint64_t exact;
  memcpy(&exact, page, sizeof exact);
  UnmapViewOfFile(page);
  *size = static_cast<size_t>(exact);
  return 0;
}

int Truncate(int fd, size_t size) {
  ShmObject* o = Object(fd);
  if (!o) return -EBADF;
  if (!o->create_pending) return -EINVAL;  // a mapping's size is fixed when it is made
  const uint64_t total = static_cast<uint64_t>(size) + kSizePage;
  HANDLE h = CreateFileMappingA(INVALID_HANDLE_VALUE, nullptr, PAGE_READWRITE, static_cast<DWORD>(total >> 32),
                                static_cast<DWORD>(total), o->name);
  if (!h) return -ErrnoOf(GetLastError());
  if (GetLastError() == ERROR_ALREADY_EXISTS) {  // made by someone else since ShmOpen
    CloseHandle(h);
    return -EEXIST;
  }
  void* page = MapViewOfFile(h, FILE_MAP_WRITE, 0, 0, kSizePage);
  if (!page) {
    const int e = ErrnoOf(GetLastError());
    CloseHandle(h);
    return -e;
  }
  const uint64_t exact = size;
  memcpy(page, &exact, sizeof exact);  // the rest is zero, as after ftruncate
  UnmapViewOfFile(page);
  o->section = h;
  o->create_pending = false;
  return 0;
}

void CloseFd(int fd) {
  ShmObject* o = Object(fd);
  if (!o) return;
  Locked lock;
  if (o->section) CloseHandle(o->section);
  o->section = nullptr;
  o->in_use = false;
}

// Thread descriptions (SetThreadDescription) need Windows 10 1607 and a wide string; a
// debugger is the only place that shows them: not worth a dependency on the version.
void NameThisThread(const char* /*name*/) {}

int SocketDrops(int /*fd*/, uint32_t* /*drops*/) { return -ENOSYS; }  // Winsock counts none per socket

// Named objects cannot be listed without the native API: ccomm_open() by hostname finds
// the node only when the node is named after the host (or CCOMM_NODE names it).
int ListShm(const char* /*prefix*/, char* /*first*/, size_t /*cap*/) { return 0; }

int ReadRegularFile(const char* path, uint64_t max_bytes, std::string* text, uint64_t* size) {
  const DWORD attributes = GetFileAttributesA(path);
  if (attributes != INVALID_FILE_ATTRIBUTES && (attributes & FILE_ATTRIBUTE_DIRECTORY)) return -EINVAL;
  HANDLE f = CreateFileA(path, GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_WRITE, nullptr, OPEN_EXISTING,
                         FILE_ATTRIBUTE_NORMAL, nullptr);
  if (f == INVALID_HANDLE_VALUE) return -ErrnoOf(GetLastError());
  LARGE_INTEGER li;
  if (GetFileType(f) != FILE_TYPE_DISK || !GetFileSizeEx(f, &li)) {
    CloseHandle(f);
    return -EINVAL;
  }
  *size = static_cast<uint64_t>(li.QuadPart);
  if (*size > max_bytes) {
    CloseHandle(f);
    return -EFBIG;
  }
  text->resize(static_cast<size_t>(*size));
  size_t got = 0;
  while (got < text->size()) {
    DWORD n = 0;
    if (!ReadFile(f, &(*text)[got], static_cast<DWORD>(text->size() - got), &n, nullptr)) {
      CloseHandle(f);
      errno = ErrnoOf(GetLastError());
      return -EIO;
    }
    if (n == 0) break;  // file shrank while reading
    got += n;
  }
  CloseHandle(f);
  text->resize(got);
  return 0;
}

// Windows has no fnmatch: the POSIX rules (flags 0) for * ? [...] [!...] ranges and backslash
// escapes, matched recursively on '*' (patterns are short signal-name globs).
bool GlobMatch(const char* p, const char* n) {
  for (; *p; ++p, ++n) {
    if (*p == '*') {
      while (p[1] == '*') ++p;
      for (const char* rest = n;; ++rest) {
        if (GlobMatch(p + 1, rest)) return true;
        if (!*rest) return false;
      }
    }
    if (!*n) return false;
    if (*p == '?') continue;
    if (*p == '[') {
      const char* q = p + 1;
      const bool negate = *q == '!';
      if (negate) ++q;
      bool in = false;
      const char* start = q;
      for (; *q && (*q != ']' || q == start); ++q) {
        if (q[1] == '-' && q[2] && q[2] != ']') {
          in |= *n >= q[0] && *n <= q[2];
          q += 2;
        } else {
          in |= *n == *q;
        }
      }
      if (!*q) {  // no closing ']': a literal '['
        if (*n != '[') return false;
        continue;
      }
      if (in == negate) return false;
      p = q;
      continue;
    }
    if (*p == '\\' && p[1]) ++p;
    if (*p != *n) return false;
  }
  return !*n;
}

bool HostName(char* buf, size_t cap) {
  DWORD n = static_cast<DWORD>(cap);
  if (!GetComputerNameExA(ComputerNameDnsHostname, buf, &n)) return false;
  buf[cap - 1] = '\0';
  for (char* c = buf; *c; ++c)  // Windows upper-cases NetBIOS names; node names are lower case
    if (*c >= 'A' && *c <= 'Z') *c = static_cast<char>(*c - 'A' + 'a');
  return buf[0] != '\0';
}

bool ParseIpv4(const char* text, uint32_t* network_order) {
  struct in_addr a;
  if (InetPtonA(AF_INET, text, &a) != 1) return false;  // needs no WSAStartup
  *network_order = a.s_addr;
  return true;
}

bool StderrIsJournal() { return false; }  // no journald: the service logs to a file

}  // namespace platform
}  // namespace ccomm
