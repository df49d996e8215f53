#include "io_util.hpp"

#include <cerrno>
#include <cstring>

namespace touchdown::detail {

std::ifstream open_for_read(const std::filesystem::path& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    throw IoError(path.string() + ": cannot open: no such file");
  }
  if (std::filesystem::is_directory(status)) {
    throw IoError(path.string() + ": cannot open: is a directory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path.string() + ": cannot open: " + std::strerror(errno));
  }
  return in;
}

}  // namespace touchdown::detail
