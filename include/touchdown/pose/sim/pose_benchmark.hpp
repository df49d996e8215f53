#pragma once
/// \file
/// Part of touchdown::pose_sim.
/// The LED-vs-ArUco benchmark of `led_pose benchmark` (the paper's table):
/// renders static and moving-camera sequences with the synthetic camera,
/// runs the LED tracker and the ArUco baseline on the same frames and
/// reports, per method and sequence, the mean and standard deviation of the
/// position error [m] and orientation error [rad, angle-axis] over the
/// successful frames, the detection success rate (frames with a pose whose
/// reprojection error is below `success_px`) and the per-frame time.
/// It also times EPnP + Gauss–Newton against OpenCV's solvePnP on the
/// tracker's matched LEDs.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/sim/aruco_baseline.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

namespace touchdown::pose {

/// One camera geometry and constellation to render static and moving
/// sequences of.
struct BenchmarkScenario {
  std::string name;  ///< names the rows ("f450 below", "paper chase")
  Constellation constellation;
  CameraGeometry geometry = CameraGeometry::Facing;
  double camera_tilt_deg = 20;  ///< Chase only
  /// Rendered with PoseBenchmarkOptions::render under this profile.
  RenderProfile profile = RenderProfile::Clean;
};

/// The three built-in scenarios: the F450's downward LEDs seen from below
/// (default_constellation(), Facing), and the source paper's setup
/// (front_board_constellation() on the drone's front, the ground
/// vehicle's camera tilted 20° up, Chase) in the clean and the harsh
/// render profile.
std::vector<BenchmarkScenario> default_benchmark_scenarios();

struct PoseBenchmarkOptions {
  CameraModel camera;
  /// The scenarios to run; empty = one Facing scenario named "custom" of
  /// `constellation`.
  std::vector<BenchmarkScenario> scenarios;
  Constellation constellation;  ///< used when `scenarios` is empty
  int frames = 300;             ///< per sequence
  std::uint64_t seed = 1;
  double min_distance = 0.4, max_distance = 3.0;  ///< [m]
  double success_px = 10.0;                       ///< success: a pose with reprojection RMS below this [px]
  bool use_depth = true;
  RenderOptions render;
  TrackerOptions tracker;
  ArucoOptions aruco;  ///< dictionary/id/size are copied into the render options
  /// `render` with the marker of `aruco` (dictionary, id, size): what the
  /// benchmark renders, so what validate() checks.
  [[nodiscard]] RenderOptions rendered_options() const;
  [[nodiscard]] bool validate(std::string* why) const;
};

struct MethodStats {
  std::string scenario;  ///< BenchmarkScenario::name
  std::string profile;   ///< its render profile: "clean" or "harsh"
  std::string method;    ///< "led" or "aruco"
  std::string sequence;  ///< "static" or "moving"
  int frames = 0;
  int successes = 0;
  double success_rate = 0;
  /// Frames reported ok (any reprojection error) whose pose is more than
  /// 0.1 m or 0.1 rad wrong: the error a pose estimator must not make.
  int wrong_ok = 0;
  double wrong_ok_rate = 0;
  double position_mean_m = 0, position_std_m = 0;
  double orientation_mean_rad = 0, orientation_std_rad = 0;
  double position_max_m = 0;
  double ms_median = 0, ms_p90 = 0;  ///< per-frame time of the whole method
};

enum class PoseBenchmarkStatus {
  Ok,                  ///< every method had successful frames on every sequence
  NoSuccessfulFrames,  ///< some row has no successful frame: its error statistics are undefined (reported as 0)
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::PoseBenchmarkStatus> {
  static constexpr std::array<std::string_view, 2> names{"ok", "no successful frames"};
};

namespace touchdown::pose {

inline std::string_view to_string(PoseBenchmarkStatus status) { return enum_name(status); }

struct PoseBenchmarkResult {
  PoseBenchmarkStatus status = PoseBenchmarkStatus::Ok;
  std::string message;  ///< which rows, when status is not Ok
  [[nodiscard]] bool ok() const { return status == PoseBenchmarkStatus::Ok; }
  std::vector<MethodStats> rows;
  int solver_samples = 0;                 ///< frames where the solvers were timed
  double epnp_gn_us_median = 0;           ///< our EPnP + Gauss–Newton on the matched LEDs
  double opencv_iterative_us_median = 0;  ///< cv::solvePnP SOLVEPNP_ITERATIVE on the same points
  double opencv_sqpnp_us_median = 0;      ///< cv::solvePnP SOLVEPNP_SQPNP
  double opencv_epnp_us_median = 0;       ///< cv::solvePnP SOLVEPNP_EPNP
};

/// Runs the benchmark (single-threaded, deterministic in everything but
/// the timings). Throws InvalidArgument on invalid options; a method that
/// never succeeds is the expected outcome NoSuccessfulFrames, not an error.
PoseBenchmarkResult run_pose_benchmark(const PoseBenchmarkOptions& options);

/// Position error [m] and angle-axis orientation error [rad] of `estimate`.
std::pair<double, double> pose_error(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth);

/// The benchmark's figures as one JSON line (keys sorted): status,
/// frames per sequence, seed, one row per scenario, method and sequence,
/// and the solvers' median times.
[[nodiscard]] std::string benchmark_json(const PoseBenchmarkResult& r, int frames_per_sequence, std::uint64_t seed);

/// The same as the table `led_pose benchmark` prints. Ends in a newline.
[[nodiscard]] std::string benchmark_table(const PoseBenchmarkResult& r);

}  // namespace touchdown::pose
