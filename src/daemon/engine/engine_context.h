// SPDX-License-Identifier: Apache-2.0
// What the engine's three thread-owning parts share (the send part, send_path.h; the
// receive part, receive_path.h; supervision, supervisor.h): Daemon owns each of these
// and hands every part one EngineContext at construction, so that no part keeps its own
// list of references. Who may touch what from which thread is said where each is
// declared (thread_handoffs.h for what the threads hand each other).
#pragma once

namespace ccomm {

namespace store {
class Segment;
}
namespace auth {
class FrameAuth;
}
struct Transport;
class SystemViewWriter;
struct ThreadHandoffs;
class PreparedSignals;

struct EngineContext {
  store::Segment& segment;          // this node's segment (created or adopted in Start)
  Transport& transport;             // the open socket (none on a local-only node)
  const auth::FrameAuth& auth;      // per-frame MAC (off unless auth_key_file is set)
  SystemViewWriter& view;           // the system view: node summaries out and in
  ThreadHandoffs& handoffs;         // what the threads hand each other
  const PreparedSignals& table;     // the prepared signals, constant while the threads run
};

}  // namespace ccomm
