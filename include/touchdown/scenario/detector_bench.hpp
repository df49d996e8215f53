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
#include <memory>
#include <string>
#include <vector>

#include "touchdown/core/batch.hpp"
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

/// A dataset's target marker (its dataset.json). Throws IoError when the
/// file cannot be read, ParseError naming the file and key otherwise.
struct DatasetMarker {
  std::string dictionary;
  int id = 0;
};
DatasetMarker read_dataset_marker(const std::filesystem::path& dataset_dir);

/// Runs every detector on every frame: result[d][i] is detectors[d] on
/// labels[i] (its image read as 8-bit grey from `dataset_dir`), scored for
/// the marker, with its detect() time. Each detector is reset to the marker
/// before each frame (no tracking across frames). `progress` is called after
/// each frame (index = the frame). Throws IoError for an image OpenCV cannot read.
std::vector<std::vector<BenchFrame>> run_detector_bench(const std::filesystem::path& dataset_dir,
                                                        const std::vector<BenchLabel>& labels,
                                                        const DatasetMarker& marker,
                                                        const std::vector<std::unique_ptr<MarkerDetector>>& detectors,
                                                        const ProgressCallback& progress = {});

/// What the report says about its input.
struct BenchReportInfo {
  std::string dataset;  ///< the directory, as the user named it
  std::string split = "all";
  DatasetMarker marker;
  double threshold = 0.7;  ///< confidence from which a detection counts (AP uses every confidence)
};

/// The benchmark's figures: per group of frames (all, by weather, distance
/// band, visible fraction, phase, the oracle's sight, and clear weather
/// with the target observable) each detector's recall, precision and
/// AP@0.5; then per detector false positives per 1 000 frames without the
/// target (and on those with distractors in view) and the median time per
/// frame. `names[d]` names `runs[d]`; every run has one frame per label.
struct BenchReport {
  std::string json;  ///< one line, no newline
  std::string text;  ///< the table and the per-detector lines, for a person
};
BenchReport bench_report(const std::vector<std::string>& names, const std::vector<std::vector<BenchFrame>>& runs,
                         const std::vector<BenchLabel>& labels, const BenchReportInfo& info);

/// Recall of the target against the distance band (SVG): one panel per
/// weather kind (small multiples), one line per detector; a band's point
/// needs at least 10 targets.
std::string bench_recall_plot(const std::vector<std::string>& names, const std::vector<std::vector<BenchFrame>>& runs,
                              const std::vector<BenchLabel>& labels, double threshold, const std::string& title);

}  // namespace touchdown::scenario
