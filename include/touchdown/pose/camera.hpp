#pragma once
/// \file
/// Part of touchdown::pose.
/// Camera intrinsics for the LED pose pipeline: a pinhole model with
/// optional Brown–Conrady distortion (OpenCV's k1, k2, p1, p2, k3 order) and
/// the scale of an aligned 16-bit depth image, loaded from the camera YAML
/// or from the calibration files users already have: OpenCV's FileStorage
/// YAML and ROS camera_info YAML (docs/formats.md). Thread-safe: plain
/// values and free functions without shared state.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <string>
#include <string_view>

#include "touchdown/core/image.hpp"

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
  /// Pixel `uv` lies at least `margin` [px] inside the image (pixel centres
  /// 0 … width − 1, 0 … height − 1).
  [[nodiscard]] bool in_image(const Eigen::Vector2d& uv, double margin = 0) const {
    return uv.x() >= margin && uv.y() >= margin && uv.x() <= width - 1 - margin && uv.y() <= height - 1 - margin;
  }
  /// Undistorted (pinhole) pixel of a distorted pixel; inverts the
  /// distortion by fixed-point iteration (as OpenCV's undistortPoints).
  [[nodiscard]] Eigen::Vector2d undistort(const Eigen::Vector2d& uv_distorted) const;
  /// False with a reason naming the key if a value is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Parses a camera file, its format told by its content (docs/formats.md):
/// touchdown's camera YAML; an OpenCV calibration file (cv::FileStorage
/// YAML: `camera_matrix`/`cameraMatrix`, `distortion_coefficients`/
/// `distCoeffs`, `image_width`, `image_height`); a ROS camera_info YAML
/// (camera_calibration_parsers: the same names plus `distortion_model`).
/// Throws ParseError "source:line: key: what", also for what touchdown's
/// model cannot represent (fisheye/equidistant, non-zero rational or
/// thin-prism terms, skew, binning).
CameraModel parse_camera(std::string_view yaml_text, std::string_view source);
/// Loads a camera file (any format parse_camera reads); IoError if
/// unreadable, ParseError if malformed.
CameraModel load_camera(const std::filesystem::path& path);
/// The camera as touchdown's YAML (round-trips through parse_camera).
std::string camera_to_yaml(const CameraModel& camera);

/// What a real depth image says about CameraModel::depth_scale: a scale in
/// the wrong unit (1 for millimetres, 0.001 for centimetres) puts every
/// depth far outside any scene a ground camera sees.
struct DepthScaleCheck {
  int samples = 0;          ///< nonzero pixels on the sampling grid
  double median_raw = 0;    ///< their median, in units of the depth image
  double median_m = 0;      ///< median_raw × depth_scale [m]
  bool conclusive = false;  ///< at least `min_samples` nonzero pixels: the median tells
  bool plausible = true;    ///< median_m within [min_m, max_m], or not conclusive
  std::string message;      ///< when implausible: "depth_scale: ..." with the scale that would fit
};
/// Median of the nonzero pixels of `depth` on a grid of at most 64×64
/// pixels (cheap: a few thousand reads); plausible when it lies in
/// [min_m, max_m] metres. Allocates the grid's samples.
DepthScaleCheck check_depth_scale(const DepthImageView& depth, double depth_scale, double min_m = 0.05,
                                  double max_m = 50.0, int min_samples = 16);

}  // namespace touchdown::pose
