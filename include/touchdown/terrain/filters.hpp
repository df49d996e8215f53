#pragma once
/// \file
/// Point cloud filters of the terrain stage. All are deterministic, keep the
/// surviving points in their original relative order (except voxel
/// downsampling, which emits voxels in a fixed spatial order), and are
/// single-threaded; distinct clouds may be filtered from distinct threads.
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <string>

#include "touchdown/core/point_cloud.hpp"

namespace touchdown::terrain {

/// Drops points with a NaN or infinite coordinate; returns how many.
std::size_t remove_non_finite(PointCloud& cloud);

/// Jump-edge ("flying pixel") filter for organized depth clouds: a pixel
/// whose depth differs from both of its row neighbours, or from both of its
/// column neighbours, by more than `threshold_at_1m` · z² (metres; stereo
/// depth error grows with z²) is a mixed return across a depth
/// discontinuity or a lone spurious return, and is set to NaN. Unorganized
/// clouds are left alone. Returns how many points were invalidated.
std::size_t remove_flying_pixels(PointCloud& organized_camera, double threshold_at_1m);

/// p ← T · p for every point; the cloud's `viewpoint` becomes the identity.
void transform_cloud(PointCloud& cloud, const Eigen::Isometry3d& T);

struct CropOptions {
  /// Drop points closer than this to the camera centre (0 = off), metres.
  double radius = 0.0;
  /// Drop points inside this box, given in the drone body frame (the legs
  /// and propellers the camera sees).
  std::optional<Eigen::AlignedBox3d> box_body;
  /// Camera → body transform used to test the box.
  Eigen::Isometry3d T_body_camera = Eigen::Isometry3d::Identity();
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Removes points of a camera-frame cloud near the camera or on the drone;
/// returns how many were removed.
std::size_t crop_near_camera(PointCloud& cloud_camera, const CropOptions& options);

/// One point per occupied cubic voxel of edge `voxel` (the centroid of the
/// points in it), voxels aligned to multiples of `voxel`. Throws
/// InvalidArgument for a non-positive size.
PointCloud voxel_downsample(const PointCloud& cloud, double voxel);

struct OutlierOptions {
  int k = 8;               ///< neighbours per point
  double std_ratio = 2.0;  ///< keep mean distance ≤ μ + std_ratio·σ
  /// Neighbour search cell (metres); 0 = derived from the point density.
  double search_cell = 0.0;
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Statistical outlier removal (as in PCL's StatisticalOutlierRemoval, Rusu
/// et al. 2008): for each point the mean distance to its k nearest neighbours;
/// points whose mean exceeds μ + std_ratio·σ over the cloud are removed.
/// Returns how many were removed.
std::size_t remove_statistical_outliers(PointCloud& cloud, const OutlierOptions& options);

}  // namespace touchdown::terrain
