#pragma once
/// \file
/// Process groups that library objects started (an `exec:` landing system
/// runs in a group of its own, with whatever it starts): registered while
/// they live, so that an app ending by a signal ends them too. The apps call
/// kill_live_process_groups() from their signal thread (apps/app_common.hpp)
/// before they end; the objects themselves kill their group when they stop.
/// Thread-safe.
#include <sys/types.h>

#include <cstddef>

namespace touchdown {

void register_process_group(pid_t pgid) noexcept;
void unregister_process_group(pid_t pgid) noexcept;
/// SIGKILL to every registered group; how many there were.
std::size_t kill_live_process_groups() noexcept;

}  // namespace touchdown
