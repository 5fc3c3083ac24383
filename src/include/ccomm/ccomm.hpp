// SPDX-License-Identifier: Apache-2.0
// ccomm C++ API: RAII and typed access, a thin header-only layer over ccomm.h.
//
//   ccomm::Client client;                       // node from $CCOMM_NODE or hostname
//   if (!client.ok()) { /* client.error() */ }
//   auto pos = client.signal<double>("wheel0_pos");     // start-up: find + type check
//   auto sp  = client.signal<double>("wheel0_vel_sp");
//   for (;;) {                                          // real-time loop
//     pos.write(measured);
//     ccomm::Reading<double> r = sp.read();             // r.value, r.fresh(), r.status
//   }
//
// No exceptions: failures are reported through ok()/error(), as the loop code that
// uses it is usually built with -fno-exceptions. It covers the C API one to one: batch
// (Client flags, flush()), history (Signal::history()), statistics and introspection
// (Signal::stats(), Client::describe(), peer_stats()); raw() for anything else.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "ccomm/ccomm.h"

namespace ccomm {

template <typename T> struct TypeCode;
template <> struct TypeCode<bool> { static constexpr int value = CCOMM_BOOL; };
template <> struct TypeCode<int32_t> { static constexpr int value = CCOMM_INT32; };
template <> struct TypeCode<uint32_t> { static constexpr int value = CCOMM_UINT32; };
template <> struct TypeCode<int64_t> { static constexpr int value = CCOMM_INT64; };
template <> struct TypeCode<float> { static constexpr int value = CCOMM_FLOAT; };
template <> struct TypeCode<double> { static constexpr int value = CCOMM_DOUBLE; };

template <typename T> struct Element { using type = T; static constexpr size_t count = 1; };
template <typename T, size_t N> struct Element<std::array<T, N>> { using type = T; static constexpr size_t count = N; };

static_assert(sizeof(bool) == 1, "bool signals are one byte in shared memory");

/// A value with its freshness.
template <typename T>
struct Reading {
  T value{};
  ccomm_info info{};
  int status = CCOMM_NEVER;  // ccomm_status (>= 0) or error (< 0); Reading.status in Python
  bool fresh() const { return status == CCOMM_FRESH; }
  bool stale() const { return status == CCOMM_STALE; }
  bool never() const { return status == CCOMM_NEVER; }
  bool empty() const { return status == CCOMM_EMPTY; }
  bool error() const { return status < 0; }
};

/// One value from a history (see History).
template <typename T>
struct HistoryReading {
  T value{};
  ccomm_history_info info{};
  int status = CCOMM_EMPTY;  // CCOMM_FRESH: a value; CCOMM_EMPTY: caught up; < 0: error
  bool empty() const { return status == CCOMM_EMPTY; }
  bool error() const { return status < 0; }
};

/// A reader's cursor over the history of a received state (ccomm_history_*; needs
/// <node history="N">). Get one with Signal::history(). Real-time safe reads.
template <typename T>
class History {
 public:
  History() = default;
  History(ccomm_client* c, ccomm_signal id, uint32_t back) : client_(c), id_(id) {
    status_ = ccomm_history_start(c, id, back, &cursor_);
  }
  /// 0, or why the history could not start (CCOMM_E_NOENT: the node keeps none of it).
  int status() const { return status_; }
  /// The next value, or empty() when this reader has caught up.
  HistoryReading<T> read() {
    HistoryReading<T> r;
    r.status = status_ < 0 ? status_ : ccomm_history_read(client_, id_, &cursor_, &r.value, sizeof(T), &r.info);
    return r;
  }
  /// Values this reader missed by falling more than the depth behind.
  uint64_t overrun() const { return cursor_.overrun; }
  int depth() const { return ccomm_history_depth(client_, id_); }

 private:
  ccomm_client* client_ = nullptr;
  ccomm_signal id_ = CCOMM_E_INVAL;
  ccomm_history_cursor cursor_{};
  int status_ = CCOMM_E_INVAL;
};

/// A typed signal handle. T is a scalar (bool, int32_t, uint32_t, int64_t, float,
/// double) or std::array of one, matching the signal's type and count.
template <typename T>
class Signal {
 public:
  Signal() = default;
  Signal(ccomm_client* c, ccomm_signal id) : client_(c), id_(id) {}
  bool valid() const { return client_ && id_ >= 0; }
  ccomm_signal id() const { return id_; }

  /// Real-time safe.
  Reading<T> read() const {
    Reading<T> r;
    r.status = ccomm_read(client_, id_, &r.value, sizeof(T), &r.info);
    return r;
  }
  /// Real-time safe. Returns 0 or a CCOMM_E_* error.
  int write(const T& v) const { return ccomm_write(client_, id_, &v, sizeof(T)); }
  /// Every value of this received state from `back` values before the next one on.
  History<T> history(uint32_t back = 1) const { return History<T>(client_, id_, back); }
  /// ccommd's counters of this signal on this node; 0 or CCOMM_E_INVAL.
  int stats(ccomm_signal_stats& out) const { return ccomm_get_signal_stats(client_, id_, &out); }

 private:
  ccomm_client* client_ = nullptr;
  ccomm_signal id_ = CCOMM_E_INVAL;
};

namespace detail {
/// A C handle owned by one object (move-only; the close call runs once), and the error
/// of the call that opened it (or, for Client, of the last signal()).
// The close call of each handle (a function, not a pointer template argument: a DLL's
// imported function has no constant address on Windows).
template <typename H> struct Closer;
template <> struct Closer<ccomm_client> { static void Close(ccomm_client* c) { ccomm_close(c); } };
template <> struct Closer<ccomm_view> { static void Close(ccomm_view* v) { ccomm_view_close(v); } };

template <typename H>
class Owned {
 public:
  Owned(const Owned&) = delete;
  Owned& operator=(const Owned&) = delete;

 protected:
  Owned() = default;
  ~Owned() { Closer<H>::Close(h_); }
  Owned(Owned&& o) noexcept : h_(std::exchange(o.h_, nullptr)), error_(o.error_) {}
  Owned& operator=(Owned&& o) noexcept {
    if (this != &o) {
      Closer<H>::Close(h_);
      h_ = std::exchange(o.h_, nullptr);
      error_ = o.error_;
    }
    return *this;
  }
  H* h_ = nullptr;
  int error_ = 0;
};
}  // namespace detail

class Client : private detail::Owned<ccomm_client> {
 public:
  explicit Client(const char* node = nullptr, uint32_t flags = 0) { error_ = ccomm_open(node, flags, &h_); }
  Client(Client&&) noexcept = default;
  Client& operator=(Client&&) noexcept = default;

  bool ok() const { return h_ != nullptr; }
  /// Why the open or the last signal() failed (a CCOMM_E_* code; 0: it did not).
  int error() const { return error_; }
  const char* error_text() const { return ccomm_strerror(error_); }
  ccomm_client* raw() const { return h_; }
  const char* node() const { return ccomm_node_name(h_); }

  /// Finds `name` and checks that it is a T. An invalid Signal (valid() == false) if
  /// not; error() says why. Start-up only.
  template <typename T>
  Signal<T> signal(const char* name) {
    using E = typename Element<T>::type;
    ccomm_signal id = ccomm_find(h_, name);
    if (id < 0) { error_ = id; return Signal<T>(); }
    ccomm_signal_desc d;
    ccomm_describe(h_, id, &d);
    if (d.type != TypeCode<E>::value || d.count != Element<T>::count) { error_ = CCOMM_E_TYPE; return Signal<T>(); }
    error_ = 0;  // error() is about the last signal(): an earlier failure no longer counts
    return Signal<T>(h_, id);
  }

  /// Cycle time for this handle's reads and writes (see ccomm_set_time); 0 = per call.
  void set_time(int64_t t_ns) { ccomm_set_time(h_, t_ns); }
  static int64_t now() { return ccomm_now(); }
  /// Real-time set-up of the calling thread (ccomm_realtime_setup; cpu < 0 and 0 leave a part).
  static int realtime_setup(int32_t cpu, bool lock_memory, int32_t fifo_priority, int32_t errors[3] = nullptr) {
    return ccomm_realtime_setup(cpu, lock_memory ? 1 : 0, fifo_priority, errors);
  }
  /// Sleeps until ccomm_now() reaches deadline_ns (ccomm_sleep_until): 0, or 1 after a signal.
  static int sleep_until(int64_t deadline_ns) { return ccomm_sleep_until(deadline_ns); }

  /// Blocks until something changes (non-real-time consumers).
  bool wait(int timeout_ms) { return ccomm_wait(h_, timeout_ms) == 1; }
  bool daemon_alive() const { return ccomm_daemon_alive(h_) == 1; }
  /// Opened with CCOMM_OPEN_BATCH: hands this step's writes to ccommd at once (call it at
  /// the end of each cycle); 0 or CCOMM_E_BUSY. Real-time safe.
  int flush() { return ccomm_flush(h_); }

  /// Introspection (not real-time): the system's signals and nodes, and the counters.
  int signal_count() const { return ccomm_signal_count(h_); }
  int describe(ccomm_signal id, ccomm_signal_desc& out) const { return ccomm_describe(h_, id, &out); }
  int node_count() const { return ccomm_node_count(h_); }
  int peer_stats(int node, ccomm_peer_stats& out) const { return ccomm_get_peer_stats(h_, node, &out); }

};

/// The system view (ccomm_view_*): every node as its summaries describe it, and the
/// production age of a value read here. Open it once at start-up; the client must
/// outlive it.
class SystemView : private detail::Owned<ccomm_view> {
 public:
  explicit SystemView(const Client& c) { error_ = ccomm_view_open(c.raw(), &h_); }
  SystemView(SystemView&&) noexcept = default;
  SystemView& operator=(SystemView&&) noexcept = default;
  bool ok() const { return h_ != nullptr; }
  int error() const { return error_; }  // CCOMM_E_NOENT: no ccommd (or none with a view)
  ccomm_view* raw() const { return h_; }

  /// Node `n` (not real-time: may wait up to ~50 ms for a record being rewritten).
  int node(int n, ccomm_view_node& out) const { return ccomm_view_get_node(h_, n, &out); }
  /// How long ago the producer wrote the value `r` holds, with its error bound, or why
  /// that is unknown (ccomm_view_production_age; bounded, allocation-free).
  template <typename T>
  ccomm_production_age production_age(const Signal<T>& s, const Reading<T>& r) const {
    ccomm_production_age a{};
    a.code = CCOMM_PAGE_NO_SUMMARY;
    a.age_ns = a.error_ns = a.production_time_ns = -1;
    if (ccomm_view_production_age(h_, s.id(), &r.info, &a) != 0) a.known = 0;
    return a;
  }

};

}  // namespace ccomm
