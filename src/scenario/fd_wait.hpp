#pragma once
// Private to the scenario module: waiting for a file descriptor, shared by
// both sides of the system protocol (process_system.cpp, the host;
// system_protocol.cpp's serve_system, the system).
#include <poll.h>
#include <sched.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::scenario::detail {

/// Waits until `fd` has one of `events` (or a hang-up or error, which the
/// next read or write reports). First `spins` polls that do not sleep, each
/// followed by sched_yield() (the process at the other end may need the
/// core): a short message usually comes within microseconds, and a wake-up
/// from a sleeping poll(2) costs as much again. Then it sleeps in poll(2)
/// until `timeout_s` [s] from the call have passed (< 0: no limit).
/// Returns false when the time ran out; throws Error for a poll error.
inline bool wait_fd(int fd, short events, int spins, double timeout_s) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  pollfd p{fd, events, 0};
  for (int spin = 0; spin < spins; ++spin) {
    if (::poll(&p, 1, 0) > 0) return true;
    ::sched_yield();
  }
  for (;;) {
    int wait_ms = -1;
    if (timeout_s >= 0) {
      const double left = timeout_s - std::chrono::duration<double>(Clock::now() - start).count();
      if (left <= 0) return false;
      wait_ms = static_cast<int>(std::ceil(left * 1000));
    }
    const int r = ::poll(&p, 1, wait_ms);
    if (r > 0) return true;
    if (r < 0 && errno != EINTR) throw Error(std::string("poll: ") + std::strerror(errno));
  }
}

}  // namespace touchdown::scenario::detail
