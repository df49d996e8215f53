#include "touchdown/core/data_path.hpp"

#include <cstdlib>
#include <system_error>

#include "touchdown/core/error.hpp"

namespace touchdown {

namespace fs = std::filesystem;

namespace {

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

bool is_dir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

void add_unique(std::vector<fs::path>& list, const fs::path& p) {
  const fs::path n = p.lexically_normal();
  for (const auto& q : list) {
    if (q == n) return;
  }
  list.push_back(n);
}

}  // namespace

std::vector<fs::path> data_directories() {
  std::vector<fs::path> out;
  if (const char* env = std::getenv("TOUCHDOWN_DATA"); env != nullptr && *env != '\0' && is_dir(env)) {
    add_unique(out, env);
  }
#ifdef TOUCHDOWN_INSTALL_DATA_DIR
  if (is_dir(TOUCHDOWN_INSTALL_DATA_DIR)) add_unique(out, TOUCHDOWN_INSTALL_DATA_DIR);
#endif
#ifdef TOUCHDOWN_SOURCE_DATA_DIR
  if (is_dir(TOUCHDOWN_SOURCE_DATA_DIR)) add_unique(out, TOUCHDOWN_SOURCE_DATA_DIR);
#endif
  return out;
}

fs::path resolve_data_file(const fs::path& base, const std::string& name, const std::string& kind_dir) {
  const fs::path written(name);
  if (name.empty()) throw IoError("empty file name");
  if (written.is_absolute()) {
    if (is_file(written)) return written;
    throw IoError(name + ": cannot open: " + (is_dir(written) ? "is a directory" : "no such file"));
  }
  std::vector<fs::path> tried;
  add_unique(tried, base / written);
  // The name without its leading "./" and "../" parts: what it names
  // inside a data tree laid out as data/ is.
  fs::path inner;
  bool leading = true;
  for (const auto& part : written) {
    if (leading && (part == "." || part == "..")) continue;
    leading = false;
    inner /= part;
  }
  for (const fs::path& dir : data_directories()) {
    if (!inner.empty()) add_unique(tried, dir / inner);
    if (!kind_dir.empty()) add_unique(tried, dir / kind_dir / written.filename());
  }
  for (const fs::path& p : tried) {
    if (is_file(p)) return p;
  }
  const fs::path first = tried.front();
  std::string message = first.string() + ": cannot open: " + (is_dir(first) ? "is a directory" : "no such file");
  if (tried.size() > 1) {
    message += " (also tried";
    for (std::size_t i = 1; i < tried.size(); ++i) message += (i == 1 ? " " : ", ") + tried[i].string();
    message += ")";
  }
  throw IoError(message);
}

}  // namespace touchdown
