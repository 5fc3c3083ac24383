// SPDX-License-Identifier: Apache-2.0
// For concurrency tests that let threads race for a while: on a loaded 2-CPU machine a
// thread can be starved for hundreds of milliseconds (CI once saw a writer thread make no
// write in 300 ms), so "run 300 ms, then expect progress" fails for the wrong reason.
#pragma once

#include <chrono>
#include <thread>

namespace ccomm {
namespace test_threads {  // not `testing`: that would hide gtest's ::testing in ccomm::* test code

/// Sleeps at least `at_least`, then on until `enough()` holds, at most `give_up` in all.
template <typename Enough>
void SleepUntilEnough(std::chrono::milliseconds at_least, Enough enough,
                      std::chrono::milliseconds give_up = std::chrono::milliseconds(10000)) {
  const auto start = std::chrono::steady_clock::now();
  std::this_thread::sleep_for(at_least);
  while (!enough() && std::chrono::steady_clock::now() - start < give_up)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

}  // namespace test_threads
}  // namespace ccomm
