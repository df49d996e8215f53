// Module boundaries (issue 54, docs/architecture.md "Modules"): a source
// under src/ includes the public headers (touchdown/...), the shared
// internal helpers (core/...) and the private headers of its own folder,
// never another module's private header; an app includes no module's
// private header but core's. Read from the files themselves.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

namespace fs = std::filesystem;

// The quoted includes of `path` ("core/format.hpp", "led_tracker_impl.hpp").
std::vector<std::string> quoted_includes(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find("#include \"");
    if (at == std::string::npos || line.find_first_not_of(" \t") != at) continue;
    const auto begin = at + 10;
    const auto end = line.find('"', begin);
    if (end != std::string::npos) out.push_back(line.substr(begin, end - begin));
  }
  return out;
}

// Every private include that crosses a boundary, "file -> header".
std::vector<std::string> crossings(const fs::path& root, const std::string& tree, bool own_folder_allowed) {
  std::vector<std::string> found;
  for (const auto& entry : fs::recursive_directory_iterator(root / tree)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".hpp")) continue;
    const std::string folder = entry.path().parent_path().lexically_relative(root / tree).generic_string();
    for (const std::string& inc : quoted_includes(entry.path())) {
      const std::string dir = fs::path(inc).parent_path().generic_string();
      const bool allowed = inc.rfind("touchdown/", 0) == 0 || inc.rfind("core/", 0) == 0 ||
                           (own_folder_allowed && (dir.empty() || dir == folder)) ||
                           (!own_folder_allowed && dir.empty());
      if (!allowed || inc.find("..") != std::string::npos) {
        found.push_back(entry.path().lexically_relative(root).generic_string() + " -> " + inc);
      }
    }
  }
  return found;
}

TEST(Boundaries, NoModuleIncludesAnotherModulesPrivateHeader) {
  const fs::path root = TOUCHDOWN_SOURCE_DIR;
  EXPECT_EQ(crossings(root, "src", true), std::vector<std::string>{});
  EXPECT_EQ(crossings(root, "apps", false), std::vector<std::string>{});
}

TEST(Boundaries, TheCheckFindsACrossing) {
  // Not vacuous: a file in src/mission that includes pose's private header
  // (and one reaching up a folder) is reported.
  const touchdown::test::TempDir dir;
  const fs::path root = dir.path();
  fs::create_directories(root / "src/mission");
  std::ofstream(root / "src/mission/a.cpp") << "#include \"pose/led_tracker_impl.hpp\"\n#include \"../twin/x.hpp\"\n"
                                            << "#include \"mission/own.hpp\"\n#include \"core/format.hpp\"\n"
                                            << "// #include \"twin/commented.hpp\"\n";
  EXPECT_EQ(crossings(root, "src", true), (std::vector<std::string>{"src/mission/a.cpp -> pose/led_tracker_impl.hpp",
                                                                    "src/mission/a.cpp -> ../twin/x.hpp"}));
}

}  // namespace
