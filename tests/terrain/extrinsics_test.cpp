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
  const auto e = tt::parse_extrinsics("xyz: [1, 2, 3]\nrpy: [180, 0, 90]\n", "cam.yaml");
  // Rz(90) * Rx(180): camera x → world y, camera y → world x, camera z → world -z.
  const Eigen::Vector3d p = e.T_world_camera * Eigen::Vector3d(1, 0, 0);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(1, 3, 3), 1e-12)) << p.transpose();
  const Eigen::Vector3d q = e.T_world_camera * Eigen::Vector3d(0, 1, 0);
  EXPECT_TRUE(q.isApprox(Eigen::Vector3d(2, 2, 3), 1e-12)) << q.transpose();
  const Eigen::Vector3d r = e.T_world_camera * Eigen::Vector3d(0, 0, 1);
  EXPECT_TRUE(r.isApprox(Eigen::Vector3d(1, 2, 2), 1e-12)) << r.transpose();
  EXPECT_TRUE(e.T_body_camera.isApprox(Eigen::Isometry3d::Identity()));
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
      "body:\n  xyz: [0.1, 0, -0.05]\n  rpy: [0, 0, 0]\n";
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

TEST(ExtrinsicsBadInput, ErrorsNameTheKey) {
  EXPECT_EQ(error_of("xyz: [1, 2]\n"), "cam.yaml:1: xyz: expected 3 numbers, got 2");
  EXPECT_EQ(error_of("xyz: [1, 2, 3]\nrpz: [0, 0, 0]\n"),
            "cam.yaml:2: rpz: unknown key (expected xyz, rpy, matrix, body)");
  EXPECT_EQ(error_of("xyz: [1, two, 3]\n"), "cam.yaml:1: xyz: expected a number, got 'two'");
  EXPECT_NE(error_of("matrix: [1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n").find("is not a rotation"),
            std::string::npos);
  EXPECT_NE(error_of("matrix: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1]\n").find("last row must be 0 0 0 1"),
            std::string::npos);
  EXPECT_NE(error_of("matrix: [1, 0, 0]\n").find("expected 16 numbers"), std::string::npos);
  EXPECT_NE(error_of("xyz: [0, 0, 0]\nmatrix: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n").find("not both"),
            std::string::npos);
  EXPECT_NE(error_of("body:\n  xyz: [0, 0]\nxyz: [0, 0, 1]\n").find("cam.yaml:2: body.xyz: expected 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of("xyz: [0, 0, 1\n").find("invalid YAML"), std::string::npos);
  EXPECT_NE(error_of("- 1\n- 2\n").find("expected a YAML mapping"), std::string::npos);
  EXPECT_NE(error_of("{}").find("xyz: missing"), std::string::npos);
  EXPECT_NE(error_of("xyz: [.nan, 0, 1]\n").find("xyz: expected a number, got '.nan'"), std::string::npos);
}

TEST(ExtrinsicsBadInput, MissingFile) { EXPECT_THROW(tt::load_extrinsics("/nonexistent/cam.yaml"), td::IoError); }
