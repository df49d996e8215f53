#include "touchdown/terrain/synthetic.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/terrain/filters.hpp"

namespace td = touchdown;
namespace syn = touchdown::terrain::synthetic;

namespace {

syn::DepthCamera ideal_camera() {
  auto cam = syn::DepthCamera::centred(160, 120, 100);
  cam.subpixel = 0;
  cam.dropout_fraction = 0;
  cam.outlier_fraction = 0;
  cam.flying_pixels = false;
  return cam;
}

td::PointCloud world_scan(const syn::Shape& s, const syn::DepthCamera& cam, std::uint64_t seed = 1) {
  const auto T = syn::nadir_camera_pose(0.1, -0.05, 1.0, 0.3);
  auto c = syn::render_depth_scan(s, cam, T, seed);
  td::terrain::remove_non_finite(c);
  td::terrain::transform_cloud(c, T);
  return c;
}

}  // namespace

TEST(Synthetic, NoiselessScansLieOnTheSurface) {
  for (auto kind : {syn::ShapeKind::Flat, syn::ShapeKind::Incline, syn::ShapeKind::Step, syn::ShapeKind::Plateau,
                    syn::ShapeKind::Rubble, syn::ShapeKind::Post}) {
    SCOPED_TRACE(syn::to_string(kind));
    syn::Shape s;
    s.kind = kind;
    s.azimuth_deg = 30;
    s.base_z = 0.05;
    s.prepare();
    const auto c = world_scan(s, ideal_camera());
    EXPECT_EQ(c.size(), 160u * 120u);
    std::size_t off = 0;
    for (const auto& p : c.points) {
      // On vertical faces a point may sit on the wall: compare where the surface is smooth.
      if (s.distance_to_edge(p.x(), p.y()) < 0.01) continue;
      if (std::abs(p.z() - s.height(p.x(), p.y())) > 2e-4) ++off;
    }
    EXPECT_EQ(off, 0u);
  }
}

TEST(Synthetic, CameraPoseLooksDown) {
  const auto T = syn::nadir_camera_pose(1, 2, 3, 0);
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitX()));
}

TEST(Synthetic, NoiseFollowsTheDepthModelAndSeedsReproduce) {
  syn::Shape flat;
  flat.prepare();
  auto cam = ideal_camera();
  cam.subpixel = 0.08;
  cam.baseline = 0.05;
  const auto a = world_scan(flat, cam, 5), b = world_scan(flat, cam, 5), c = world_scan(flat, cam, 6);
  EXPECT_TRUE(td::test::same_points(a, b));
  EXPECT_FALSE(td::test::same_points(a, c));
  // The camera is 1 m above the plane: sigma_z = 1 * 0.08 / (100 * 0.05) = 0.016 m along the ray.
  double s2 = 0;
  for (const auto& p : a.points) s2 += p.z() * p.z();
  EXPECT_NEAR(std::sqrt(s2 / static_cast<double>(a.size())), 0.016, 0.0015);
}

TEST(Synthetic, DropoutsAndOutliers) {
  syn::Shape flat;
  flat.prepare();
  auto cam = ideal_camera();
  cam.dropout_fraction = 0.1;
  cam.outlier_fraction = 0.05;
  const auto T = syn::nadir_camera_pose(0, 0, 1.0);
  const auto c = syn::render_depth_scan(flat, cam, T, 2);
  ASSERT_TRUE(c.is_organized());
  std::size_t nan = 0, above = 0;
  for (const auto& p : c.points) {
    if (!p.allFinite())
      ++nan;
    else if (p.z() < 0.95f)
      ++above;  // depth < 0.95 m: well above the ground
  }
  const double n = static_cast<double>(c.size());
  EXPECT_NEAR(nan / n, 0.1, 0.01);
  EXPECT_NEAR(above / n, 0.9 * 0.05 * 0.95, 0.01);
}

TEST(Synthetic, UnknownShapeIsAnError) {
  EXPECT_THROW((void)td::from_string<syn::ShapeKind>("crater"), td::InvalidArgument);
  EXPECT_EQ(td::from_string<syn::ShapeKind>("plateau"), syn::ShapeKind::Plateau);
}
