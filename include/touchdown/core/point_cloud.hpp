#pragma once
/// \file
/// The point cloud value type shared by every stage.
#include <Eigen/Core>
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

  [[nodiscard]] std::size_t size() const { return points.size(); }
  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] bool is_organized() const {
    return height > 1 && static_cast<std::size_t>(width) * height == points.size();
  }
  /// Forget the pixel grid (after points were removed or reordered).
  void mark_unorganized() {
    width = static_cast<std::uint32_t>(points.size());
    height = 1;
  }
};

}  // namespace touchdown
