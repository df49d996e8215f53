#pragma once
/// \file
/// Part of touchdown::pose_sim.
/// Image sequences on disk (written by write_sequence below, or recorded
/// from a camera):
///
///     NNNNNN.png          colour frame: 8-bit BGR (8-bit grey and BGRA accepted)
///     NNNNNN.depth.png    optional aligned depth: 16-bit, one channel
///     ground_truth.jsonl  optional: one JSON object per frame
///     camera.yaml, constellation.yaml
///     sequence.yaml       optional: how it was rendered (seed, ArUco marker)
///
/// ground_truth.jsonl is read by touchdown/pose/ground_truth.hpp (in
/// touchdown::pose: plain text, no OpenCV); this header reads images.
/// Thread-safety: free functions without shared state.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/image.hpp"
#include "touchdown/pose/ground_truth.hpp"
#include "touchdown/pose/sim/aruco_baseline.hpp"
#include "touchdown/pose/sim/synthetic.hpp"
#include "touchdown/pose/sim/trajectory.hpp"

namespace touchdown::pose {

struct SequenceFrame {
  std::string name;  ///< the file name without its extension: "000042", "frame_0001"
  std::filesystem::path colour;
  std::optional<std::filesystem::path> depth;
};

/// The frames of the sequence in `dir`: numbered images — PREFIX + number
/// + .png, .jpg or .jpeg, as write_sequence's "000042.png" or a camera's
/// "frame_0001.jpg" — sorted by number, each with its "NAME.depth.png" when
/// present. Throws IoError when `dir` is missing or not a directory,
/// ParseError when it holds no frames (naming the files it found), frames
/// of two numberings (two prefixes) or two files of one frame number.
std::vector<SequenceFrame> list_sequence(const std::filesystem::path& dir);

/// Reads a frame into `colour` (and `depth` unless null), reusing their
/// storage. Throws IoError naming the file when it is missing or unreadable,
/// ParseError when it is corrupt, not 8-bit colour/grey, or when the depth
/// image is not 16-bit single-channel of the colour frame's size. A frame
/// without depth leaves `*depth` empty.
void read_frame(const SequenceFrame& frame, BgrImage& colour, DepthImage* depth);

/// sequence.yaml: what write_sequence records besides the camera and the
/// constellation (docs/formats.md, "Image sequences"). Both parts are
/// optional: a sequence written before they were recorded, or recorded from
/// a camera, has neither.
struct SequenceInfo {
  std::optional<std::uint64_t> seed;  ///< the renderer's seed
  /// The rendered ArUco marker: `dictionary` (as written by render),
  /// `marker_id` and `marker_size`; the other fields keep their defaults.
  std::optional<ArucoOptions> aruco;
};

/// The file name of SequenceInfo in a sequence directory.
inline constexpr const char* kSequenceInfoFile = "sequence.yaml";

/// SequenceInfo as YAML text (numbers that read back exactly).
std::string sequence_info_to_yaml(const SequenceInfo& info);

/// Parses sequence.yaml text; ParseError "source:line: key: what" on a
/// malformed file (unknown or repeated key, a seed that is not an integer in
/// [0, 2^64), an invalid marker).
SequenceInfo parse_sequence_info(std::string_view yaml_text, std::string_view source);

/// Reads `dir`/sequence.yaml; an empty SequenceInfo when the file does not
/// exist. IoError when unreadable, ParseError when malformed.
SequenceInfo read_sequence_info(const std::filesystem::path& dir);

// ---- writing ----------------------------------------------------------------

/// Renders `samples` (frame i with Rng stream i, motion blur from sample
/// i−1 unless the pose jumps by more than 0.1 m or 10° between samples) and
/// writes into `out_dir`: NNNNNN.png (8-bit BGR), NNNNNN.depth.png (16-bit),
/// ground_truth.jsonl (ground_truth.hpp), camera.yaml, constellation.yaml and
/// sequence.yaml (`seed` and the marker of `options`).
/// The files are rendered into a staging directory next to `out_dir` and
/// moved into place at the end, so a failure leaves no partial files.
/// `out_dir` itself is created, never its parent. Over an existing sequence
/// the new one replaces it: the old one's files that the new one does not
/// overwrite (its frames beyond the new count) are removed, any other file
/// is kept. Throws InvalidArgument for invalid inputs, IoError when the
/// parent directory is missing or writing fails.
/// `progress`, when set, is called with (frames written, total) after each frame.
void write_sequence(const std::filesystem::path& out_dir, const CameraModel& camera, const Constellation& constellation,
                    std::span<const TrajectorySample> samples, const RenderOptions& options, std::uint64_t seed,
                    const ProgressCallback& progress = {});

}  // namespace touchdown::pose
