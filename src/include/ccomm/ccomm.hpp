// SPDX-License-Identifier: Apache-2.0
// ccomm C++ API: RAII and typed access, a thin header-only layer over ccomm.h.
//
//   ccomm::Client client;                       // node from $CCOMM_NODE or hostname
//   if (!client.ok()) { /* client.error() */ }
//   auto pos = client.signal<double>("wheel0_pos");     // start-up: find + type check
//   auto sp  = client.signal<double>("wheel0_vel_sp");
//   for (;;) {                                          // real-time loop
//     pos.write(measured);
//     ccomm::Reading<double> r = sp.read();             // r.value, r.fresh(), r.info
//   }
//
// No exceptions: failures are reported through ok()/error(), as the loop code that
// uses it is usually built with -fno-exceptions.
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
  int code = CCOMM_NEVER;  // ccomm_status (>= 0) or error (< 0)
  bool fresh() const { return code == CCOMM_FRESH; }
  bool stale() const { return code == CCOMM_STALE; }
  bool never() const { return code == CCOMM_NEVER; }
  bool empty() const { return code == CCOMM_EMPTY; }
  bool error() const { return code < 0; }
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
    r.code = ccomm_read(client_, id_, &r.value, sizeof(T), &r.info);
    return r;
  }
  /// Real-time safe. Returns 0 or a CCOMM_E_* error.
  int write(const T& v) const { return ccomm_write(client_, id_, &v, sizeof(T)); }

 private:
  ccomm_client* client_ = nullptr;
  ccomm_signal id_ = CCOMM_E_INVAL;
};

class Client {
 public:
  explicit Client(const char* node = nullptr, uint32_t flags = 0) { error_ = ccomm_open(node, flags, &c_); }
  ~Client() { ccomm_close(c_); }
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;
  Client(Client&& o) noexcept : c_(std::exchange(o.c_, nullptr)), error_(o.error_) {}
  Client& operator=(Client&& o) noexcept {
    if (this != &o) {
      ccomm_close(c_);
      c_ = std::exchange(o.c_, nullptr);
      error_ = o.error_;
    }
    return *this;
  }

  bool ok() const { return c_ != nullptr; }
  int error() const { return error_; }
  const char* error_text() const { return ccomm_strerror(error_); }
  ccomm_client* raw() const { return c_; }
  const char* node() const { return ccomm_node_name(c_); }

  /// Finds `name` and checks that it is a T. An invalid Signal (valid() == false) if
  /// not; last_error() says why. Start-up only.
  template <typename T>
  Signal<T> signal(const char* name) {
    using E = typename Element<T>::type;
    ccomm_signal id = ccomm_find(c_, name);
    if (id < 0) { error_ = id; return Signal<T>(); }
    ccomm_signal_desc d;
    ccomm_describe(c_, id, &d);
    if (d.type != TypeCode<E>::value || d.count != Element<T>::count) { error_ = CCOMM_E_TYPE; return Signal<T>(); }
    return Signal<T>(c_, id);
  }
  int last_error() const { return error_; }

  /// Cycle time for this handle's reads and writes (see ccomm_set_time); 0 = per call.
  void set_time(int64_t t_ns) { ccomm_set_time(c_, t_ns); }
  static int64_t now() { return ccomm_now(); }

  /// Blocks until something changes (non-real-time consumers).
  bool wait(int timeout_ms) { return ccomm_wait(c_, timeout_ms) == 1; }
  bool daemon_alive() const { return ccomm_daemon_alive(c_) == 1; }

 private:
  ccomm_client* c_ = nullptr;
  int error_ = 0;
};

}  // namespace ccomm
