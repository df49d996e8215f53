#pragma once
// The learned marker detector (touchdown/scenario/marker_detector.hpp): a
// small one-stage centre-heatmap network (after CenterNet: Zhou, Wang and
// Krähenbühl, "Objects as Points", 2019) trained by tools/train_detector.py
// on the test world's frames and run through OpenCV's DNN module. Private
// to the scenario module; the decoding is exposed for its tests.
//
// The model file is ONNX; its manifest (the same name with .json) says
// which marker it detects and how its input and output are laid out
// (docs/formats.md, "Detector model"):
//   input   1 × 1 × H × W grey levels / 255 (the frame letterboxed to W × H);
//   output  1 × 11 × H/s × W/s: channel 0 the centre heatmap (a sigmoid,
//           in [0, 1]), 1–2 the centre's offset in its cell [cells], 3–10
//           the four corners relative to the centre [corner_scale px of
//           the network's input], clockwise from the one nearest the
//           image's top-left.
// Format 2 adds a second stage: the heat map proposes (peaks above the
// manifest's proposal threshold, the highest few), and a verifier network
// reads each proposal at the frame's own resolution — the frame warped
// through its corners to a small patch (extract_patch) — and gives the
// detection's confidence. The stride-8 heat map finds a marker 10 m away
// but cannot read its code; the patch can (docs/architecture.md).
#include <array>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scenario/tracking_region.hpp"
#include "touchdown/scenario/marker_detector.hpp"

namespace touchdown::scenario::detail {

/// The second stage a "touchdown-detector/2" manifest names: a verifier
/// that reads each proposal at the frame's own resolution (the frame
/// warped through the proposal's corners to a patch × patch square) and
/// gives the detection's confidence.
struct VerifierManifest {
  std::filesystem::path file;     ///< the verifier's ONNX file (beside the model)
  int patch = 0;                  ///< its input side [px]
  int margin_cells = 0;           ///< white margin around the code in the patch [cells]
  int cells = 0;                  ///< the code's side with its black border [cells] (the dictionary's)
  double min_range = 0;           ///< the normalisation's smallest stretch [grey levels]
  double proposal_threshold = 0;  ///< the first stage's heat that makes a proposal
  int max_proposals = 0;          ///< proposals verified per frame (highest heat first)
};

/// A model's manifest (the keys the detector needs).
struct ModelManifest {
  std::string dictionary;
  int marker_id = 0;
  int width = 0, height = 0;  ///< the network's input [px]
  int stride = 0;             ///< input pixels per output cell
  int channels = 0;           ///< output channels (11)
  double corner_scale = 0;    ///< corner offsets' unit [input px]
  double pad_value = 0;       ///< letterbox fill, grey level / 255
  /// format "touchdown-detector/2": the verifier (absent in /1 models).
  std::optional<VerifierManifest> verifier;
};

/// Reads and checks `path` (JSON); throws InvalidArgument naming the file
/// and the key for a missing file, bad JSON or a missing/invalid key.
ModelManifest read_model_manifest(const std::filesystem::path& path);
/// The same from the manifest's text (`path` names it in errors).
ModelManifest parse_model_manifest(std::string_view text, const std::filesystem::path& path);
/// The manifest beside a model: the same path with ".json".
std::filesystem::path manifest_path(const std::filesystem::path& model);

/// How a frame of `width` × `height` maps into the network's input: scaled
/// by `scale` and shifted by `offset` (letterboxing keeps the aspect ratio).
struct Letterbox {
  double scale = 1;
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  int width = 0, height = 0;  ///< the scaled frame inside the input [px]
};
Letterbox letterbox(int frame_width, int frame_height, int input_width, int input_height);

/// Decodes one output (channels × rows × cols floats, row-major per
/// channel): every cell whose heat is at least `min_confidence` and not
/// below any of its 8 neighbours is a candidate; corners and box in frame
/// pixels through `box`; then greedy non-maximum suppression (highest
/// confidence first, ties by cell order) drops any candidate whose box
/// overlaps a kept one by more than `nms_iou` (intersection over union).
std::vector<MarkerDetection> decode_heatmap(const float* out, int rows, int cols, const ModelManifest& m,
                                            const Letterbox& box, double min_confidence, double nms_iou, int id);

/// The verifier's input for a proposal (tools/detector_model.py,
/// extract_patch, does the same with the same OpenCV calls): the
/// corners' quad grown by the margin about its centre bounds a crop (1 px
/// more each side, clipped to the frame); a code more than twice the
/// patch's code size is shrunk by area averaging first; the crop is warped
/// so the corners land on the patch's code square (bilinear, border
/// replicated); then (v − min) / max(max − min, min_range). False (and
/// `patch` untouched) when the proposal lies outside the frame or is
/// degenerate. `patch` becomes CV_32FC1 of v.patch × v.patch.
bool extract_patch(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, const VerifierManifest& v,
                   cv::Mat& patch);

/// Intersection over union of two axis-aligned boxes (0 when either is empty).
double box_iou(const MarkerDetection& a, const MarkerDetection& b);
/// The same for boxes given by their corners (min, max) [px].
double box_iou(const Eigen::Vector2d& a_min, const Eigen::Vector2d& a_max, const Eigen::Vector2d& b_min,
               const Eigen::Vector2d& b_max);

class LearnedDetector final : public MarkerDetector {
 public:
  /// Loads `model` and its manifest, and runs it once on a blank input to
  /// check its output's shape; throws InvalidArgument naming the file for
  /// a missing, truncated or wrong-shape model.
  /// `roi`: while the target is tracked, run the network at full
  /// resolution on a region around it first (the whole frame when that
  /// finds nothing, and every `full_frame_period`-th frame), as the ArUco
  /// detector does; false: the whole frame every time.
  LearnedDetector(std::filesystem::path model, double min_confidence, double nms_iou, bool roi = false,
                  int full_frame_period = 10);

  [[nodiscard]] std::string_view name() const override { return "learned"; }
  void reset(std::string_view dictionary, int marker_id) override;
  void detect(const DetectorFrame& frame, std::vector<MarkerDetection>& out) override;
  void track(const MarkerDetection* accepted) override;

  /// The network's raw output for a grey frame (for the PyTorch cross-check).
  const cv::Mat& forward(const cv::Mat& gray);
  /// The verifier's probability for a patch (extract_patch's output; for
  /// the PyTorch cross-check); throws std::logic_error for a /1 model.
  double verify_patch(const cv::Mat& patch);
  [[nodiscard]] const ModelManifest& manifest() const { return manifest_; }
  /// The region the last detect() searched at the end: the whole frame's
  /// rectangle, or the tracking region when that found the target.
  [[nodiscard]] const cv::Rect& last_region() const { return last_region_; }

 private:
  std::filesystem::path path_;
  ModelManifest manifest_;
  double min_confidence_;
  double nms_iou_;
  cv::dnn::Net net_;
  cv::dnn::Net verifier_;  ///< empty for a /1 model
  cv::Mat input_, blob_, output_;
  cv::Mat patch_, patch_blob_;
  Letterbox box_;
  TrackingRegion region_;
  cv::Rect last_region_;

  /// The network on input_ (filled by forward or forward_region) into output_.
  const cv::Mat& run_input();
  /// output_ decoded through box_ (the last input's mapping to the frame).
  [[nodiscard]] std::vector<MarkerDetection> decode_output() const;
  /// The network on `gray(region)` at 1:1 (region sides multiples of 32).
  void forward_region(const cv::Mat& gray, const cv::Rect& region);
  /// Loads and checks the verifier the manifest names (constructor).
  void load_verifier();
  /// The first stage's proposals in `out` verified on `gray`: each of the
  /// first max_proposals gets the verifier's probability as its
  /// confidence; those below min_confidence and the rest are dropped.
  void verify(const cv::Mat& gray, std::vector<MarkerDetection>& out);
};

}  // namespace touchdown::scenario::detail
