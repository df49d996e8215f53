#include "touchdown/core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown {

void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& write) {
  namespace fs = std::filesystem;
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw IoError(target.string() + ": output directory '" + dir.string() + "' does not exist");
  }
  if (fs::is_directory(target, ec)) {
    throw IoError(target.string() + ": is a directory");
  }
  static std::atomic<unsigned> counter{0};
  const fs::path tmp =
      dir / ("." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
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

}  // namespace touchdown
