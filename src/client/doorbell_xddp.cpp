// SPDX-License-Identifier: Apache-2.0
// Doorbell under Xenomai 3 (Cobalt, POSIX skin), see doorbell.h and docs/design.md
// "Xenomai". A FUTEX_WAKE is a Linux syscall: from a primary-mode thread it would switch
// the caller to secondary mode. Here the real-time side only makes Cobalt calls on an
// XDDP socket (cross-domain datagrams); a Linux relay thread of the same process reads
// the other end, /dev/rtpN, and makes the FUTEX_WAKEs ccommd already sleeps on, so
// ccommd is unchanged.
//   ring:  writer bumps the word (as on Linux); if ccommd sleeps or someone waits, it
//          sends kRing (non-blocking). The relay wakes whichever bell is pending, so a
//          message dropped on a full pool loses nothing: the queued ones ring it.
//   wait:  ccomm_wait() sends kWait {seen, timeout, seq} and blocks in recvfrom() (a
//          Cobalt call: it stays in primary mode); the relay sleeps in FUTEX_WAIT for
//          it and answers with seq. A handle serves one thread at a time, so no ring of
//          this handle arrives while the relay waits.
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <sys/socket.h>
#include <unistd.h>

#include <rtdm/ipc.h>

#include <new>

#include "client/doorbell.h"
#include "common/platform.h"

namespace ccomm {
namespace client {

namespace {

enum MessageKind : uint32_t { kRing = 1, kWait = 2, kQuit = 3 };

struct Message {
  uint32_t kind;
  uint32_t seen;       // kWait: rx_doorbell as the waiter last saw it
  int64_t timeout_ns;  // kWait: < 0 = no limit
  uint64_t seq;        // kWait: echoed in the answer
};

// The XDDP pool holds this many queued messages; more rings than this while the relay
// is behind are dropped (harmless, see above).
constexpr size_t kPoolBytes = 64 * sizeof(Message);

}  // namespace

struct Doorbell {
  const store::Segment* segment;
  int rt_socket = -1;  // Cobalt XDDP socket: the real-time end
  int relay_fd = -1;   // /dev/rtpN: the Linux end, read by the relay thread
  uint64_t wait_seq = 0;
  pthread_t relay;
  bool relay_started = false;
};

namespace {

// Rings every bell that has someone to wake: ccommd's send thread if it sleeps,
// ccomm_wait() callers if any. The writer bumped the word before sending.
void RingPending(const store::SegmentHeader* h) {
  auto* hh = const_cast<store::SegmentHeader*>(h);
  if (hh->tx_sleeping.load(std::memory_order_seq_cst)) platform::FutexWake(&hh->tx_doorbell, 1);
  if (hh->rx_waiters.load(std::memory_order_seq_cst)) platform::FutexWake(&hh->rx_doorbell, 1 << 30);
}

// The relay: a plain Linux thread (created with the unwrapped pthread_create, using the
// unwrapped read/write), so its syscalls never involve the Cobalt scheduler.
void* Relay(void* arg) {
  Doorbell* d = static_cast<Doorbell*>(arg);
  store::SegmentHeader* h = d->segment->header();
  Message m;
  for (;;) {
    ssize_t n = __STD(read)(d->relay_fd, &m, sizeof m);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;                                  // the real-time end is gone
    if (n != static_cast<ssize_t>(sizeof m)) continue;  // not a message of ours: ignored
    if (m.kind == kQuit) break;
    if (m.kind == kWait) {
      platform::FutexWait(&h->rx_doorbell, m.seen, m.timeout_ns);
      while (__STD(write)(d->relay_fd, &m.seq, sizeof m.seq) < 0 && errno == EINTR) {
      }
    } else {
      RingPending(h);
    }
  }
  return nullptr;
}

// [rt] Queues a ring for the relay; never blocks (a full pool means rings are queued).
void SendRing(Doorbell* d) {
  Message m{kRing, 0, 0, 0};
  __RT(sendto)(d->rt_socket, &m, sizeof m, MSG_DONTWAIT, nullptr, 0);
}

}  // namespace

int DoorbellOpen(const store::Segment& segment, Doorbell** out) {
  *out = nullptr;
  Doorbell* d = new (std::nothrow) Doorbell{&segment};
  if (!d) return -ENOMEM;
  int err = 0;
  sockaddr_ipc addr{};
  socklen_t addr_len = sizeof addr;
  size_t pool = kPoolBytes;
  char dev[32];
  d->rt_socket = __RT(socket)(AF_RTIPC, SOCK_DGRAM, IPCPROTO_XDDP);
  if (d->rt_socket < 0) goto fail;
  // A private pool: this handle's rings cannot exhaust the Cobalt heap.
  if (__RT(setsockopt)(d->rt_socket, SOL_XDDP, XDDP_POOLSZ, &pool, sizeof pool) != 0) goto fail;
  addr.sipc_family = AF_RTIPC;
  addr.sipc_port = -1;  // any free port; its /dev/rtpN is learnt below
  if (__RT(bind)(d->rt_socket, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) goto fail;
  if (__RT(getsockname)(d->rt_socket, reinterpret_cast<sockaddr*>(&addr), &addr_len) != 0) goto fail;
  snprintf(dev, sizeof dev, "/dev/rtp%d", static_cast<int>(addr.sipc_port));
  d->relay_fd = __STD(open)(dev, O_RDWR | O_CLOEXEC);
  if (d->relay_fd < 0) goto fail;
  {
    // The relay takes no process signals: they belong to the application's threads.
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    err = __STD(pthread_create)(&d->relay, nullptr, Relay, d);
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    if (err != 0) {
      errno = err;
      goto fail;
    }
    d->relay_started = true;
  }
  *out = d;
  return 0;
fail:
  err = errno ? errno : EIO;
  DoorbellClose(d);
  return -err;
}

void DoorbellClose(Doorbell* d) {
  if (!d) return;
  if (d->relay_started) {
    Message m{kQuit, 0, 0, 0};
    __RT(sendto)(d->rt_socket, &m, sizeof m, 0, nullptr, 0);
    __STD(pthread_join)(d->relay, nullptr);
  }
  if (d->relay_fd >= 0) __STD(close)(d->relay_fd);
  if (d->rt_socket >= 0) __RT(close)(d->rt_socket);
  delete d;
}

void DoorbellRingTx(Doorbell* d) {
  store::SegmentHeader* h = d->segment->header();
  h->tx_doorbell.fetch_add(1, std::memory_order_seq_cst);
  if (h->tx_sleeping.load(std::memory_order_seq_cst)) SendRing(d);
}

void DoorbellNotifyTx(Doorbell* d, uint32_t id, bool wake) {
  d->segment->MarkDirty(id);
  if (wake) {
    DoorbellRingTx(d);
  } else {
    d->segment->header()->tx_doorbell.fetch_add(1, std::memory_order_release);
  }
}

void DoorbellNotifyRx(Doorbell* d) {
  store::SegmentHeader* h = d->segment->header();
  // Same Dekker pairing as store::Segment::NotifyRx: the caller published with a
  // seq_cst RMW, so this load sees a waiter that registered before it looked.
  if (!h->rx_waiters.load(std::memory_order_seq_cst)) return;
  h->rx_doorbell.fetch_add(1, std::memory_order_seq_cst);
  SendRing(d);
}

void DoorbellWait(Doorbell* d, uint32_t seen, int64_t timeout_ns) {
  Message m{kWait, seen, timeout_ns, ++d->wait_seq};
  if (__RT(sendto)(d->rt_socket, &m, sizeof m, 0, nullptr, 0) != static_cast<ssize_t>(sizeof m)) return;
  // Answers to earlier waits cut short (a signal) come first: skip them.
  uint64_t answer = 0;
  do {
    if (__RT(recvfrom)(d->rt_socket, &answer, sizeof answer, 0, nullptr, nullptr) != sizeof answer) return;
  } while (answer < m.seq);
}

}  // namespace client
}  // namespace ccomm
