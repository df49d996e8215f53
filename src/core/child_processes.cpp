// The registry of live child process groups (child_processes.hpp).
#include "touchdown/core/child_processes.hpp"

#include <algorithm>
#include <csignal>
#include <mutex>
#include <vector>

namespace touchdown {
namespace {

std::mutex& groups_mutex() {
  static std::mutex m;
  return m;
}
std::vector<pid_t>& groups() {
  static std::vector<pid_t> g;
  return g;
}

}  // namespace

void register_process_group(pid_t pgid) noexcept {
  if (pgid <= 0) return;
  try {
    const std::lock_guard lock(groups_mutex());
    groups().push_back(pgid);
  } catch (...) {  // out of memory: the group is still killed by its owner
  }
}

void unregister_process_group(pid_t pgid) noexcept {
  const std::lock_guard lock(groups_mutex());
  auto& g = groups();
  const auto it = std::find(g.begin(), g.end(), pgid);
  if (it != g.end()) g.erase(it);
}

std::size_t kill_live_process_groups() noexcept {
  const std::lock_guard lock(groups_mutex());
  for (const pid_t pgid : groups()) ::kill(-pgid, SIGKILL);
  return groups().size();
}

}  // namespace touchdown
