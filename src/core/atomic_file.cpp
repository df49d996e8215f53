#include "touchdown/core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown {

namespace {

namespace fs = std::filesystem;

// A temporary path beside `target`: hidden, unique in this process, with
// `ext` at the end.
fs::path temporary_beside(const fs::path& target, const std::string& ext) {
  static std::atomic<unsigned> counter{0};
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  return dir / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter++) + ext);
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

}  // namespace

void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& write) {
  check_writable(target, target.string(), false);
  const fs::path tmp = temporary_beside(target, "");
  std::error_code ec;
  try {
    write(tmp);
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  if (std::rename(tmp.c_str(), target.c_str()) != 0) {
    const std::string why = std::strerror(errno);
    fs::remove(tmp, ec);
    throw IoError(target.string() + ": cannot rename the finished output into place: " + why);
  }
}

StagedOutputs::~StagedOutputs() {
  if (committed_) return;
  std::error_code ec;
  for (const Entry& e : entries_) fs::remove(e.tmp, ec);
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
  entries_.push_back({target, temporary_beside(target, target.extension().string()), identity, label});
  return entries_.back().tmp;
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
