#pragma once
// The tracking shortcut both marker detectors take (aruco_detector.hpp,
// learned_detector.hpp): while a target is tracked, search a region around
// where it was last accepted first, and the whole frame when the region
// finds nothing and at least every `full_frame_period`-th frame, so the
// region never hides the target and distractors are still seen regularly
// (docs/architecture.md, "Marker detectors"). Private to the scenario module.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

namespace touchdown::scenario::detail {

class TrackingRegion {
 public:
  /// How the region is drawn around the last accepted box: grown by
  /// `grow_factor` times the box's longer side (at least `min_grow` px) on
  /// every side, out to a grid of `grid` px, clipped to the frame; a region
  /// narrower than `min_side` or over half the frame saves nothing.
  struct Shape {
    double grow_factor = 1;
    double min_grow = 32;
    int grid = 1;
    int min_side = 16;
  };

  TrackingRegion(bool enabled, int full_frame_period, Shape shape)
      : enabled_(enabled), full_frame_period_(std::max(1, full_frame_period)), shape_(shape) {}

  /// Forgets the target (a new run).
  void reset() {
    tracking_ = false;
    since_full_ = 0;
  }

  /// Starts a frame of `width` × `height`: the region to search first, or
  /// an empty one when the whole frame is due.
  cv::Rect next(int width, int height) {
    ++since_full_;
    if (!enabled_ || !tracking_ || since_full_ >= full_frame_period_) return {};
    const int g = std::max(1, shape_.grid);
    const Eigen::Vector2d size = max_ - min_;
    const double grow = std::max({shape_.grow_factor * size.x(), shape_.grow_factor * size.y(), shape_.min_grow});
    const auto cells = [&](double v) { return std::clamp(v / g, -1e6, 1e6); };  // no overflow in the casts
    const auto down = [&](double v, int hi) { return std::clamp(g * static_cast<int>(std::floor(cells(v))), 0, hi); };
    const auto up = [&](double v, int hi) { return std::clamp(g * static_cast<int>(std::ceil(cells(v))), 0, hi); };
    const int x0 = down(min_.x() - grow, width), x1 = up(max_.x() + grow, width);
    const int y0 = down(min_.y() - grow, height), y1 = up(max_.y() + grow, height);
    const int w = x1 - x0, h = y1 - y0;
    if (w < shape_.min_side || h < shape_.min_side || w % g != 0 || h % g != 0 || 2 * w * h > width * height) return {};
    return {x0, y0, w, h};
  }

  /// The whole frame was searched: the full-frame period starts again.
  void searched_whole() { since_full_ = 0; }

  /// The detection the system accepted this frame (its box [px]), or
  /// nothing: the target is no longer tracked.
  void track(const Eigen::Vector2d* box_min, const Eigen::Vector2d* box_max) {
    tracking_ = box_min && box_max && box_min->allFinite() && box_max->allFinite();
    if (!tracking_) return;
    min_ = *box_min;
    max_ = *box_max;
  }

 private:
  bool enabled_;
  int full_frame_period_;
  Shape shape_;
  bool tracking_ = false;
  int since_full_ = 0;
  Eigen::Vector2d min_ = Eigen::Vector2d::Zero(), max_ = Eigen::Vector2d::Zero();
};

}  // namespace touchdown::scenario::detail
