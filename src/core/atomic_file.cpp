#include "touchdown/core/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown {

namespace {

namespace fs = std::filesystem;

// The kinds of temporary this file's writers make: a file (".NAME.tmp-")
// and a staging directory (".NAME.partial-"); remove_stale_temporaries
// reads the PID back after either.
constexpr const char* kFileKind = ".tmp-";
constexpr const char* kDirectoryKind = ".partial-";

// A temporary path beside `target`: hidden, unique in this process
// (".NAME" + kind + "PID-N"), with `ext` at the end.
fs::path temporary_beside(const fs::path& target, const std::string& ext, const char* kind = kFileKind) {
  static std::atomic<unsigned> counter{0};
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  return dir /
         ("." + target.filename().string() + kind + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ext);
}

// IoError unless `target` can be written: its directory exists, `target` is
// not a directory. `what` prefixes the message ("--plot: out/p.svg").
void check_writable(const fs::path& target, const std::string& what, bool need_write_access) {
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw IoError(what + ": output directory '" + dir.string() + "' does not exist");
  if (fs::is_directory(target, ec)) throw IoError(what + ": is a directory");
  if (need_write_access && ::access(dir.c_str(), W_OK) != 0) {
    throw IoError(what + ": output directory '" + dir.string() + "' is not writable");
  }
}

std::mutex& live_mutex() {
  static std::mutex m;
  return m;
}

std::vector<fs::path>& live_temporaries() {
  static std::vector<fs::path> list;
  return list;
}

// Removes `tmp` and takes it off the live list.
void discard(const fs::path& tmp) {
  std::error_code ec;
  fs::remove_all(tmp, ec);
  unregister_temporary(tmp);
}

// The PID in a temporary's name after `prefix` (".NAME.tmp-" or
// ".NAME.partial-"), or 0 when the rest is not "PID-N...".
pid_t pid_after(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  std::size_t i = prefix.size();
  long long pid = 0;
  const std::size_t digits_start = i;
  while (i < name.size() && name[i] >= '0' && name[i] <= '9' && i - digits_start < 10)
    pid = pid * 10 + (name[i++] - '0');
  if (i == digits_start || i >= name.size() || name[i] != '-' || pid <= 0) return 0;
  return static_cast<pid_t>(pid);
}

}  // namespace

void register_temporary(const fs::path& path) {
  const std::lock_guard lock(live_mutex());
  live_temporaries().push_back(path);
}

void unregister_temporary(const fs::path& path) {
  const std::lock_guard lock(live_mutex());
  auto& list = live_temporaries();
  const auto it = std::find(list.begin(), list.end(), path);
  if (it != list.end()) list.erase(it);
}

std::size_t remove_live_temporaries() noexcept {
  const std::lock_guard lock(live_mutex());
  auto& list = live_temporaries();
  std::size_t n = 0;
  for (const fs::path& p : list) {
    std::error_code ec;
    if (fs::remove_all(p, ec) > 0 && !ec) ++n;  // a registered one may not be created yet
  }
  list.clear();
  return n;
}

std::vector<fs::path> remove_stale_temporaries(const fs::path& target) noexcept {
  std::vector<fs::path> removed;
  try {
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const std::string name = target.filename().string();
    if (name.empty()) return removed;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string entry = it->path().filename().string();
      pid_t pid = pid_after(entry, "." + name + kFileKind);
      if (pid == 0) pid = pid_after(entry, "." + name + kDirectoryKind);
      // Only a process that is gone: kill(pid, 0) fails with ESRCH.
      if (pid == 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
      std::error_code rm;
      fs::remove_all(it->path(), rm);
      if (!rm) removed.push_back(it->path());
    }
  } catch (...) {
    // Best effort: a directory that cannot be listed keeps what it holds.
  }
  return removed;
}

void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& write) {
  check_writable(target, target.string(), false);
  (void)remove_stale_temporaries(target);
  const fs::path tmp = temporary_beside(target, "");
  register_temporary(tmp);
  try {
    write(tmp);
  } catch (...) {
    discard(tmp);
    throw;
  }
  if (std::rename(tmp.c_str(), target.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    discard(tmp);
    throw IoError(target.string() + ": cannot rename the finished output into place: " + why);
  }
  unregister_temporary(tmp);
}

StagedOutputs::~StagedOutputs() {
  for (const Entry& e : entries_) {
    if (committed_) {
      unregister_temporary(e.tmp);
    } else {
      discard(e.tmp);
    }
  }
}

fs::path StagedOutputs::add(const fs::path& target, const std::string& label) {
  const std::string what = label.empty() ? target.string() : label + ": " + target.string();
  check_writable(target, what, true);
  std::error_code ec;
  fs::path identity = fs::weakly_canonical(target, ec);
  if (ec) identity = fs::absolute(target).lexically_normal();
  for (const Entry& e : entries_) {
    if (e.identity == identity) {
      throw IoError(what + ": is also the output of " + (e.label.empty() ? e.target.string() : e.label));
    }
  }
  (void)remove_stale_temporaries(target);
  entries_.push_back({target, temporary_beside(target, target.extension().string()), identity, label});
  register_temporary(entries_.back().tmp);
  return entries_.back().tmp;
}

StagedDirectory::StagedDirectory(const fs::path& target) : target_(target.lexically_normal()) {
  if (!target_.has_filename()) target_ = target_.parent_path();
  if (target_.empty()) throw IoError("empty output directory name");
  const fs::path parent = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(parent, ec)) {
    throw IoError(target_.string() + ": output directory '" + parent.string() + "' does not exist");
  }
  (void)remove_stale_temporaries(target_);  // what a killed run left
  staging_ = temporary_beside(target_, "", kDirectoryKind);
  fs::remove_all(staging_, ec);
  // Registered before it exists: a signal between its creation and its
  // registration left it behind (an interrupt that came just as it appeared).
  register_temporary(staging_);
  if (!fs::create_directory(staging_, ec) || ec) {
    unregister_temporary(staging_);
    throw IoError(staging_.string() + ": cannot create the staging directory: " + ec.message());
  }
}

StagedDirectory::~StagedDirectory() {
  if (committed_) {
    unregister_temporary(staging_);
  } else {
    discard(staging_);
  }
}

void StagedDirectory::commit() {
  std::error_code ec;
  if (fs::exists(target_, ec)) throw IoError(target_.string() + ": exists (the output goes into a new directory)");
  fs::rename(staging_, target_, ec);
  if (ec) throw IoError(target_.string() + ": cannot rename the finished output into place: " + ec.message());
  committed_ = true;
}

void StagedOutputs::commit() {
  std::error_code ec;
  for (const Entry& e : entries_) {
    if (!fs::exists(e.tmp, ec)) continue;
    if (std::rename(e.tmp.c_str(), e.target.c_str()) != 0) {
      throw IoError(e.target.string() + ": cannot rename the finished output into place: " + std::strerror(errno));
    }
  }
  committed_ = true;
}

}  // namespace touchdown
