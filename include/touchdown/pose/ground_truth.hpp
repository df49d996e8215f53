#pragma once
/// \file
/// Part of touchdown::pose.
/// Ground-truth, attitude and pose files in JSON Lines (no OpenCV).
///
/// A ground-truth line: {"frame":"000000","t_s":0.0,"t":[x,y,z],
/// "q":[w,x,y,z],"leds_visible":[true,...],"marker_visible":true} with
/// T_camera_body = (q, t) (metres; q a unit quaternion). "leds_visible" and
/// "marker_visible" are optional; unknown keys are ignored.
/// Thread-safety: free functions without shared state.
#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace touchdown::pose {

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

/// One line of an attitude file (docs/formats.md, "Attitude"):
/// {"frame": "000000", "t_s": 0.0, "g_camera": [x, y, z], "g_body": [x, y, z],
/// "sigma_deg": 1.0} — the unit "down" direction measured by the camera's
/// (vehicle's) IMU in the camera frame and by the drone's IMU in its body
/// frame, each with sigma_deg of noise. Unknown keys are ignored.
struct AttitudeSample {
  std::string frame;
  double t_s = 0;
  Eigen::Vector3d g_camera = Eigen::Vector3d::Zero();  ///< unit (normalised on reading)
  Eigen::Vector3d g_body = Eigen::Vector3d::Zero();    ///< unit (normalised on reading)
  double sigma_deg = 0;                                ///< 1-σ of each direction [deg], in (0, 90]
  std::size_t line = 0;                                ///< the line it was read from (1-based)
};

/// Parses attitude JSON Lines; blank lines are skipped. Throws ParseError
/// "source:line: what" on a malformed line: bad JSON, a missing or
/// mistyped key, a non-finite number, a vector whose norm is more than
/// 1e-3 from 1, sigma_deg outside (0, 90], a frame given twice.
std::vector<AttitudeSample> parse_attitude(std::string_view text, std::string_view source);

/// Reads an attitude file; IoError if unreadable, ParseError if malformed.
std::vector<AttitudeSample> read_attitude(const std::filesystem::path& path);

}  // namespace touchdown::pose
