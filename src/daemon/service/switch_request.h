// SPDX-License-Identifier: Apache-2.0
// A switch at an agreed instant (ccomm deploy's second phase; docs/usage.md, "Deploy to
// every board"). `ccommd -c CONFIG --reload PID --at T` checks CONFIG.staged, leaves T in
// CONFIG.staged.at and asks ccommd PID (stop_request.h, Request::kReloadAt). ccommd reads
// and checks the staged file at once and answers "armed"; at T on its CLOCK_REALTIME it
// switches, unless the staged file was removed or changed meanwhile (that is how deploy
// aborts). Once applied, the requester keeps CONFIG as CONFIG.previous and moves
// CONFIG.staged over CONFIG, so the file in place is the one that runs. Parsing and
// checking happen before T: boards whose clocks agree switch within the swap's own time.
#pragma once

#include <stdint.h>

#include <string>

namespace ccomm {
namespace switch_at {

std::string StagedPath(const std::string& config);   ///< CONFIG.staged
std::string InstantPath(const std::string& config);  ///< CONFIG.staged.at

/// T as given to --at: seconds since the epoch with up to 9 decimals ("1764748800.25"),
/// in ns; 0 if the text is not that.
uint64_t ParseInstant(const char* text);

/// The instant CONFIG.staged.at holds, in ns; 0 (and *why) when there is none.
uint64_t ReadInstant(const std::string& config, std::string* why);

/// The requester side: checks CONFIG.staged, asks ccommd `pid`, prints "armed T" and then
/// "switched T APPLIED" (ns) on stdout, moves the files once applied. The exit status:
/// 0 switched, 1 refused / cancelled / not applied (the log says why).
int Request(const std::string& config, int pid, uint64_t at_ns);

}  // namespace switch_at
}  // namespace ccomm
