#pragma once
/// \file
/// Marker detectors measured on a labelled dataset (`landing_scenario
/// detect-bench`; docs/benchmarks.md): precision, recall and AP@0.5 of the
/// target, split by weather, distance band, visible fraction and phase;
/// false positives per 1 000 frames without the target; time per frame.
///
/// Which targets count (the benchmark's ground truth, whatever a detector
/// was trained on): a target is *positive* when it is in view with at least
/// 85 % of its box inside the image, at least 60 % of it unhidden and at
/// least 8 px a side; *ignored* when it is in view otherwise (a detection of
/// it is neither a hit nor a false positive); else the frame has *no target*.
/// A detection is of the target when its id is the target's; it hits when
/// its box overlaps the target's by IoU ≥ 0.5 (one hit per target; more are
/// false positives).
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <istream>
#include <string>
#include <vector>

#include "touchdown/scenario/marker_detector.hpp"

namespace touchdown::scenario {

/// One frame of a dataset's labels.jsonl (the keys the benchmark reads).
struct BenchLabel {
  std::string image;  ///< relative to the dataset directory
  std::string split, weather, phase;
  std::string sight;  ///< the observability oracle's reading of the target ("" when the labels give none)
  double distance = 0;
  bool in_view = false;
  std::array<Eigen::Vector2d, 4> corners{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                         Eigen::Vector2d::Zero()};
  bool has_corners = false;
  Eigen::Vector2d box_min = Eigen::Vector2d::Zero(), box_max = Eigen::Vector2d::Zero();
  double inside_fraction = 0, visible_fraction = 0;
  int distractors_in_view = 0;
};

/// The dataset's labels; throws ParseError naming "file:line: key" for a
/// line that is not JSON or lacks a key, IoError for a missing file.
std::vector<BenchLabel> read_bench_labels(const std::filesystem::path& labels_jsonl);
/// The same from a stream; `path` names it in errors.
std::vector<BenchLabel> parse_bench_labels(std::istream& in, const std::filesystem::path& path);

enum class TargetRole { Positive, Ignored, None };
TargetRole bench_role(const BenchLabel& label);

/// A detection of the target id, scored against the frame's target.
struct Scored {
  double confidence = 0;
  bool hit = false;
};

/// What one detector made of one frame.
struct BenchFrame {
  TargetRole role = TargetRole::None;
  std::vector<Scored> detections;  ///< of the target id (ignored-target matches left out)
  double ms = 0;                   ///< detect() time
};

/// Scores `found` (a detector's output on the frame of `label`) for the target id `id`.
BenchFrame score_frame(const BenchLabel& label, const std::vector<MarkerDetection>& found, int id);

/// All-point interpolated average precision (PASCAL VOC 2010 on): the area
/// under the precision-recall curve made monotone, detections ranked by
/// confidence (equal confidences keep the given order). NaN when there are
/// no positives.
double average_precision(std::vector<Scored> detections, int positives);

/// Figures of a set of frames at a confidence threshold.
struct BenchFigures {
  int frames = 0, positives = 0, hits = 0, false_positives = 0;
  double ap50 = 0;
  [[nodiscard]] double recall() const { return positives > 0 ? static_cast<double>(hits) / positives : 0.0; }
  [[nodiscard]] double precision() const {
    return hits + false_positives > 0 ? static_cast<double>(hits) / (hits + false_positives) : 1.0;
  }
};
BenchFigures bench_figures(const std::vector<const BenchFrame*>& frames, double threshold);

/// The distance band of a frame, one of distance_bands().
std::string distance_band(double distance);
/// "0-3 m", "3-6 m", "6-10 m", "10-15 m", "15+ m", from near to far.
const std::vector<std::string>& distance_bands();
/// The visible-fraction band of a positive target, one of visible_bands().
std::string visible_band(double visible_fraction);
/// "whole" (≥ 0.99), "0.8-0.99", "0.6-0.8".
const std::vector<std::string>& visible_bands();

}  // namespace touchdown::scenario
