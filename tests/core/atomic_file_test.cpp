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

TEST(StagedOutputs, CommitRenamesEveryOutputIntoPlace) {
  td::test::TempDir dir;
  td::StagedOutputs out;
  const auto a = out.add(dir / "a.csv", "--csv");
  const auto b = out.add(dir / "b.svg");
  EXPECT_EQ(a.extension(), ".csv") << "writers that pick a format by extension must see it";
  EXPECT_EQ(b.extension(), ".svg");
  EXPECT_EQ(a.parent_path(), dir.path());
  std::ofstream(a) << "1,2";
  std::ofstream(b) << "<svg/>";
  EXPECT_FALSE(std::filesystem::exists(dir / "a.csv")) << "nothing is in place before commit";
  out.commit();
  EXPECT_EQ(td::test::read_text(dir / "a.csv"), "1,2");
  EXPECT_EQ(td::test::read_text(dir / "b.svg"), "<svg/>");
  EXPECT_EQ(dir.files().size(), 2u);
}

TEST(StagedOutputs, AnErrorBeforeCommitLeavesNoOutput) {
  td::test::TempDir dir;
  td::test::write_text(dir / "old.csv", "old");
  {
    td::StagedOutputs out;
    std::ofstream(out.add(dir / "old.csv")) << "new";
    std::ofstream(out.add(dir / "video.avi")) << "frames";
  }  // an exception on the way unwinds here
  EXPECT_EQ(td::test::read_text(dir / "old.csv"), "old");
  EXPECT_EQ(dir.files().size(), 1u);
}

TEST(StagedOutputs, ABadPathIsRefusedWhenAddedNamingTheOption) {
  td::test::TempDir dir;
  td::StagedOutputs out;
  out.add(dir / "ok.avi", "--video");
  try {
    out.add(dir / "nope" / "a.png", "--snapshot");
    FAIL();
  } catch (const td::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("--snapshot: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  EXPECT_THROW(out.add(dir.path(), "--log"), td::IoError) << "a directory";
  try {
    out.add(dir / "." / "ok.avi", "--log");
    FAIL();
  } catch (const td::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("also the output of --video"), std::string::npos) << e.what();
  }
}

TEST(StagedOutputs, AnOutputNotProducedIsLeftAsItWas) {
  td::test::TempDir dir;
  td::test::write_text(dir / "b.csv", "old");
  td::StagedOutputs out;
  std::ofstream(out.add(dir / "a.csv")) << "x";
  out.add(dir / "b.csv");
  out.add(dir / "c.csv");
  out.commit();
  EXPECT_EQ(td::test::read_text(dir / "a.csv"), "x");
  EXPECT_EQ(td::test::read_text(dir / "b.csv"), "old");
  EXPECT_FALSE(std::filesystem::exists(dir / "c.csv"));
  EXPECT_EQ(dir.files().size(), 2u);
}
