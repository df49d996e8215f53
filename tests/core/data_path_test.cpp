// resolve_data_file: beside the referring file first, then each data
// directory ($TOUCHDOWN_DATA here, a tree made by the test), and a miss
// names every place tried.
#include "touchdown/core/data_path.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace td = touchdown;
namespace fs = std::filesystem;

namespace {

// Sets $TOUCHDOWN_DATA for one test, restoring it after.
class DataEnv {
 public:
  explicit DataEnv(const fs::path& dir) {
    if (const char* old = std::getenv("TOUCHDOWN_DATA")) old_ = old;
    ::setenv("TOUCHDOWN_DATA", dir.c_str(), 1);
  }
  ~DataEnv() {
    if (old_.empty()) {
      ::unsetenv("TOUCHDOWN_DATA");
    } else {
      ::setenv("TOUCHDOWN_DATA", old_.c_str(), 1);
    }
  }
  DataEnv(const DataEnv&) = delete;
  DataEnv& operator=(const DataEnv&) = delete;

 private:
  std::string old_;
};

std::string message_of(const fs::path& base, const std::string& name, const std::string& kind = "") {
  try {
    (void)td::resolve_data_file(base, name, kind);
  } catch (const td::IoError& e) {
    return e.what();
  }
  return "(resolved)";
}

}  // namespace

TEST(DataPath, BesideTheFileFirstThenTheDataDirectories) {
  td::test::TempDir dir;
  const fs::path data = dir / "share", mission_dir = dir / "copied";
  fs::create_directories(data / "airframes");
  fs::create_directories(mission_dir);
  td::test::write_text(data / "airframes/a.yaml", "data");
  const DataEnv env(data);
  ASSERT_FALSE(td::data_directories().empty());
  EXPECT_EQ(td::data_directories().front(), data.lexically_normal());
  // Not beside the copied file: its ../airframes/a.yaml is the data tree's.
  EXPECT_EQ(td::resolve_data_file(mission_dir, "../airframes/a.yaml"), (data / "airframes/a.yaml").lexically_normal());
  // A bare name is found through the kind's directory.
  EXPECT_EQ(td::resolve_data_file(mission_dir, "a.yaml", "airframes"), (data / "airframes/a.yaml").lexically_normal());
  EXPECT_NE(message_of(mission_dir, "a.yaml"), "(resolved)");  // no kind: not looked for in airframes/
  // A file beside the referring one wins over the data tree's.
  fs::create_directories(dir / "airframes");
  td::test::write_text(dir / "airframes/a.yaml", "beside");
  EXPECT_EQ(td::resolve_data_file(mission_dir, "../airframes/a.yaml"), (dir / "airframes/a.yaml").lexically_normal());
  // An absolute name is taken as it is.
  const fs::path absolute = data / "airframes/a.yaml";
  EXPECT_EQ(td::resolve_data_file(mission_dir, absolute.string()), absolute);
}

TEST(DataPath, AMissNamesEveryPlaceTried) {
  td::test::TempDir dir;
  const fs::path data = dir / "share";
  fs::create_directories(data);
  const DataEnv env(data);
  const fs::path base = dir / "m";
  const std::string why = message_of(base, "../airframes/none.yaml", "airframes");
  EXPECT_EQ(
      why.find((base / "../airframes/none.yaml").lexically_normal().string() +
               ": cannot open: no such file (also tried " + (data / "airframes/none.yaml").lexically_normal().string()),
      0U)
      << why;
  // A directory is not a file, and says so.
  fs::create_directories(base / "d.yaml");
  EXPECT_NE(message_of(base, "d.yaml").find("d.yaml: cannot open: is a directory"), std::string::npos);
  EXPECT_NE(message_of(base, (dir / "nope.yaml").string()).find("nope.yaml: cannot open: no such file"),
            std::string::npos);
}
