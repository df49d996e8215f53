#include "io_util.hpp"

#include <cerrno>
#include <cstring>
#include <iterator>

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

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in = open_for_read(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw IoError(path.string() + ": read error");
  return text;
}

void write_text_file(const std::filesystem::path& path, std::string_view text, const std::string& shown) {
  const std::string name = shown.empty() ? path.string() : shown;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(name + ": cannot write");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.flush();
  if (!out) throw IoError(name + ": write failed");
}

}  // namespace touchdown::detail
