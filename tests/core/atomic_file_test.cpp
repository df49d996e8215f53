#include "touchdown/core/atomic_file.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace td = touchdown;

TEST(AtomicFile, RenamesIntoPlace) {
  td::test::TempDir dir;
  td::write_file_atomically(dir / "out.txt", [](const std::filesystem::path& tmp) {
    EXPECT_NE(tmp.filename(), "out.txt");
    std::ofstream(tmp) << "hello";
  });
  EXPECT_EQ(td::test::read_text(dir / "out.txt"), "hello");
  EXPECT_EQ(dir.files().size(), 1u);
}

TEST(AtomicFile, FailedWriteLeavesNothingAndKeepsOldFile) {
  td::test::TempDir dir;
  td::test::write_text(dir / "out.txt", "old");
  EXPECT_THROW(td::write_file_atomically(dir / "out.txt",
                                         [](const std::filesystem::path& tmp) {
                                           std::ofstream(tmp) << "partial";
                                           throw td::IoError("disk full");
                                         }),
               td::IoError);
  EXPECT_EQ(td::test::read_text(dir / "out.txt"), "old");
  EXPECT_EQ(dir.files().size(), 1u);
}

TEST(AtomicFile, MissingDirectoryIsNamed) {
  td::test::TempDir dir;
  try {
    td::write_file_atomically(dir / "sub" / "out.txt", [](const std::filesystem::path&) { FAIL(); });
    FAIL();
  } catch (const td::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("sub' does not exist"), std::string::npos) << e.what();
  }
}
