#include "touchdown/terrain/extrinsics.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;

namespace {

std::string error_of(const std::string& yaml) {
  return td::test::error_of([&] { tt::parse_extrinsics(yaml, "cam.yaml"); });
}

}  // namespace

TEST(Extrinsics, XyzRpyDegrees) {
  const auto e = tt::parse_extrinsics("xyz: [1, 2, 3]\nrpy_deg: [180, 0, 90]\n", "cam.yaml");
  // Rz(90) * Rx(180): camera x → world y, camera y → world x, camera z → world -z.
  const Eigen::Vector3d p = e.T_world_camera * Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(1, 3, 3), 1e-12)) << p.transpose();
  const Eigen::Vector3d q = e.T_world_camera * Eigen::Vector3d(0, 1, 0);
  EXPECT_TRUE(q.isApprox(Eigen::Vector3d(2, 2, 3), 1e-12)) << q.transpose();
  const Eigen::Vector3d r = e.T_world_camera * Eigen::Vector3d(0, 0, 1);
  EXPECT_TRUE(r.isApprox(Eigen::Vector3d(1, 2, 2), 1e-12)) << r.transpose();
  EXPECT_TRUE(e.T_body_camera.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(Extrinsics, LegacyRpyKeyReadsDegreesToo) {
  const auto canonical = tt::parse_extrinsics("xyz: [1, 2, 3]\nrpy_deg: [170, 5, 90]\n", "a.yaml");
  const auto legacy = tt::parse_extrinsics("xyz: [1, 2, 3]\nrpy: [170, 5, 90]\n", "b.yaml");
  EXPECT_TRUE(legacy.T_world_camera.isApprox(canonical.T_world_camera, 1e-15));
  EXPECT_EQ(error_of("rpy: [180, x, 0]\n"), "cam.yaml:1: rpy: expected a number, got 'x'");
}

TEST(Extrinsics, RepeatedKeyIsAnError) {
  td::test::TempDir dir;
  const auto f =
      td::test::with_repeated_key(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/terrains/step.extrinsics.yaml",
                                  dir / "cam.yaml", "rpy_deg", "[0, 0, 0]");
  EXPECT_EQ(td::test::error_of([&] { (void)tt::load_extrinsics(f.path); }), f.expected);
  EXPECT_THROW((void)tt::load_extrinsics(f.path), td::ParseError);
}

TEST(Extrinsics, RpyOrderIsZYX) {
  const double d = std::numbers::pi / 180;
  const Eigen::Matrix3d R = tt::rotation_from_rpy(10 * d, 20 * d, 30 * d);
  const Eigen::Matrix3d expected =
      (Eigen::AngleAxisd(30 * d, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(20 * d, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(10 * d, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  EXPECT_TRUE(R.isApprox(expected, 1e-14));
}

TEST(Extrinsics, MatrixFlatOrNestedAndBody) {
  const std::string flat =
      "matrix: [0, -1, 0, 0.5,  1, 0, 0, -0.25,  0, 0, 1, 2,  0, 0, 0, 1]\n"
      "body:\n  xyz: [0.1, 0, -0.05]\n  rpy_deg: [0, 0, 0]\n";
  const std::string nested = "matrix:\n  - [0, -1, 0, 0.5]\n  - [1, 0, 0, -0.25]\n  - [0, 0, 1, 2]\n  - [0, 0, 0, 1]\n";
  const auto a = tt::parse_extrinsics(flat, "a.yaml");
  const auto b = tt::parse_extrinsics(nested, "b.yaml");
  EXPECT_TRUE(a.T_world_camera.isApprox(b.T_world_camera, 1e-15));
  EXPECT_TRUE((a.T_world_camera * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0.5, 0.75, 2)));
  EXPECT_TRUE(a.T_body_camera.translation().isApprox(Eigen::Vector3d(0.1, 0, -0.05)));
}

TEST(Extrinsics, FormatParseRoundTrip) {
  tt::Extrinsics e;
  e.T_world_camera = tt::pose_from_xyz_rpy({0.3, -0.2, 1.4}, {3.0, -0.4, 1.1});
  e.T_body_camera = tt::pose_from_xyz_rpy({0.05, 0, -0.03}, {std::numbers::pi, 0, 0.2});
  const auto back = tt::parse_extrinsics(tt::format_extrinsics(e, true), "x");
  EXPECT_TRUE(back.T_world_camera.isApprox(e.T_world_camera, 1e-12));
  EXPECT_TRUE(back.T_body_camera.isApprox(e.T_body_camera, 1e-12));
  // Gimbal lock (pitch = 90 deg) still round-trips.
  e.T_world_camera = tt::pose_from_xyz_rpy({0, 0, 1}, {0.0, std::numbers::pi / 2, 0.7});
  EXPECT_TRUE(
      tt::parse_extrinsics(tt::format_extrinsics(e, false), "x").T_world_camera.isApprox(e.T_world_camera, 1e-9));
}

// One case per malformed extrinsics file: one error naming the file, the
// line and the key.
class ExtrinsicsBadInput : public ::testing::TestWithParam<td::test::BadInput> {};

TEST_P(ExtrinsicsBadInput, OneErrorNamingTheKey) {
  touchdown::test::expect_one_line_naming(error_of(GetParam().text), GetParam());
}

INSTANTIATE_TEST_SUITE_P(
    Cases, ExtrinsicsBadInput,
    ::testing::ValuesIn(std::vector<td::test::BadInput>{
        {"XyzWithTwoNumbers", "xyz: [1, 2]\n", {"cam.yaml:1: xyz: expected 3 numbers, got 2"}},
        {"UnknownKey",
         "xyz: [1, 2, 3]\nrpz: [0, 0, 0]\n",
         {"cam.yaml:2: rpz: unknown key (expected xyz, rpy_deg, rpy, matrix, body)"}},
        {"NonNumber", "xyz: [1, two, 3]\n", {"cam.yaml:1: xyz: expected a number, got 'two'"}},
        {"NotARotation", "matrix: [1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n", {"is not a rotation"}},
        {"BadLastRow", "matrix: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]\n", {"last row must be 0 0 0 1"}},
        {"MatrixWithThreeNumbers", "matrix: [1, 0, 0]\n", {"expected 16 numbers"}},
        {"MatrixAndXyz", "xyz: [0, 0, 0]\nmatrix: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n", {"not both"}},
        {"BodyXyzWithTwoNumbers",
         "body:\n  xyz: [0, 0]\nxyz: [0, 0, 1]\nrpy_deg: [180, 0, 0]\n",
         {"cam.yaml:2: body.xyz: expected 3 numbers"}},
        // Issue 11: a file with only xyz was read with the identity rotation
        // (a camera looking up): the terrain ended up above the camera.
        {"XyzOnlyHasNoRotation",
         "xyz: [0, 0, 1.5]\n",
         {"cam.yaml:1: rpy_deg: missing", "rotation is required", "rpy_deg: [180, 0, 0]"}},
        {"BodyXyzOnlyHasNoRotation",
         "xyz: [0, 0, 1.5]\nrpy_deg: [180, 0, 0]\nbody:\n  xyz: [0.06, 0, -0.04]\n",
         {"cam.yaml:4: body.rpy_deg: missing"}},
        {"InvalidYaml", "xyz: [0, 0, 1\n", {"invalid YAML"}},
        {"NotAMapping", "- 1\n- 2\n", {"expected a YAML mapping"}},
        {"Empty", "{}", {"rpy_deg: missing"}},
        {"NaN", "xyz: [.nan, 0, 1]\n", {"xyz: expected a number, got '.nan'"}},
        {"RpyAndRpyDeg", "rpy_deg: [180, 0, 0]\nrpy: [180, 0, 0]\n", {"cam.yaml:2: rpy: give rpy_deg only"}},
    }),
    td::test::bad_input_name);

// Issue 11: rpy given in radians was read as degrees without a word.
TEST(Extrinsics, RpyThatLooksLikeRadiansIsReadAsDegreesWithAWarning) {
  const auto e = tt::parse_extrinsics("xyz: [0, 0, 1.2]\nrpy_deg: [3.14159, 0, 1.5708]\n", "cam.yaml");
  EXPECT_TRUE(e.T_world_camera.linear().isApprox(
      tt::rotation_from_rpy(3.14159 * std::numbers::pi / 180, 0, 1.5708 * std::numbers::pi / 180)));
  ASSERT_EQ(e.warnings.size(), 1u);
  const std::string& w = e.warnings[0];
  EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  EXPECT_NE(w.find("cam.yaml:2: rpy_deg: [3.14159, 0, 1.5708] look like radians"), std::string::npos) << w;
  EXPECT_NE(w.find("write [180, 0, 90]"), std::string::npos) << w;
  // The legacy key and the body section are checked too.
  const auto b = tt::parse_extrinsics("rpy: [180, 0, 0]\nbody:\n  rpy: [0, -0.5, 0]\n", "b.yaml");
  ASSERT_EQ(b.warnings.size(), 1u);
  EXPECT_NE(b.warnings[0].find("b.yaml:3: body.rpy: [0, -0.5, 0] look like radians"), std::string::npos)
      << b.warnings[0];
}

TEST(Extrinsics, DegreesAndMatricesGiveNoWarning) {
  for (const char* yaml :
       {"rpy_deg: [180, 0, 90]\n", "rpy_deg: [0, 0, 0]\n", "rpy_deg: [2, -3, 6]\n", "rpy_deg: [179.5, 0.5, 30]\n",
        "rpy_deg: [0, 0, 7.5]\n", "matrix: [1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 1.2, 0, 0, 0, 1]\n"}) {
    EXPECT_TRUE(tt::parse_extrinsics(yaml, "cam.yaml").warnings.empty()) << yaml;
  }
  // What terrain_synth --extrinsics-out writes reads back without warnings.
  tt::Extrinsics e;
  e.T_world_camera = tt::pose_from_xyz_rpy({0, 0, 1.2}, {std::numbers::pi, 0, 0});
  EXPECT_TRUE(tt::parse_extrinsics(tt::format_extrinsics(e, true), "x").warnings.empty());
}

TEST(ExtrinsicsBadInput, MissingFile) { EXPECT_THROW(tt::load_extrinsics("/nonexistent/cam.yaml"), td::IoError); }
