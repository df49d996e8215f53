#pragma once
/// \file
/// The point cloud value type shared by every stage.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace touchdown {

/// A set of 3-D points (metres) in one frame, stored as floats like the
/// depth cameras and PCD files it comes from. An *organized* cloud keeps the
/// sensor's row-major pixel grid (`width` × `height`, missing pixels NaN);
/// an unorganized one has `height == 1` and `width == size()`.
///
/// Thread-safety: a plain value; const access from many threads is safe.
struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::uint32_t width = 0;
  std::uint32_t height = 1;
  /// The PCD file's `VIEWPOINT` (tx ty tz qw qx qy qz: the acquisition
  /// pose a sensor driver recorded); the identity for other formats and for
  /// clouds touchdown makes. Kept only as evidence that a cloud comes
  /// straight from a sensor (terrain::camera_frame_evidence): writers always
  /// write the identity, and transform_cloud resets it.
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] bool is_organized() const {
    return height > 1 && static_cast<std::size_t>(width) * height == points.size();
  }
  /// True unless `viewpoint` is the identity (q and -q are the same rotation).
  [[nodiscard]] bool has_viewpoint() const {
    constexpr double eps = 1e-6;
    return std::abs(viewpoint[0]) > eps || std::abs(viewpoint[1]) > eps || std::abs(viewpoint[2]) > eps ||
           std::abs(std::abs(viewpoint[3]) - 1) > eps || std::abs(viewpoint[4]) > eps || std::abs(viewpoint[5]) > eps ||
           std::abs(viewpoint[6]) > eps;
  }
  /// Forget the pixel grid (after points were removed or reordered).
  void mark_unorganized() {
    width = static_cast<std::uint32_t>(points.size());
    height = 1;
  }
};

}  // namespace touchdown
