#pragma once
/// \file
/// Part of touchdown::pose_sim.
/// Trajectories of a drone seen by a camera, to render with the synthetic
/// camera (synthetic.hpp) for tests and benchmarks. Thread-safety: free
/// functions without shared state.
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"

namespace touchdown::pose {

enum class TrajectoryKind {
  /// The camera stands still; the drone hovers at ~6 hold points whose
  /// distances spread evenly over [min_distance, max_distance] (frames split
  /// evenly among them), with a few mm and ~0.5° of hovering jitter.
  Static,
  /// The distance sweeps smoothly min → max → min over the sequence, with
  /// lateral motion, continuous yaw rotation and tilt up to ~20°, fast enough
  /// to blur at short range.
  Moving,
};

/// Where the camera sees the drone from.
enum class CameraGeometry {
  /// The camera faces the constellation's facing side
  /// (Constellation::facing(); body −z, i.e. from below, when it has no
  /// normals): the facing axis points at the camera, the drone turns freely
  /// about it.
  Facing,
  /// The source paper's geometry: the camera on the ground vehicle looks
  /// back, tilted up by `camera_tilt_deg`; the drone follows behind and
  /// above, roughly level, heading toward the vehicle (body +x forward,
  /// ±15° of heading sway), so LEDs on its front face the camera.
  Chase,
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::TrajectoryKind> {
  static constexpr std::array<std::string_view, 2> names{"static", "moving"};
};

template <>
struct touchdown::EnumNames<touchdown::pose::CameraGeometry> {
  static constexpr std::array<std::string_view, 2> names{"facing", "chase"};
};

namespace touchdown::pose {

inline std::string_view to_string(TrajectoryKind kind) { return enum_name(kind); }
inline std::string_view to_string(CameraGeometry geometry) { return enum_name(geometry); }

/// Most frames make_trajectory makes (and led_pose renders): 100000 frames
/// are 55 minutes at 30 Hz.
inline constexpr int kMaxTrajectoryFrames = 100000;
/// [m] Farthest camera–constellation distance: beyond it an LED board is a
/// few pixels wide and the 16-bit depth image (65.5 m at 1 mm) saturates.
inline constexpr double kMaxTrajectoryDistance = 100.0;

struct TrajectoryOptions {
  double min_distance = 0.4;  ///< [m] camera–constellation (centroid) distance, in (0, max_distance]
  double max_distance = 3.0;  ///< [m] at most kMaxTrajectoryDistance
  double fps = 30;            ///< [Hz] sample rate
  double margin_px = 16;      ///< every LED stays this far inside the image
  CameraGeometry geometry = CameraGeometry::Facing;
  double camera_tilt_deg = 20;  ///< Chase: camera tilt above the horizontal [deg], in [0, 80]
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

struct TrajectorySample {
  double t = 0;  ///< [s]
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();
};

/// A trajectory of the drone seen by the camera in `options.geometry` that
/// keeps every LED inside the image by `margin_px` (the lateral offset,
/// then the tilt, shrink where needed). Deterministic in `seed`. Throws InvalidArgument for invalid
/// options (frames outside 1..kMaxTrajectoryFrames, distances not 0 < min ≤ max ≤
/// kMaxTrajectoryDistance, fps ≤ 0) or when the
/// constellation cannot fit in the image at min_distance.
std::vector<TrajectorySample> make_trajectory(TrajectoryKind kind, int frames, std::uint64_t seed,
                                              const CameraModel& camera, const Constellation& constellation,
                                              const TrajectoryOptions& options = {});

/// The pose to smear sample i's motion blur from: sample i−1, unless the
/// pose jumps by more than 0.1 m or 10° (a cut between hold points), then
/// sample i itself (no blur).
const Eigen::Isometry3d& motion_blur_start(std::span<const TrajectorySample> samples, std::size_t i);

}  // namespace touchdown::pose
