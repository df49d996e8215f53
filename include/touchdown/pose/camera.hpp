#pragma once
/// \file
/// Camera intrinsics for the LED pose pipeline: a pinhole model with
/// optional Brown–Conrady distortion (OpenCV's k1, k2, p1, p2, k3 order) and
/// the scale of an aligned 16-bit depth image, loaded from the camera YAML
/// (docs/formats.md). Thread-safe: plain values.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <string_view>

namespace touchdown::pose {

/// Pinhole intrinsics in pixels (undistorted image coordinates).
struct PinholeCamera {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  [[nodiscard]] Eigen::Vector2d project(const Eigen::Vector3d& p_camera) const {
    return {fx * p_camera.x() / p_camera.z() + cx, fy * p_camera.y() / p_camera.z() + cy};
  }
  /// The ray through pixel `uv` scaled to depth z: (x, y, z) in the camera frame.
  [[nodiscard]] Eigen::Vector3d back_project(const Eigen::Vector2d& uv, double z) const {
    return {(uv.x() - cx) / fx * z, (uv.y() - cy) / fy * z, z};
  }
};

/// A calibrated camera (OpenCV axes: x right, y down, z forward).
struct CameraModel {
  int width = 848;
  int height = 480;
  double fx = 615.0, fy = 615.0, cx = 423.5, cy = 239.5;
  std::array<double, 5> distortion{};  ///< k1, k2, p1, p2, k3; all zero = none
  double depth_scale = 0.001;          ///< metres per unit of the 16-bit depth image

  [[nodiscard]] PinholeCamera pinhole() const { return {fx, fy, cx, cy}; }
  [[nodiscard]] bool has_distortion() const;
  /// Pixel of a camera-frame point, through the distortion model.
  [[nodiscard]] Eigen::Vector2d project(const Eigen::Vector3d& p_camera) const;
  /// Undistorted (pinhole) pixel of a distorted pixel; inverts the
  /// distortion by fixed-point iteration (as OpenCV's undistortPoints).
  [[nodiscard]] Eigen::Vector2d undistort(const Eigen::Vector2d& uv_distorted) const;
  /// False with a reason naming the key if a value is out of range.
  bool validate(std::string* why) const;
};

/// Parses the camera YAML; throws ParseError "source:line: key: what".
CameraModel parse_camera(std::string_view yaml_text, std::string_view source);
/// Loads the camera YAML; IoError if unreadable, ParseError if malformed.
CameraModel load_camera(const std::filesystem::path& path);
/// The camera as YAML (round-trips through parse_camera).
std::string camera_to_yaml(const CameraModel& camera);

}  // namespace touchdown::pose
