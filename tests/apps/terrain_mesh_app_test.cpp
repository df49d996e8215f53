// The terrain_mesh app end to end: success output and every bad-input case
// of issue 2 (one line naming the file, exit code 2, no output left behind).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "test_util.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/mesh_io.hpp"

namespace td = touchdown;
using td::test::TempDir;

namespace {

using td::test::AppRun;

AppRun run(const std::string& args, const TempDir& dir) { return td::test::run_app(TERRAIN_MESH_EXE, args, dir); }

// Expects exit 2, exactly one stderr line mentioning `file` and `problem`,
// and no output file (nor a temporary) in the directory.
void expect_bad_input(const TempDir& dir, const std::string& input_name, const std::string& contents,
                      const std::string& problem, const std::string& extra_args = "") {
  const auto input = dir / input_name;
  td::test::write_text(input, contents);
  const auto before = dir.files().size();
  const AppRun r = run(input.string() + " -o " + (dir / "out.stl").string() + " " + extra_args, dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(input_name), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(problem), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(dir.files().size(), before) << "an output or temporary file was left behind";
}

const std::string kHead = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

std::string small_step_pcd() {
  std::stringstream s;
  td::PointCloud c;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 40; ++j)
      c.points.emplace_back(0.005f + static_cast<float>(i) * 0.01f, 0.005f + static_cast<float>(j) * 0.01f,
                            i < 30 ? 0.f : 0.1f);
  c.mark_unorganized();
  td::write_pcd(c, s, td::PcdEncoding::Binary);
  return s.str();
}

// An organized 60 x 40 frame of a flat floor 1.2 m below a downward-looking
// camera, in the camera's optical frame.
std::string organized_camera_pcd() {
  std::stringstream s;
  td::PointCloud c;
  c.width = 60;
  c.height = 40;
  for (int v = 0; v < 40; ++v)
    for (int u = 0; u < 60; ++u)
      c.points.emplace_back(0.02f * static_cast<float>(u - 30), 0.02f * static_cast<float>(v - 20), 1.2f);
  td::write_pcd(c, s, td::PcdEncoding::Binary);
  return s.str();
}

void expect_one_line(const AppRun& r) { EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err; }

}  // namespace

TEST(TerrainMeshApp, JsonReportAndClosedMesh) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  const AppRun r =
      run((dir / "step.pcd").string() + " -o " + (dir / "step.stl").string() + " --json --outlier-k 0", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key :
       {"input", "output", "points_read", "points_used", "cells", "holes_filled", "triangles", "bounds", "seconds"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["points_read"], 2400);
  EXPECT_EQ(j["cells"], 30 * 20);
  EXPECT_NEAR(j["bounds"]["max"][2].get<double>(), 0.1, 1e-6);
  EXPECT_NEAR(j["bounds"]["min"][2].get<double>(), 0.0, 1e-6);
  const auto mesh = td::read_mesh(dir / "step.stl");
  EXPECT_EQ(mesh.triangles.size(), j["triangles"].get<std::size_t>());
  EXPECT_TRUE(td::check_closedness(mesh).consistently_oriented());
}

TEST(TerrainMeshApp, SavesTheFilteredCloud) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  const AppRun r = run((dir / "step.pcd").string() + " -o " + (dir / "step.ply").string() + " --save-cloud " +
                           (dir / "kept.pcd").string() + " --json",
                       dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(td::read_cloud(dir / "kept.pcd").size(), j["points_used"].get<std::size_t>());
}

TEST(TerrainMeshAppBadInput, TruncatedBinary) {
  TempDir dir;
  const std::string s = small_step_pcd();
  expect_bad_input(dir, "trunc.pcd", s.substr(0, s.size() - 100), "truncated binary data");
}

TEST(TerrainMeshAppBadInput, HeaderCountMismatch) {
  TempDir dir;
  expect_bad_input(dir, "count.pcd", kHead + "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n",
                   "header/count mismatch");
}

TEST(TerrainMeshAppBadInput, UnknownDataType) {
  TempDir dir;
  expect_bad_input(dir, "data.pcd", kHead + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA lz4\n", "unknown DATA type 'lz4'");
}

TEST(TerrainMeshAppBadInput, MissingXyzFields) {
  TempDir dir;
  expect_bad_input(dir, "fields.pcd", "FIELDS x z\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n1 2\n", "no 'y' field");
}

TEST(TerrainMeshAppBadInput, NonNumericText) {
  TempDir dir;
  expect_bad_input(dir, "text.xyz", "0 0 0\n1 1 one\n", "text.xyz:2: 'one' is not a number");
}

TEST(TerrainMeshAppBadInput, EmptyCloud) {
  TempDir dir;
  expect_bad_input(dir, "empty.xyz", "# nothing here\n", "the point cloud is empty");
  expect_bad_input(dir, "nan.pcd", kHead + "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\nnan nan nan\nnan 0 0\n",
                   "no points left");
}

TEST(TerrainMeshAppBadInput, AllPointsInOneCell) {
  TempDir dir;
  expect_bad_input(dir, "one.xyz", "0.001 0.001 0\n0.002 0.003 0.01\n0.004 0.002 0\n", "2 x 2 block of cells");
}

TEST(TerrainMeshAppBadInput, UnreadableFile) {
  TempDir dir;
  const AppRun r = run((dir / "missing.pcd").string() + " -o " + (dir / "out.stl").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.pcd: cannot open"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_TRUE(dir.files().empty());
}

// Issue 31, item 9: a directory (or a missing file without an extension)
// said "unknown point cloud format ''".
TEST(TerrainMeshAppBadInput, DirectoryOrMissingFileSaysSo) {
  TempDir dir;
  std::filesystem::create_directory(dir / "scans");
  const AppRun d = run((dir / "scans").string() + " -o " + (dir / "out.stl").string(), dir);
  EXPECT_EQ(d.code, 2);
  EXPECT_NE(d.err.find("scans: cannot open: is a directory"), std::string::npos) << d.err;
  EXPECT_EQ(d.err.find("unknown point cloud format"), std::string::npos) << d.err;
  expect_one_line(d);
  const AppRun m = run((dir / "nothing").string() + " -o " + (dir / "out.stl").string(), dir);
  EXPECT_EQ(m.code, 2);
  EXPECT_NE(m.err.find("nothing: cannot open: no such file"), std::string::npos) << m.err;
  expect_one_line(m);
  EXPECT_FALSE(std::filesystem::exists(dir / "out.stl"));
}

TEST(TerrainMeshAppBadInput, OutputDirectoryMissing) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  const AppRun r = run((dir / "step.pcd").string() + " -o " + (dir / "nodir" / "out.stl").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("out.stl: output directory"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);
  EXPECT_EQ(dir.files().size(), 1u);
}

TEST(TerrainMeshAppBadInput, BadOptionsAndExtrinsics) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  td::test::write_text(dir / "cam.yaml", "xyz: [0, 0]\n");
  AppRun r = run(
      (dir / "step.pcd").string() + " -o " + (dir / "o.stl").string() + " --extrinsics " + (dir / "cam.yaml").string(),
      dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cam.yaml:1: xyz: expected 3 numbers"), std::string::npos) << r.err;
  r = run((dir / "step.pcd").string() + " -o " + (dir / "o.stl").string() + " --cell -1", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cell"), std::string::npos) << r.err;
  r = run((dir / "step.pcd").string() + " -o " + (dir / "o.stl").string() + " --agg mean", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--agg: expected one of max, median; got 'mean'"), std::string::npos) << r.err;
  r = run((dir / "step.pcd").string() + " -o " + (dir / "o.gltf").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown mesh format"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files().size(), 2u);
}

// Issue 11: a camera-frame cloud meshed without --extrinsics came out upside
// down (z is depth) without a word. Refused now, with the way out.
TEST(TerrainMeshAppBadInput, OrganizedCameraFrameWithoutExtrinsics) {
  TempDir dir;
  expect_bad_input(dir, "frame.pcd", organized_camera_pcd(), "looks like a camera-frame point cloud");
  const AppRun r = run((dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string(), dir);
  EXPECT_NE(r.err.find("organized (60 x 40 pixels)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--extrinsics FILE"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--assume-world-frame"), std::string::npos) << r.err;
}

TEST(TerrainMeshApp, AssumeWorldFrameAcceptsAnOrganizedCloud) {
  TempDir dir;
  td::test::write_text(dir / "frame.pcd", organized_camera_pcd());
  const AppRun r =
      run((dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string() + " --assume-world-frame --json", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_NEAR(nlohmann::json::parse(r.out)["bounds"]["max"][2].get<double>(), 1.2, 1e-6);
  // With its camera pose it is a floor at z = 0.
  td::test::write_text(dir / "cam.yaml", "xyz: [0, 0, 1.2]\nrpy_deg: [180, 0, 0]\n");
  const AppRun e = run((dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string() + " --extrinsics " +
                           (dir / "cam.yaml").string() + " --json",
                       dir);
  ASSERT_EQ(e.code, 0) << e.err;
  EXPECT_NEAR(nlohmann::json::parse(e.out)["bounds"]["max"][2].get<double>(), 0.0, 1e-6);
  // Both at once contradict each other.
  const AppRun both = run((dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string() + " --extrinsics " +
                              (dir / "cam.yaml").string() + " --assume-world-frame",
                          dir);
  EXPECT_EQ(both.code, 2);
  expect_one_line(both);
}

// Data we did not make: PCL's real organized stereo scan of a table.
TEST(TerrainMeshAppBadInput, RealPclTableScanWithoutExtrinsics) {
  TempDir dir;
  const auto table = td::test::data_path("pcl/table_scene_mug_stereo_textured.pcd");
  const AppRun r = run(table.string() + " -o " + (dir / "t.stl").string(), dir);
  EXPECT_EQ(r.code, 2) << r.err;
  expect_one_line(r);
  EXPECT_NE(r.err.find("table_scene_mug_stereo_textured.pcd: looks like a camera-frame point cloud: it is organized "
                       "(640 x 480 pixels)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "t.stl"));
}

// Issue 11: an xyz-only extrinsics file meant the identity rotation.
TEST(TerrainMeshAppBadInput, ExtrinsicsWithoutRotation) {
  TempDir dir;
  td::test::write_text(dir / "frame.pcd", organized_camera_pcd());
  td::test::write_text(dir / "cam.yaml", "xyz: [0, 0, 1.2]\n");
  const AppRun r = run(
      (dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string() + " --extrinsics " + (dir / "cam.yaml").string(),
      dir);
  EXPECT_EQ(r.code, 2);
  expect_one_line(r);
  EXPECT_NE(r.err.find("cam.yaml:1: rpy_deg: missing"), std::string::npos) << r.err;
}

// Issue 11: rpy in radians was read as degrees without a word; now a
// one-line warning on stderr (the run goes on: it is a plausible value).
TEST(TerrainMeshApp, RpyInRadiansGetsAWarning) {
  TempDir dir;
  td::test::write_text(dir / "frame.pcd", organized_camera_pcd());
  td::test::write_text(dir / "cam.yaml", "xyz: [0, 0, 1.2]\nrpy_deg: [3.14159, 0, 1.5708]\n");
  const AppRun r = run(
      (dir / "frame.pcd").string() + " -o " + (dir / "o.stl").string() + " --extrinsics " + (dir / "cam.yaml").string(),
      dir);
  EXPECT_EQ(r.code, 0) << r.err;
  expect_one_line(r);
  EXPECT_NE(r.err.find("terrain_mesh: warning: " + (dir / "cam.yaml").string() +
                       ":2: rpy_deg: [3.14159, 0, 1.5708] look like radians"),
            std::string::npos)
      << r.err;
}

// Issue 11 item 4: every size option has a range; outside it, exit 2 naming the option.
TEST(TerrainMeshAppBadInput, OptionsOutOfRange) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  for (const char* opt :
       {"--cell 0", "--cell 100", "--outlier-k 1000000", "--outlier-std 0", "--voxel 1e9", "--voxel nan",
        "--crop-radius -1", "--max-hole inf", "--base 0", "--flying-threshold -0.1", "--crop-box 0,0,0,1,1,1e9"}) {
    SCOPED_TRACE(opt);
    const AppRun r = run((dir / "step.pcd").string() + " -o " + (dir / "o.stl").string() + " " + opt, dir);
    EXPECT_EQ(r.code, 2) << r.err;
    expect_one_line(r);
    const std::string name = std::string(opt).substr(0, std::string(opt).find(' '));
    EXPECT_NE(r.err.find(name + ": "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is outside"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "o.stl"));
}

// docs/architecture.md, "Conventions" (apps): --help shows the default of every option that takes a value.
TEST(TerrainMeshApp, HelpShowsEveryDefault) {
  TempDir dir;
  const AppRun r = run("--help", dir);
  ASSERT_EQ(r.code, 0);
  td::test::expect_help_shows_defaults(r.out);
}

// Issue 31 item 2: --save-cloud was written before the mesh's path failed.
TEST(TerrainMeshAppBadInput, ABadOutputPathLeavesNoOtherOutput) {
  TempDir dir;
  td::test::write_text(dir / "step.pcd", small_step_pcd());
  const AppRun r = run((dir / "step.pcd").string() + " --save-cloud " + (dir / "kept.pcd").string() + " -o " +
                           (dir / "nodir" / "out.stl").string(),
                       dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--output: "), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(dir.files().size(), 1u) << "only the input";
}
