// terrain_synth end to end: the ranges of its options (issue 11 item 4:
// limits instead of bad_alloc) and the frame of what it writes.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "test_util.hpp"
#include "touchdown/core/cloud_io.hpp"

namespace td = touchdown;
using td::test::AppRun;
using td::test::TempDir;

namespace {

AppRun synth(const std::string& args, const TempDir& dir) { return td::test::run_app(TERRAIN_SYNTH_EXE, args, dir); }

// Exit 2, one stderr line naming `option` and containing `what`, nothing written.
void expect_refused(const std::string& args, const std::string& option, const std::string& what) {
  SCOPED_TRACE(args);
  TempDir dir;
  const AppRun r = synth("flat -o " + (dir / "x.pcd").string() + " " + args, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(option), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.pcd"));
}

}  // namespace

// Issue 11: ended in std::bad_alloc, exit 3.
TEST(TerrainSynthAppBadInput, HugeImageIsRefusedNotBadAlloc) {
  expect_refused("--width 100000 --height 100000", "--width", "outside [1, 8192]");
  // Each side in range, the product not: the memory estimate says why.
  expect_refused("--width 8192 --height 8192", "--width x --height = 8192 x 8192 = 67108864 pixels",
                 "needs ~3.5 GB; the limit is 4194304 pixels");
}

// Issue 11: accepted before.
TEST(TerrainSynthAppBadInput, CameraHeightZeroAndSlopeBeyondTheRenderer) {
  expect_refused("--camera-height 0", "--camera-height", "outside (0, 10]");
  expect_refused("--slope 95", "--slope", "outside [0, 80)");
}

TEST(TerrainSynthAppBadInput, ANameNotInTheListIsRefusedListingTheNames) {
  TempDir dir;
  const AppRun r = synth("crater -o " + (dir / "x.pcd").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("KIND: expected one of flat, incline, step, plateau, rubble, post; got 'crater'"),
            std::string::npos)
      << r.err;
  expect_refused("--encoding lzf", "--encoding", "expected one of ascii, binary, binary_compressed; got 'lzf'");
}

TEST(TerrainSynthAppBadInput, EveryOptionHasARange) {
  expect_refused("--fx 0", "--fx", "outside (0, 100000]");
  expect_refused("--fx nan", "--fx", "outside");
  expect_refused("--rubble-count 100000000", "--rubble-count", "outside [0, 1000]");
  expect_refused("--step-height inf", "--step-height", "outside [-5, 5]");
  expect_refused("--plateau-size 0.6,-1", "--plateau-size", "outside (0, 1000]");
  expect_refused("--post 0,0,0,0.2", "--post", "radius must be in (0, 100]");
  expect_refused("--noise-scale -1", "--noise-scale", "outside [0, 100]");
  expect_refused("--seed -1", "--seed", "must be >= 0, got -1");
  // In range, but the camera would be inside the terrain.
  expect_refused("--camera-height 0.1", "--camera-height", "it sees from 0.2 m");
}

// The world-frame output is never organized (even when no pixel was lost):
// terrain_mesh would take an organized cloud for a camera frame.
TEST(TerrainSynthApp, WorldFrameOutputIsUnorganized) {
  TempDir dir;
  const AppRun r = synth(
      "flat --frame world --noise-scale 0 --width 64 --height 48 --fx 40 --json -o " + (dir / "w.pcd").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto cloud = td::read_cloud(dir / "w.pcd");
  EXPECT_EQ(cloud.size(), 64u * 48u);
  EXPECT_FALSE(cloud.is_organized());
  const AppRun m = td::test::run_app(TERRAIN_MESH_EXE,
                                     (dir / "w.pcd").string() + " -o " + (dir / "w.stl").string() + " --cell 0.1", dir);
  EXPECT_EQ(m.code, 0) << m.err;
}

TEST(TerrainSynthApp, HelpShowsEveryDefault) {
  TempDir dir;
  const AppRun r = synth("--help", dir);
  ASSERT_EQ(r.code, 0);
  td::test::expect_help_shows_defaults(r.out);
  EXPECT_NE(r.out.find("--post FLOAT:in [-1000, 1000]=[0.205,0.205,0.04,0.25]"), std::string::npos) << r.out;
}

// Issue 31 item 2: the cloud was written before --extrinsics-out failed.
TEST(TerrainSynthAppBadInput, ABadOutputPathLeavesNoOtherOutput) {
  TempDir dir;
  const AppRun r = synth(
      "flat -o " + (dir / "ok.pcd").string() + " --frame camera --extrinsics-out " + (dir / "nope" / "e.yaml").string(),
      dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--extrinsics-out: "), std::string::npos) << r.err;
  EXPECT_TRUE(dir.files().empty());
}
