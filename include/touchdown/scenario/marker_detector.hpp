#pragma once
/// \file
/// Marker detectors, behind one interface: a camera frame in, detections
/// out. Every landing system takes its detector by option
/// (MlsOptions::detector), so a user compares detectors on the same system.
/// Two implementations:
///   aruco    OpenCV's ArUco detector (the bit code: it reads the id, a
///            look-alike is read as the target only through the decoder's
///            error correction), optionally with a tracking ROI;
///   learned  a small convolutional detector trained on the test world's
///            frames (tools/train_detector.py), run through OpenCV's DNN
///            module: it gives a box, four corners and a confidence for
///            the one marker it was trained on (its manifest names the
///            dictionary and id), and can fail the way learned perception
///            fails (a look-alike, a white object or glare taken for the
///            marker).
///
/// Thread-safety: one detector object per thread (a campaign builds one
/// per worker); objects share nothing mutable.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/image.hpp"
#include "touchdown/core/registry.hpp"

namespace touchdown::scenario {

/// One detection in a frame. Pixels of the full frame (x right, y down).
struct MarkerDetection {
  Eigen::Vector2d box_min = Eigen::Vector2d::Zero();  ///< top-left of the axis-aligned box [px]
  Eigen::Vector2d box_max = Eigen::Vector2d::Zero();  ///< bottom-right [px]
  /// The marker's four corners, clockwise in the image, when `has_corners`:
  /// with `oriented`, in ArUco's order (the code's top-left corner first);
  /// else starting from the corner nearest the image's top-left (the
  /// detector did not read the code's rotation).
  std::array<Eigen::Vector2d, 4> corners{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(),
                                         Eigen::Vector2d::Zero()};
  bool has_corners = false;
  bool oriented = false;
  /// aruco: the decoded id; learned: the id of the marker the model was
  /// trained on (it has one class).
  int id = -1;
  double confidence = 0;  ///< in [0, 1] (aruco: 1 for a read code)

  [[nodiscard]] Eigen::Vector2d centre() const { return 0.5 * (box_min + box_max); }
};

/// A frame as a detector sees it: the colour image and its grey version
/// (the caller converts once; detectors use either).
struct DetectorFrame {
  BgrImageView bgr;
  GrayImageView gray;
};

/// Which detector and its settings (landing systems: MlsOptions::detector;
/// the apps: --detector, --model).
struct DetectorOptions {
  std::string kind = "aruco";  ///< "aruco" or "learned"
  /// While the target is tracked, search a region around it first (and
  /// the whole frame when that misses, and every full_frame_period-th
  /// frame; learned: only for frames of the network's input size, read at
  /// 1:1); false: the whole frame every time.
  bool roi = true;
  int full_frame_period = 10;
  /// learned: the ONNX model; empty = default_model_path().
  std::filesystem::path model;
  /// learned: detections below this confidence are not reported.
  double min_confidence = 0.3;
  /// learned: non-maximum suppression's box overlap (IoU) limit.
  double nms_iou = 0.45;

  /// False (with "key: what" in *why) for an unknown kind or a value out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The learned model shipped with touchdown: data/models/ of the source
/// tree, else of the installation (share/touchdown/models/); the
/// environment variable TOUCHDOWN_MODEL overrides both.
std::filesystem::path default_model_path();

/// What a learned model is, for results that depend on it (campaign.json's
/// "detector_model"): "fnv1a64:<hex>" of the ONNX file's bytes and then its
/// manifest's (which carries the verifier's sha256). Throws IoError naming
/// a file that cannot be read.
std::string learned_model_id(const std::filesystem::path& model);

class MarkerDetector {
 public:
  virtual ~MarkerDetector() = default;
  /// "aruco" or "learned" (or a user's), fixed for the object's life.
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Starts a run looking for `marker_id` of `dictionary` ("4X4_50", ...).
  /// Throws InvalidArgument when the detector cannot look for that marker
  /// (an unknown dictionary; a learned model trained on another marker).
  virtual void reset(std::string_view dictionary, int marker_id) = 0;
  /// The detections in `frame`, replacing `out`'s contents. Deterministic:
  /// the same frames after the same reset() give the same detections.
  virtual void detect(const DetectorFrame& frame, std::vector<MarkerDetection>& out) = 0;
  /// Tells the detector which detection of its last frame the system
  /// accepted as the target (nullptr: none), for region-of-interest
  /// tracking. The default ignores it.
  virtual void track(const MarkerDetection* /*accepted*/) {}
};

/// Makes a detector from its options (`kind` picked it).
using MakeDetector = std::function<std::unique_ptr<MarkerDetector>(const DetectorOptions&)>;

/// The registry of marker detectors (core/registry.hpp, the idiom of the
/// landing systems): `aruco` and `learned` built in; a detector you add is
/// valid as `DetectorOptions::kind` (`detector:` in system options).
Registry<MakeDetector>& detector_registry();

/// Builds the detector `options.kind` names; throws InvalidArgument for
/// invalid options and a clear error naming the model file when a learned
/// model is missing, truncated or of the wrong shape.
std::unique_ptr<MarkerDetector> make_marker_detector(const DetectorOptions& options);
/// detector_registry()'s names.
std::vector<std::string> marker_detector_names();

}  // namespace touchdown::scenario
