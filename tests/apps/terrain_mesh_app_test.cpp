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
  r = run((dir / "step.pcd").string() + " -o " + (dir / "o.gltf").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown mesh format"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files().size(), 2u);
}
