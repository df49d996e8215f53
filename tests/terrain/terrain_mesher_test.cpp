#include "touchdown/terrain/terrain_mesher.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/terrain/synthetic.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;
namespace syn = touchdown::terrain::synthetic;

namespace {

struct Scan {
  syn::Shape shape;
  Eigen::Isometry3d T_world_camera;
  td::PointCloud cloud;
};

// A D435-like scan (848x480, realistic depth noise, dropouts, spurious
// returns and flying pixels) from 1.1 m.
Scan scan(syn::Shape shape, std::uint64_t seed, const syn::DepthCamera& camera = syn::DepthCamera{}) {
  shape.prepare();
  Scan s{shape, syn::nadir_camera_pose(0.05, -0.02, 1.1, 0.2), {}};
  s.cloud = syn::render_depth_scan(s.shape, camera, s.T_world_camera, seed);
  return s;
}

// The terrain mesh matches the analytic surface within 1 cm at random
// interior points away from discontinuities; the mesh is a closed solid.
void expect_matches_surface(const Scan& s, std::uint64_t seed) {
  tt::TerrainOptions o;
  o.T_world_camera = s.T_world_camera;
  const auto r = tt::mesh_terrain(s.cloud, o);
  ASSERT_TRUE(r.ok()) << r.message;
  const auto closed = td::check_closedness(r.mesh);
  EXPECT_TRUE(closed.watertight());
  EXPECT_TRUE(closed.consistently_oriented());
  EXPECT_GT(td::signed_volume(r.mesh), 0);
  EXPECT_GT(r.report.points_outliers, 0u);

  td::Rng rng(seed);
  int tested = 0;
  double worst = 0;
  // Interior: within 0.45 m of the point below the camera (the footprint
  // reaches at least 0.55 m from it in every direction).
  const Eigen::Vector3d c = s.T_world_camera.translation();
  while (tested < 60) {
    const double x = c.x() + rng.uniform(-0.45, 0.45), y = c.y() + rng.uniform(-0.45, 0.45);
    if (std::hypot(x - c.x(), y - c.y()) > 0.45) continue;
    if (s.shape.distance_to_edge(x, y) < 0.05) continue;  // two cells either side of an edge
    const double z = td::test::mesh_top_z(r.mesh, x, y);
    ASSERT_FALSE(std::isnan(z)) << "no surface at " << x << ", " << y;
    worst = std::max(worst, std::abs(z - s.shape.height(x, y)));
    ++tested;
  }
  EXPECT_LT(worst, 0.01) << "worst deviation from the analytic surface";
}

}  // namespace

TEST(TerrainMesher, InclineMatchesAnalyticSurface) {
  syn::Shape s;
  s.kind = syn::ShapeKind::Incline;
  s.slope_deg = 12;
  s.azimuth_deg = 40;
  expect_matches_surface(scan(s, 1), 11);
}

TEST(TerrainMesher, StepMatchesAnalyticSurface) {
  syn::Shape s;
  s.kind = syn::ShapeKind::Step;
  s.step_height = 0.12;
  s.edge_offset = 0.1;
  s.azimuth_deg = -20;
  expect_matches_surface(scan(s, 2), 12);
}

TEST(TerrainMesher, PlateauMatchesAnalyticSurface) {
  syn::Shape s;
  s.kind = syn::ShapeKind::Plateau;
  s.plateau_height = 0.2;
  s.azimuth_deg = 15;
  expect_matches_surface(scan(s, 3), 13);
}

TEST(TerrainMesher, RubbleGivesAClosedSolid) {
  syn::Shape s;
  s.kind = syn::ShapeKind::Rubble;
  // The D435's 424 x 240 mode: ray-marching rubble is slow.
  const auto half = syn::DepthCamera::centred(424, 240, 215);
  const auto sc = scan(s, 4, half);
  tt::TerrainOptions o;
  o.T_world_camera = sc.T_world_camera;
  const auto r = tt::mesh_terrain(sc.cloud, o);
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(td::check_closedness(r.mesh).consistently_oriented());
  EXPECT_GT(r.report.bounds.max.z(), 0.02);
}

TEST(TerrainMesher, ReportCountsAddUp) {
  syn::Shape s;
  const auto sc = scan(s, 5);
  tt::TerrainOptions o;
  o.T_world_camera = sc.T_world_camera;
  o.crop_radius = 0.3;           // only spurious returns are that close
  o.flying_pixel_threshold = 0;  // keep them for the crop
  o.keep_filtered_cloud = true;
  const auto r = tt::mesh_terrain(sc.cloud, o);
  ASSERT_TRUE(r.ok());
  const auto& rep = r.report;
  EXPECT_EQ(rep.points_read, 848u * 480u);
  // Cropped: exactly the (spurious) returns within 0.3 m of the camera.
  std::size_t near = 0;
  for (const auto& p : sc.cloud.points) near += p.allFinite() && p.norm() < 0.3f;
  EXPECT_EQ(rep.points_cropped, near);
  EXPECT_GT(rep.points_non_finite, 0u);
  EXPECT_EQ(rep.points_after_voxel - rep.points_outliers, rep.points_used);
  EXPECT_EQ(r.filtered_cloud.size(), rep.points_used);
  // The footprint of an 848 x 480 px, f = 430 px camera 1.1 m above the
  // ground is 2.169 x 1.228 m = 2.664 m^2, i.e. 6660 cells of 2 cm, plus
  // the partly covered cells along its 6.79 m border (about half a cell
  // each: 170).
  const double cells = static_cast<double>(rep.cells + rep.holes_filled);
  EXPECT_NEAR(cells, 6830.0, 0.025 * 6830.0);
  EXPECT_EQ(rep.unknown_regions, 0u);
  EXPECT_EQ(rep.triangles, r.mesh.triangles.size());
  // Extremes over ~7000 cells of the noisy ground (sparse border cells included).
  EXPECT_NEAR(rep.bounds.max.z(), 0.0, 0.025);
  EXPECT_NEAR(rep.bounds.min.z(), 0.0, 0.025);
}

TEST(TerrainMesher, CropBoxRemovesTheDronesLegs) {
  // Legs seen by the camera: a dense cluster 0.15 m below the camera.
  syn::Shape s;
  auto sc = scan(s, 6);
  for (int k = 0; k < 2000; ++k) sc.cloud.points.emplace_back(0.1f + 0.0001f * (k % 10), 0.05f, 0.15f);
  sc.cloud.mark_unorganized();
  tt::TerrainOptions o;
  o.T_world_camera = sc.T_world_camera;
  o.crop_box_body = Eigen::AlignedBox3d(Eigen::Vector3d(0.05, 0, 0.1), Eigen::Vector3d(0.15, 0.1, 0.2));
  const auto r = tt::mesh_terrain(sc.cloud, o);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.report.points_cropped, 2000u);
  EXPECT_LT(r.report.bounds.max.z(), 0.02);
}

TEST(TerrainMesher, EmptyAndSingleCellClouds) {
  td::PointCloud nan_only;
  nan_only.points.assign(10, Eigen::Vector3f::Constant(NAN));
  auto r = tt::mesh_terrain(nan_only, tt::TerrainOptions{});
  EXPECT_EQ(r.status, tt::TerrainStatus::EmptyCloud);
  EXPECT_NE(r.message.find("10 not finite"), std::string::npos) << r.message;

  td::PointCloud one_cell;
  for (int k = 0; k < 50; ++k) one_cell.points.emplace_back(0.001f * (k % 5), 0.001f * (k / 10), 0.f);
  r = tt::mesh_terrain(one_cell, tt::TerrainOptions{});
  EXPECT_EQ(r.status, tt::TerrainStatus::TooSmall);
  EXPECT_NE(r.message.find("2 x 2"), std::string::npos) << r.message;
}

TEST(TerrainMesher, InvalidOptionsThrow) {
  tt::TerrainOptions o;
  o.height_map.cell = -1;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("cell"), std::string::npos);
  EXPECT_THROW(tt::mesh_terrain(td::PointCloud{}, o), td::InvalidArgument);
}
