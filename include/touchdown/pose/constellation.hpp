#pragma once
/// \file
/// Part of touchdown::pose.
/// The LED constellation carried by the drone: LED positions in the body
/// frame with their colour class, and where the ArUco marker of the baseline
/// sits (docs/formats.md). Thread-safe: plain values.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::pose {

/// LED colour classes used to prune correspondences. `Unknown` is only a
/// detection outcome (a blob whose hue fits no class); it matches any LED.
enum class LedColor : std::uint8_t { Red, Green, Blue, White, Unknown };

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::LedColor> {
  static constexpr std::array<std::string_view, 5> names{"red", "green", "blue", "white", "unknown"};
};

namespace touchdown::pose {

inline std::string_view to_string(LedColor color) { return enum_name(color); }
/// True if a blob classified as `detected` may be the LED of colour `led`.
inline bool colors_compatible(LedColor led, LedColor detected) {
  return detected == LedColor::Unknown || led == detected;
}

/// One LED: where it is, its colour class and where it shines.
///
/// Emission geometry is data: an LED with a `normal` emits into the cone of
/// half-angle `half_angle_deg` around it (a camera outside the cone does not
/// see it); an LED without a normal (the zero vector) is visible from every
/// direction. Nothing in touchdown assumes a body axis for the LEDs.
struct Led {
  Eigen::Vector3d p_body = Eigen::Vector3d::Zero();  ///< [m], body frame
  LedColor color = LedColor::White;
  /// Unit emission axis in the body frame; zero = omnidirectional.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double half_angle_deg = 90.0;  ///< emission cone half-angle [deg], in (0, 180); used with a normal

  [[nodiscard]] bool has_normal() const { return normal.squaredNorm() > 0; }
  /// True if a camera at `camera_body` (body frame) lies inside the emission
  /// cone widened by `margin_rad` (always true without a normal).
  [[nodiscard]] bool emits_toward(const Eigen::Vector3d& camera_body, double margin_rad = 0) const;
};

/// Largest constellation the tracker handles (fixed-size buffers).
inline constexpr std::size_t kMaxLeds = 16;

struct Constellation {
  std::vector<Led> leds;
  /// Pose of the baseline's ArUco marker in the body frame (marker frame as
  /// OpenCV's aruco: z out of the marker face, x right, y up). Default: at
  /// the body origin facing down (body z is up).
  Eigen::Isometry3d T_body_marker = default_marker_pose();

  static Eigen::Isometry3d default_marker_pose();
  [[nodiscard]] Eigen::Vector3d centroid() const;
  /// Mean distance of the LEDs from their centroid [m] (the scale the
  /// detector's outlier test compares the detections' spread with).
  [[nodiscard]] double mean_absolute_deviation() const;
  /// Largest distance of an LED from the centroid [m].
  [[nodiscard]] double radius() const;
  /// True if all LEDs lie within `tolerance` [m] of one plane.
  [[nodiscard]] bool planar(double tolerance = 1e-6) const;
  /// The direction the constellation faces: the normalised sum of the LED
  /// normals, or zero when no LED has one (or they cancel out).
  [[nodiscard]] Eigen::Vector3d facing() const;
  /// Rejects fewer than 4 or more than kMaxLeds LEDs, duplicates (closer
  /// than 1 mm), collinear sets, normals that are not unit length (within
  /// 1e-6) or not finite, and half-angles outside (0, 180), naming the LED.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The six-LED F450 constellation of data/constellations/f450_leds.yaml
/// (built in, for the benchmark and examples): under the body, shining down
/// (normal body −z, half-angle 90°).
Constellation default_constellation();

/// The source paper's six LEDs on a forward-facing front board of
/// data/constellations/front_board.yaml (built in, for the benchmark).
Constellation front_board_constellation();

/// Parses the constellation YAML; throws ParseError "source:line: key: what".
/// A `normal` is normalised on reading (any non-zero length).
Constellation parse_constellation(std::string_view yaml_text, std::string_view source);
Constellation load_constellation(const std::filesystem::path& path);
/// The constellation as YAML (round-trips through parse_constellation).
std::string constellation_to_yaml(const Constellation& constellation);

}  // namespace touchdown::pose
