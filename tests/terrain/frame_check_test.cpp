#include "touchdown/terrain/frame_check.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "test_util.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/synthetic.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;
namespace syn = touchdown::terrain::synthetic;

namespace {

// A D435-like scan (212 x 120, f = 107.5 px) of `shape` from `T_world_camera`,
// in the camera's optical frame, with the pixel grid dropped.
td::PointCloud unorganized_scan(const syn::Shape& shape, const Eigen::Isometry3d& T_world_camera) {
  td::PointCloud c = syn::render_depth_scan(shape, syn::DepthCamera::centred(212, 120, 107.5), T_world_camera, 3);
  tt::remove_non_finite(c);
  c.mark_unorganized();
  return c;
}

syn::Shape prepared(syn::ShapeKind kind) {
  syn::Shape s;
  s.kind = kind;
  s.prepare();
  return s;
}

// Optical frame looking along world +x, tilted `down_deg` below the horizon.
Eigen::Isometry3d forward_camera(double height, double down_deg) {
  Eigen::Matrix3d level;
  level.col(0) = Eigen::Vector3d(0, -1, 0);  // image x: to the right
  level.col(1) = Eigen::Vector3d(0, 0, -1);  // image y: down
  level.col(2) = Eigen::Vector3d(1, 0, 0);   // optical axis: ahead
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(down_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix() * level;
  T.translation() = Eigen::Vector3d(0, 0, height);
  return T;
}

}  // namespace

TEST(FrameCheck, OrganizedCloudIsACameraFrame) {
  const td::PointCloud c = syn::render_depth_scan(prepared(syn::ShapeKind::Flat), syn::DepthCamera::centred(64, 48, 40),
                                                  syn::nadir_camera_pose(0, 0, 1.2), 1);
  const auto e = tt::camera_frame_evidence(c);
  EXPECT_EQ(e.rule, tt::FrameRule::Organized);
  EXPECT_NE(e.reason.find("organized (64 x 48 pixels)"), std::string::npos) << e.reason;
}

TEST(FrameCheck, ViewpointThatIsNotTheIdentity) {
  td::PointCloud c = td::test::random_cloud(100, 1);
  c.viewpoint = {0, 0, 0, 0, 1, 0, 0};
  const auto e = tt::camera_frame_evidence(c);
  EXPECT_EQ(e.rule, tt::FrameRule::Viewpoint);
  EXPECT_NE(e.reason.find("VIEWPOINT (0 0 0 0 1 0 0)"), std::string::npos) << e.reason;
  // transform_cloud puts the points in a frame of our making.
  tt::transform_cloud(c, Eigen::Isometry3d::Identity());
  EXPECT_NE(tt::camera_frame_evidence(c).rule, tt::FrameRule::Viewpoint);
}

// The same scan in its optical frame (z = depth) and in the world frame.
TEST(FrameCheck, DownwardCameraFrameLooksLikeDepthWorldFrameDoesNot) {
  for (auto kind : {syn::ShapeKind::Flat, syn::ShapeKind::Step, syn::ShapeKind::Rubble, syn::ShapeKind::Incline}) {
    SCOPED_TRACE(syn::to_string(kind));
    const Eigen::Isometry3d T = syn::nadir_camera_pose(0.1, -0.2, 1.2, 0.4);
    td::PointCloud c = unorganized_scan(prepared(kind), T);
    const auto cam = tt::camera_frame_evidence(c);
    EXPECT_EQ(cam.rule, tt::FrameRule::DepthLike) << cam.reason;
    EXPECT_LT(cam.plane_tilt_deg, 15);
    EXPECT_NEAR(cam.plane_height, 1.2, 0.25);
    EXPECT_GT(cam.positive_fraction, 0.999);
    EXPECT_NE(cam.reason.find("z looks like depth"), std::string::npos) << cam.reason;
    tt::transform_cloud(c, T);
    const auto world = tt::camera_frame_evidence(c);
    EXPECT_EQ(world.rule, tt::FrameRule::None) << world.reason;
    EXPECT_LT(world.plane_tilt_deg, 15);
    EXPECT_NEAR(world.plane_height, 0, 0.15);
  }
}

TEST(FrameCheck, ForwardCameraFrameHasATiltedGround) {
  const Eigen::Isometry3d T = forward_camera(1.5, 30);
  td::PointCloud c = unorganized_scan(prepared(syn::ShapeKind::Flat), T);
  ASSERT_GT(c.size(), 5000u);
  const auto e = tt::camera_frame_evidence(c);
  EXPECT_EQ(e.rule, tt::FrameRule::TiltedPlane) << e.reason;
  EXPECT_NEAR(e.plane_tilt_deg, 60, 2);  // the ground normal is 60 deg from the optical axis
  EXPECT_NE(e.reason.find("tilted 60 deg from horizontal"), std::string::npos) << e.reason;
  tt::transform_cloud(c, T);
  EXPECT_EQ(tt::camera_frame_evidence(c).rule, tt::FrameRule::None);
}

// A world-frame incline steeper than the rule's 45 deg is refused too (no
// landing there, and --assume-world-frame is the way out); 40 deg is not.
TEST(FrameCheck, TiltRuleIsAt45Degrees) {
  for (double slope : {40.0, 50.0}) {
    syn::Shape s = prepared(syn::ShapeKind::Incline);
    s.slope_deg = slope;
    const Eigen::Isometry3d T = syn::nadir_camera_pose(0, 0, 1.2);
    td::PointCloud c = unorganized_scan(s, T);
    tt::transform_cloud(c, T);
    const auto e = tt::camera_frame_evidence(c);
    EXPECT_NEAR(e.plane_tilt_deg, slope, 1);
    EXPECT_EQ(e.camera_frame(), slope > 45) << e.reason;
  }
}

// Data we did not make: PCL's real stereo scan of a table with a mug is
// refused as organized; without its pixel grid and viewpoint, the table
// plane seen at an angle still gives it away.
TEST(FrameCheck, RealPclTableScan) {
  td::PointCloud c = td::read_cloud(td::test::data_path("pcl/table_scene_mug_stereo_textured.pcd"));
  EXPECT_EQ(tt::camera_frame_evidence(c).rule, tt::FrameRule::Organized);
  c.mark_unorganized();
  EXPECT_EQ(tt::camera_frame_evidence(c).rule, tt::FrameRule::Viewpoint);
  c.viewpoint = td::PointCloud{}.viewpoint;
  const auto e = tt::camera_frame_evidence(c);  // NaNs included: skipped
  EXPECT_EQ(e.rule, tt::FrameRule::TiltedPlane) << e.reason;
  EXPECT_GT(e.plane_fraction, 0.4);
  EXPECT_EQ(tt::camera_frame_evidence(c).reason, e.reason);  // deterministic
}

TEST(FrameCheck, TooFewPointsOrDegenerateIsNoEvidence) {
  td::PointCloud c;
  for (int i = 0; i < 49; ++i) c.points.emplace_back(0.01f * static_cast<float>(i), 0.f, 5.f);
  c.mark_unorganized();
  EXPECT_EQ(tt::camera_frame_evidence(c).rule, tt::FrameRule::None);
  c.points.emplace_back(1.f, 0.f, 5.f);  // 50 points, all on one line: no plane
  c.mark_unorganized();
  EXPECT_EQ(tt::camera_frame_evidence(c).rule, tt::FrameRule::None);
  EXPECT_EQ(tt::camera_frame_evidence(td::PointCloud{}).rule, tt::FrameRule::None);
}

TEST(FrameCheck, InvalidOptionsThrow) {
  tt::FrameCheckOptions o;
  o.max_tilt_deg = 0;
  EXPECT_THROW(tt::camera_frame_evidence(td::PointCloud{}, o), td::InvalidArgument);
  o = {};
  o.min_points = 2;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("min_points"), std::string::npos);
}
