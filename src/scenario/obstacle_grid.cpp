// MM-MLS's obstacle map (obstacle_grid.hpp).
#include "scenario/obstacle_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace touchdown::scenario::detail {

void ObstacleGrid::reset(const Eigen::Vector2d& centre, const MlsOptions& options) {
  const double cell = options.map_cell;
  cell_ = cell;
  min_height_ = options.obstacle_height;
  depth_samples_ = static_cast<double>(options.depth_samples);
  ground_hits_ = options.map_ground_hits;
  clear_frames_ = options.map_clear_frames;
  change_height_ = static_cast<float>(options.map_change_height);
  merge_height_ = static_cast<float>(options.box_merge_height);
  n_ = static_cast<int>(std::ceil(2 * options.map_half_extent / cell));
  origin_ = centre - Eigen::Vector2d::Constant(0.5 * n_ * cell);
  const auto count = static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_);
  height_.assign(count, 0.0f);
  free_frames_.assign(count, 0);
  stamp_.assign(count, 0);
  frame_max_.assign(count, 0.0f);
  frame_ground_.assign(count, 0);
  touched_.clear();
  touched_.reserve(8192);
  frame_ = 0;
  changes_ = 0;
}

void ObstacleGrid::integrate(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera,
                             const Eigen::Matrix3d& K_inv) {
  ++frame_;
  const int stride = std::max(1, static_cast<int>(std::lround(std::sqrt(f.width * f.height / depth_samples_))));
  const Eigen::Matrix3d M = T_world_camera.linear() * K_inv;
  const Eigen::Vector3d o = T_world_camera.translation();
  const Eigen::Vector3d dx = M.col(0) * static_cast<double>(stride);
  const double inv_cell = 1.0 / cell_;
  for (int y = 0; y < f.height; y += stride) {
    Eigen::Vector3d ray = M * Eigen::Vector3d(0, y, 1);  // the ray of pixel (x, y), moved along the row
    const float* row = f.depth.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width);
    for (int x = 0; x < f.width; x += stride, ray += dx) {
      const float d = row[x];
      if (!(d > 0 && d < std::numeric_limits<float>::max())) continue;  // sky (+inf) or no return
      const Eigen::Vector3d p = o + static_cast<double>(d) * ray;
      const double gx = (p.x() - origin_.x()) * inv_cell, gy = (p.y() - origin_.y()) * inv_cell;
      if (!(gx >= 0 && gy >= 0 && gx < n_ && gy < n_)) continue;
      const std::size_t i = index(static_cast<int>(gx), static_cast<int>(gy));
      if (stamp_[i] != frame_) {
        stamp_[i] = frame_;
        frame_max_[i] = 0;
        frame_ground_[i] = 0;
        touched_.push_back(i);
      }
      if (p.z() > min_height_) {
        frame_max_[i] = std::max(frame_max_[i], static_cast<float>(p.z()));
      } else if (frame_ground_[i] < 255) {
        ++frame_ground_[i];
      }
    }
  }
  for (const std::size_t i : touched_) {
    if (frame_max_[i] > 0) {
      // New, or clearly higher than mapped: the planner must look again.
      if (height_[i] == 0 || frame_max_[i] > height_[i] + change_height_) ++changes_;
      height_[i] = std::max(height_[i], frame_max_[i]);
      free_frames_[i] = 0;
    } else if (height_[i] > 0 && frame_ground_[i] >= ground_hits_ && ++free_frames_[i] >= clear_frames_) {
      height_[i] = 0;
      free_frames_[i] = 0;
      ++changes_;
    }
  }
  touched_.clear();
}

double ObstacleGrid::max_height_near(const Eigen::Vector2d& p, double radius) const {
  int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
  cell_range(p - Eigen::Vector2d::Constant(radius), p + Eigen::Vector2d::Constant(radius), &i0, &j0, &i1, &j1);
  double h = 0;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const float hc = height_[index(i, j)];
      if (hc <= h) continue;
      const Eigen::Vector2d lo = origin_ + cell_ * Eigen::Vector2d(i, j);
      const Eigen::Vector2d hi = lo + Eigen::Vector2d::Constant(cell_);
      const Eigen::Vector2d q = p.cwiseMax(lo).cwiseMin(hi);  // nearest point of the cell
      if ((q - p).squaredNorm() <= radius * radius) h = hc;
    }
  }
  return h;
}

bool ObstacleGrid::boxes(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double inflate, std::size_t max_boxes,
                         std::vector<plan::Box>* out) {
  out->clear();
  int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
  cell_range(lo, hi, &i0, &j0, &i1, &j1);
  if (i1 < i0 || j1 < j0) return true;
  const int w = i1 - i0 + 1;
  used_.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(j1 - j0 + 1), 0);
  const auto used = [&](int i, int j) -> std::uint8_t& {
    return used_[static_cast<std::size_t>(j - j0) * static_cast<std::size_t>(w) + static_cast<std::size_t>(i - i0)];
  };
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const float h0 = height_[index(i, j)];
      if (h0 <= 0 || used(i, j)) continue;
      const auto fits = [&](int a, int b) {
        const float h = height_[index(a, b)];
        return h > 0 && !used(a, b) && std::abs(h - h0) <= merge_height_;
      };
      int ie = i;
      while (ie + 1 <= i1 && fits(ie + 1, j)) ++ie;
      int je = j;
      for (;;) {
        if (je + 1 > j1) break;
        bool row_ok = true;
        for (int a = i; a <= ie && row_ok; ++a) row_ok = fits(a, je + 1);
        if (!row_ok) break;
        ++je;
      }
      double top = 0;
      for (int b = j; b <= je; ++b) {
        for (int a = i; a <= ie; ++a) {
          used(a, b) = 1;
          top = std::max(top, static_cast<double>(height_[index(a, b)]));
        }
      }
      if (out->size() == max_boxes) return false;
      plan::Box box;
      box.min = Eigen::Vector3d(origin_.x() + i * cell_ - inflate, origin_.y() + j * cell_ - inflate, 0);
      box.max = Eigen::Vector3d(origin_.x() + (ie + 1) * cell_ + inflate, origin_.y() + (je + 1) * cell_ + inflate,
                                top + inflate);
      out->push_back(box);
    }
  }
  return true;
}

void ObstacleGrid::cell_range(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int* i0, int* j0, int* i1,
                              int* j1) const {
  const auto clampi = [&](double g) { return static_cast<int>(std::clamp(std::floor(g), 0.0, n_ - 1.0)); };
  const Eigen::Vector2d a = (lo - origin_) / cell_, b = (hi - origin_) / cell_;
  if (b.x() < 0 || b.y() < 0 || a.x() >= n_ || a.y() >= n_) return;  // empty range
  *i0 = clampi(a.x());
  *j0 = clampi(a.y());
  *i1 = clampi(b.x());
  *j1 = clampi(b.y());
}

}  // namespace touchdown::scenario::detail
