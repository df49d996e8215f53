#pragma once
/// \file
/// Image sequences on disk (written by write_sequence in synthetic.hpp, or
/// recorded from a camera):
///
///     NNNNNN.png          colour frame: 8-bit BGR (8-bit grey and BGRA accepted)
///     NNNNNN.depth.png    optional aligned depth: 16-bit, one channel
///     ground_truth.jsonl  optional: one JSON object per frame
///     camera.yaml, constellation.yaml
///
/// A ground-truth line: {"frame":"000000","t_s":0.0,"t":[x,y,z],
/// "q":[w,x,y,z],"leds_visible":[true,...],"marker_visible":true} with
/// T_camera_body = (q, t) (metres; q a unit quaternion). "leds_visible" and
/// "marker_visible" are optional; unknown keys are ignored.
/// Thread-safety: free functions without shared state.
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/pose/image.hpp"

namespace touchdown::pose {

struct SequenceFrame {
  std::string name;  ///< "000042"
  std::filesystem::path colour;
  std::optional<std::filesystem::path> depth;
};

/// The frames of the sequence in `dir`: files named exactly six digits +
/// ".png", sorted by name, each with its "NNNNNN.depth.png" when present.
/// Throws IoError when `dir` is missing or not a directory, ParseError when
/// it holds no frames.
std::vector<SequenceFrame> list_sequence(const std::filesystem::path& dir);

/// Reads a frame into `colour` (and `depth` unless null), reusing their
/// storage. Throws IoError naming the file when it is missing or unreadable,
/// ParseError when it is corrupt, not 8-bit colour/grey, or when the depth
/// image is not 16-bit single-channel of the colour frame's size. A frame
/// without depth leaves `*depth` empty.
void read_frame(const SequenceFrame& frame, BgrImage& colour, DepthImage* depth);

struct GroundTruthSample {
  std::string frame;  ///< frame name ("000042")
  double t_s = 0;     ///< [s]
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();
  std::vector<bool> leds_visible;  ///< empty when not recorded
  bool marker_visible = false;
};

/// One ground-truth JSON line (no newline), doubles printed so that they read
/// back exactly.
std::string ground_truth_to_json(const GroundTruthSample& sample);

/// Parses ground_truth.jsonl text; blank lines are skipped. Throws
/// ParseError "source:line: what" on a malformed line (bad JSON, missing or
/// mistyped key, non-finite number, quaternion far from unit norm).
std::vector<GroundTruthSample> parse_ground_truth(std::string_view text, std::string_view source);

/// Reads ground_truth.jsonl; IoError if unreadable, ParseError if malformed.
std::vector<GroundTruthSample> read_ground_truth(const std::filesystem::path& path);

}  // namespace touchdown::pose
