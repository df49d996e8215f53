#pragma once
/// \file
/// Training and test frames for marker detectors, rendered from the test
/// world the way the landing systems see it, with labels from the world's
/// ground truth (`landing_scenario dataset`; docs/formats.md, "Detector
/// dataset").
///
/// Frame i of a dataset with seed S is drawn from its own generator
/// Rng(S, i): a random scenario (every weather, light and map property of
/// the bounds table, distractors of every kind, static and moving objects)
/// with the requested target marker, a camera pose of one of the systems'
/// phases (search at cruise altitude, descent, land, a far approach), and
/// sometimes an object moved between the camera and the target. The frame
/// depends on (S, i) only, so any thread count gives the same dataset.
/// Its split (train / validation / test) follows its own seed too, so no
/// scenario is in two splits; a benchmark takes frames from a seed never
/// used for training.
///
/// Thread-safety: render_dataset_frame is reentrant (a renderer per call).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/oracle.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

struct DatasetOptions {
  std::uint64_t seed = 1;
  std::string dictionary = "4X4_50";  ///< the target marker
  int marker_id = 0;
  CameraOptions camera;      ///< the systems' camera (640 × 480, 90°); tilt is drawn per frame
  double max_tilt_deg = 20;  ///< camera tilt drawn in [0, max] for a fifth of the frames
  double validation_fraction = 0.1;
  double test_fraction = 0.1;

  [[nodiscard]] bool validate(std::string* why) const;
};

/// A marker's outline in a frame.
struct QuadLabel {
  /// Corners in the image, clockwise, starting from the one nearest the
  /// image's top-left (the order the learned detector is trained on) [px].
  std::array<Eigen::Vector2d, 4> corners{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                         Eigen::Vector2d::Zero()};
  bool in_front = false;  ///< all four corners in front of the camera
  /// The corners' bounding box clipped to the image [px] (empty when out of view).
  Eigen::Vector2d box_min = Eigen::Vector2d::Zero(), box_max = Eigen::Vector2d::Zero();
  double inside_fraction = 0;   ///< of the marker's whole box, inside the image
  double visible_fraction = 0;  ///< of its area in the image, showing it in the mask (objects hide the rest)
  [[nodiscard]] bool in_view() const { return in_front && box_max.x() > box_min.x() && box_max.y() > box_min.y(); }
};

struct DistractorLabel {
  DistractorKind kind = DistractorKind::WrongId;
  QuadLabel quad;
};

enum class DatasetSplit { Train, Validation, Test };

struct DatasetFrame {
  int index = 0;
  std::uint64_t scenario_seed = 0;
  DatasetSplit split = DatasetSplit::Train;
  Scenario scenario;
  std::string_view phase;  ///< "search", "approach", "descent", "land"
  std::string weather;     ///< dominant_weather() of the scenario
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  CameraOptions camera;
  double distance = 0;  ///< camera to the target's centre [m]
  QuadLabel target;
  TargetView view;  ///< the observability oracle's reading of the target
  std::vector<DistractorLabel> distractors;
  std::string occluder;  ///< the object moved between camera and target, if any
  CameraFrame frame;
};

/// Renders `s` seen by `camera` from `state` and labels it (the target, the
/// distractors, the oracle's view): what render_dataset_frame does once it
/// has drawn a scene, for hand-built scenes too. Sets the frame's scenario,
/// weather, camera, pose, distance and labels only.
DatasetFrame label_frame(const Scenario& s, const CameraOptions& camera, const SceneState& state);

/// Renders frame `index` of the dataset; throws InvalidArgument for invalid options.
DatasetFrame render_dataset_frame(const DatasetOptions& options, int index);

/// The split of frame `index` (the first draw of its generator, as
/// render_dataset_frame draws it) without rendering the frame; throws
/// InvalidArgument for invalid options.
[[nodiscard]] DatasetSplit dataset_split(const DatasetOptions& options, int index);

/// A marker named "DICTIONARY:ID" ("4X4_50:0"): false, leaving both
/// unchanged, unless `text` is a name, a colon and a whole integer (the
/// name and the id's range are DatasetOptions::validate's to check).
bool parse_marker_spec(std::string_view text, std::string& dictionary, int& id);

/// Frame `f`'s line of labels.jsonl (docs/formats.md, "Detector dataset"),
/// its image at `image` (relative to the dataset directory). No newline.
[[nodiscard]] std::string dataset_label_json(const DatasetFrame& f, std::string_view image);

/// What write_dataset wrote: frames per split (train, validation, test).
struct DatasetSummary {
  int count = 0;
  std::array<int, 3> splits{};
};

/// Renders frames [0, count) of the dataset into the new directory `out`:
/// images/NNNNNN.png (8-bit grey, the systems' BGR frame converted as
/// cv::cvtColor's COLOR_BGR2GRAY), labels.jsonl (one line per frame, in
/// frame order) and dataset.json (format, seed, marker, camera, splits).
/// The frames are spread over `batch` (threads, progress, cancellation; the
/// files do not depend on the thread count). Written into a directory
/// beside `out` and renamed when complete, so a failed, cancelled or
/// interrupted run leaves no dataset; a cancelled one (`batch.cancel`)
/// writes nothing and returns a count of 0. Throws InvalidArgument for
/// invalid options or a count below 1, IoError when `out` exists, its
/// parent does not, or a file cannot be written.
DatasetSummary write_dataset(const DatasetOptions& options, int count, const std::filesystem::path& out,
                             const BatchOptions& batch = {});

}  // namespace touchdown::scenario

template <>
struct touchdown::EnumNames<touchdown::scenario::DatasetSplit> {
  static constexpr std::array<std::string_view, 3> names{"train", "validation", "test"};
};

namespace touchdown::scenario {

inline std::string_view to_string(DatasetSplit split) { return enum_name(split); }

}  // namespace touchdown::scenario
