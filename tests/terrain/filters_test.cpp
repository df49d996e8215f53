#include "touchdown/terrain/filters.hpp"

#include <gtest/gtest.h>

#include <set>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;

TEST(Filters, RemoveNonFinite) {
  td::PointCloud c;
  c.points = {{1, 2, 3}, {NAN, 0, 0}, {0, INFINITY, 0}, {4, 5, 6}};
  c.width = 2;
  c.height = 2;
  EXPECT_EQ(tt::remove_non_finite(c), 2u);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_FALSE(c.is_organized());
}

TEST(Filters, CropRadiusAndBodyBox) {
  td::PointCloud c;
  c.points = {{0, 0, 0.1f}, {0, 0, 1.0f}, {0.2f, 0, 0.5f}, {2, 0, 0.5f}};
  c.mark_unorganized();
  tt::CropOptions o;
  o.radius = 0.3;
  // Body frame = camera frame shifted by +1 in x; box around body x in [1.1, 1.3].
  o.T_body_camera = Eigen::Isometry3d(Eigen::Translation3d(1, 0, 0));
  o.box_body = Eigen::AlignedBox3d(Eigen::Vector3d(1.1, -0.1, 0.4), Eigen::Vector3d(1.3, 0.1, 0.6));
  EXPECT_EQ(tt::crop_near_camera(c, o), 2u);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(0, 0, 1));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(2, 0, 0.5f));
}

TEST(Filters, TransformAppliesIsometry) {
  td::PointCloud c;
  c.points = {{1, 0, 0}};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0, 0, 2);
  tt::transform_cloud(c, T);
  EXPECT_TRUE(c.points[0].isApprox(Eigen::Vector3f(0, 1, 2), 1e-6f));
}

TEST(Filters, VoxelDownsampleGivesOneCentroidPerVoxel) {
  td::Rng rng(3);
  td::PointCloud c;
  const double v = 0.1;
  std::set<std::tuple<long, long, long>> voxels;
  for (int i = 0; i < 5000; ++i) {
    const auto z = static_cast<float>(rng.uniform(0, 0.3));  // drawn z first, as recorded
    const auto y = static_cast<float>(rng.uniform(-1, 1));
    Eigen::Vector3f p(static_cast<float>(rng.uniform(-1, 1)), y, z);
    c.points.push_back(p);
    voxels.insert({static_cast<long>(std::floor(p.x() / v)), static_cast<long>(std::floor(p.y() / v)),
                   static_cast<long>(std::floor(p.z() / v))});
  }
  c.mark_unorganized();
  const auto d = tt::voxel_downsample(c, v);
  EXPECT_EQ(d.size(), voxels.size());
  // Each output point is the centroid of the input points of its voxel.
  for (std::size_t k = 0; k < d.size(); k += 37) {
    const auto& q = d.points[k];
    const auto key = std::make_tuple(static_cast<long>(std::floor(q.x() / v)), static_cast<long>(std::floor(q.y() / v)),
                                     static_cast<long>(std::floor(q.z() / v)));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (const auto& p : c.points) {
      if (std::make_tuple(static_cast<long>(std::floor(p.x() / v)), static_cast<long>(std::floor(p.y() / v)),
                          static_cast<long>(std::floor(p.z() / v))) == key) {
        sum += p.cast<double>();
        ++n;
      }
    }
    ASSERT_GT(n, 0);
    EXPECT_TRUE(q.cast<double>().isApprox(sum / n, 1e-5)) << k;
  }
}

TEST(Filters, VoxelDownsampleOfASparseWideCloudUsesTheSamePartition) {
  // 2 clusters 5 km apart: too many columns for the column grid.
  td::PointCloud c;
  c.points = {{0.01f, 0.01f, 0}, {0.02f, 0.02f, 0}, {5000.01f, 5000.01f, 0}, {5000.05f, 5000.01f, 0}};
  c.mark_unorganized();
  const auto d = tt::voxel_downsample(c, 0.03);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_TRUE(d.points[0].isApprox(Eigen::Vector3f(0.015f, 0.015f, 0)));
}

TEST(Filters, StatisticalOutliersAreRemoved) {
  // A noisy 1 m x 1 m plane sampled every cm plus 30 points floating 0.2-0.5 m above it.
  td::Rng rng(9);
  td::PointCloud c;
  for (int i = 0; i < 100; ++i)
    for (int j = 0; j < 100; ++j)
      c.points.emplace_back(static_cast<float>(i) * 0.01f, static_cast<float>(j) * 0.01f,
                            static_cast<float>(rng.normal(0, 0.002)));
  const std::size_t plane = c.size();
  for (int k = 0; k < 30; ++k) {
    const auto z = static_cast<float>(rng.uniform(0.2, 0.5));  // drawn z first, as recorded
    const auto y = static_cast<float>(rng.uniform(0, 1));
    c.points.emplace_back(static_cast<float>(rng.uniform(0, 1)), y, z);
  }
  c.mark_unorganized();
  const auto removed = tt::remove_statistical_outliers(c, tt::OutlierOptions{});
  EXPECT_GE(removed, 30u);
  EXPECT_LE(removed, 30u + plane / 100);  // keeps at least 99% of the plane
  for (const auto& p : c.points) EXPECT_LT(p.z(), 0.05f);
}

TEST(Filters, OutlierRemovalKWithTooFewPoints) {
  td::PointCloud c;
  c.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  c.mark_unorganized();
  EXPECT_EQ(tt::remove_statistical_outliers(c, tt::OutlierOptions{}), 0u);
  EXPECT_EQ(c.size(), 3u);
}

TEST(Filters, FlyingPixelsAcrossADepthJumpAndLoneSpikesAreRemoved) {
  // 7 x 5 organized cloud: left half at 1.0 m, right half at 1.3 m (a step
  // edge), one mixed pixel between them, one spike towards the camera, and a
  // steady slant that must survive.
  td::PointCloud c;
  c.width = 7;
  c.height = 5;
  for (int v = 0; v < 5; ++v)
    for (int u = 0; u < 7; ++u) {
      float z = u < 3 ? 1.0f + 0.004f * u : 1.3f;
      if (u == 3) z = v == 2 ? 1.15f : 1.3f;  // (3, 2) is the mixed pixel
      c.points.emplace_back(0.01f * u * z, 0.01f * v * z, z);
    }
  c.points[1 * 7 + 5].z() = 0.8f;  // spike at (5, 1)
  EXPECT_EQ(tt::remove_flying_pixels(c, 0.02), 2u);
  EXPECT_TRUE(std::isnan(c.points[2 * 7 + 3].z()));
  EXPECT_TRUE(std::isnan(c.points[1 * 7 + 5].z()));
  EXPECT_TRUE(c.is_organized());
  std::size_t finite = 0;
  for (const auto& p : c.points) finite += p.allFinite();
  EXPECT_EQ(finite, 33u);
  // Unorganized clouds are not touched.
  td::PointCloud u;
  u.points = {{0, 0, 1}, {0, 0, 2}, {0, 0, 1}};
  u.mark_unorganized();
  EXPECT_EQ(tt::remove_flying_pixels(u, 0.02), 0u);
}

// Every Options struct validates its fields and names the one at fault.
TEST(FilterOptions, ValidateNamesTheField) {
  td::test::expect_validate_names_fields<tt::CropOptions>({
      {"radius:", [](tt::CropOptions& o) { o.radius = -0.1; }},
      {"box_body:",
       [](tt::CropOptions& o) {
         o.box_body = Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 1, 0));
       }},
  });
  td::test::expect_validate_names_fields<tt::OutlierOptions>({
      {"std_ratio:", [](tt::OutlierOptions& o) { o.std_ratio = 0; }},
      {"k:", [](tt::OutlierOptions& o) { o.k = -1; }},
  });
  // Refused where they are used.
  td::PointCloud cloud;
  tt::CropOptions crop;
  crop.radius = -0.1;
  EXPECT_THROW(tt::crop_near_camera(cloud, crop), td::InvalidArgument);
  tt::OutlierOptions outliers;
  outliers.k = -1;
  EXPECT_THROW(tt::remove_statistical_outliers(cloud, outliers), td::InvalidArgument);
}
