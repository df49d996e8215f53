#include "touchdown/core/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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

namespace {

// A PID no process has: a child that has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

void touch(const std::filesystem::path& p) { std::ofstream(p) << "x"; }

}  // namespace

// Issue 58 item 1: what a signal must remove is known while it is written.
TEST(LiveTemporaries, StagedOutputsAreRemovedOnRequestAndForgottenOnCommit) {
  td::test::TempDir dir;
  {
    touchdown::StagedOutputs staged;
    const auto tmp = staged.add(dir / "a.svg");
    touch(tmp);
    touchdown::StagedDirectory folder(dir / "seq");
    touch(folder.path() / "000000.png");
    EXPECT_EQ(touchdown::remove_live_temporaries(), 2U);  // what a SIGINT's thread does
    EXPECT_FALSE(std::filesystem::exists(tmp));
    EXPECT_FALSE(std::filesystem::exists(folder.path()));
    EXPECT_EQ(touchdown::remove_live_temporaries(), 0U);
  }
  EXPECT_TRUE(dir.files().empty());
  // Committed outputs are no longer temporaries: nothing to remove.
  touchdown::StagedOutputs staged;
  touch(staged.add(dir / "b.svg"));
  staged.commit();
  touchdown::StagedDirectory folder(dir / "seq");
  folder.commit();
  EXPECT_EQ(touchdown::remove_live_temporaries(), 0U);
  EXPECT_TRUE(std::filesystem::exists(dir / "b.svg"));
  EXPECT_TRUE(std::filesystem::is_directory(dir / "seq"));
  // A staged directory onto an existing one is refused, and cleans up.
  EXPECT_THROW(
      {
        touchdown::StagedDirectory again(dir / "seq");
        again.commit();
      },
      touchdown::IoError);
  EXPECT_EQ(dir.files().size(), 2U);
}

// A run killed with SIGKILL cannot clean up: the next run writing the same
// output removes what a gone process left, and nothing of a live one.
TEST(LiveTemporaries, StaleTemporariesOfAGoneProcessAreRemovedOnTheNextRun) {
  td::test::TempDir dir;
  const std::string gone = std::to_string(dead_pid()), live = std::to_string(::getppid());
  touch(dir / (".out.svg.tmp-" + gone + "-0.svg"));
  std::filesystem::create_directory(dir / (".seq.partial-" + gone + "-3"));
  touch(dir / (".seq.partial-" + gone + "-3") / "000000.png");
  touch(dir / (".out.svg.tmp-" + live + "-0.svg"));    // its owner still runs
  touch(dir / (".other.svg.tmp-" + gone + "-0.svg"));  // another output's
  touch(dir / (".out.svg.tmp-x" + gone + "-0.svg"));   // not this writer's name
  touchdown::write_file_atomically(dir / "out.svg", [](const std::filesystem::path& tmp) { touch(tmp); });
  { touchdown::StagedDirectory folder(dir / "seq"); }
  auto files = dir.files();
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{".other.svg.tmp-" + gone + "-0.svg", ".out.svg.tmp-" + live + "-0.svg",
                                             ".out.svg.tmp-x" + gone + "-0.svg", "out.svg"}));
  const auto removed = touchdown::remove_stale_temporaries(dir / "other.svg");
  ASSERT_EQ(removed.size(), 1U);
  EXPECT_EQ(removed[0].filename(), ".other.svg.tmp-" + gone + "-0.svg");
}
