#pragma once
// MM-MLS's obstacle map (landing_system.hpp): a world-frame grid of the
// highest obstacle point seen in each cell, built from the depth images and
// kept across frames (what the camera saw a moment ago is still there when
// it is out of view or hidden by the descent). A depth pixel is a world
// point o + depth·R K⁻¹ (u, v, 1) (depth along the optical axis,
// camera.hpp); points more than `obstacle_height` above the ground plane
// are obstacles, the others ground. A cell seen as ground in
// `map_clear_frames` frames with no obstacle point in between is cleared
// again, so that a person or a dog that walked away does not leave a wall
// behind; a thin pole hit now and then keeps its cell. Overhangs (a tree
// crown) count as solid down to the ground: the map is 2.5-D, which is what
// a descent needs. Private to the scenario module.
//
// Thread-safety: one grid per landing system. integrate() does not allocate
// once the first frames have grown its scratch list.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "touchdown/plan/corridor.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/landing_system.hpp"

namespace touchdown::scenario::detail {

class ObstacleGrid {
 public:
  /// An empty map of ±map_half_extent about `centre` in cells of map_cell,
  /// with the thresholds of `options` (already validated).
  void reset(const Eigen::Vector2d& centre, const MlsOptions& options);

  /// Adds one depth image (about depth_samples samples whatever the
  /// resolution).
  void integrate(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera, const Eigen::Matrix3d& K_inv);

  /// Counts the changes that matter to a plan (an obstacle cell appeared,
  /// grew or was cleared).
  [[nodiscard]] std::uint64_t changes() const { return changes_; }

  /// The highest obstacle with a cell (a square) within `radius` of p; 0 when none.
  [[nodiscard]] double max_height_near(const Eigen::Vector2d& p, double radius) const;

  /// The obstacle cells in [lo, hi] merged into axis-aligned boxes from the
  /// ground to their highest cell, each grown by `inflate` (also upwards).
  /// Greedy: a run of cells along x, extended along y while the whole run
  /// stays occupied; cells merge only with heights within box_merge_height
  /// of the first, so that a pole does not raise a whole box. Returns false
  /// (and leaves *out partial) beyond `max_boxes`.
  bool boxes(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double inflate, std::size_t max_boxes,
             std::vector<plan::Box>* out);

 private:
  [[nodiscard]] std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i);
  }
  void cell_range(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int* i0, int* j0, int* i1, int* j1) const;

  double cell_ = 0.25;
  double min_height_ = 0.3;
  double depth_samples_ = 76800;
  int ground_hits_ = 2;
  int clear_frames_ = 10;
  float change_height_ = 0.25f;
  float merge_height_ = 0.5f;
  int n_ = 0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::vector<float> height_;  // highest obstacle point [m]; 0 = free or never seen
  std::vector<std::uint8_t> free_frames_;
  std::vector<std::uint32_t> stamp_;  // the frame that last touched the cell
  std::vector<float> frame_max_;      // this frame's highest obstacle point per cell
  std::vector<std::uint8_t> frame_ground_;
  std::vector<std::size_t> touched_;
  std::vector<std::uint8_t> used_;
  std::uint32_t frame_ = 0;
  std::uint64_t changes_ = 0;
};

}  // namespace touchdown::scenario::detail
