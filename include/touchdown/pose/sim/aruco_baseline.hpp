#pragma once
/// \file
/// Part of touchdown::pose_sim.
/// The ArUco baseline the LED tracker is compared against: one square
/// fiducial fixed on the airframe at `Constellation::T_body_marker`, detected
/// with OpenCV's aruco module (Garrido-Jurado et al., "Automatic generation
/// and detection of highly reliable fiducial markers under occlusion",
/// Pattern Recognition 47(6), 2014) and solved with IPPE for squares
/// (Collins & Bartoli, "Infinitesimal Plane-Based Pose Estimation", IJCV
/// 2014; OpenCV's SOLVEPNP_IPPE_SQUARE). It returns the same `PoseEstimate`
/// as the LED tracker, so a benchmark can run both on the same frames.
///
/// Marker frame (OpenCV aruco's): origin at the marker centre, z out of the
/// printed face, x right and y up when the marker is read upright; corners
/// (-s/2, s/2, 0), (s/2, s/2, 0), (s/2, -s/2, 0), (-s/2, -s/2, 0) in the
/// order the detector reports them, s = the black square's edge.
///
/// OpenCV stays out of this header (pimpl), so consumers need no OpenCV
/// include path.
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/image.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

struct ArucoOptions {
  /// One of OpenCV's predefined dictionaries, written without the DICT_
  /// prefix ("4X4_50", "6X6_250", "ARUCO_ORIGINAL", "APRILTAG_36h11", ...;
  /// case-insensitive, a leading "DICT_" is accepted too).
  std::string dictionary = "4X4_50";
  int marker_id = 3;  ///< the marker on the airframe; others in view are ignored
  /// [m] edge of the black square (border included, quiet zone excluded), in
  /// (0, 10].
  /// Print the marker with a white margin of at least a quarter of this
  /// edge: with a narrower one on a darker background, aruco takes the
  /// margin's outer edge for a duplicate candidate and drops the marker
  /// (docs/benchmarks.md, "LED relative pose").
  double marker_size = 0.10;
  /// Refine the corners to sub-pixel accuracy (aruco's CORNER_REFINE_SUBPIX);
  /// off = the corners of the polygon fit, less accurate (docs/benchmarks.md,
  /// "LED relative pose").
  bool corner_refinement = true;
  /// Assumed 1-σ corner noise [px]: the floor of the reported sigma (a
  /// four-corner fit leaves 2 degrees of freedom to estimate it from).
  double detection_sigma_px = 0.5;

  /// False with a reason naming the option ("dictionary: ...", "marker_id:
  /// ...", "marker_size: ...") if a value is invalid.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The dictionary names ArucoOptions::dictionary accepts, in OpenCV's
/// PREDEFINED_DICTIONARY_NAME order (canonical spelling).
std::vector<std::string> aruco_dictionary_names();

/// The canonical spelling of a dictionary name ArucoOptions::dictionary
/// accepts ("dict_4x4_50" → "4X4_50"); "" when unknown. Two names are the
/// same dictionary when their canonical names are equal.
std::string canonical_aruco_dictionary(std::string_view name);

/// Per-frame ArUco pose: detect markers, pick `marker_id`, solve IPPE on
/// its four corners with the camera's distortion, and return
/// T_camera_body = T_camera_marker · T_body_marker⁻¹.
///
/// Statuses: Ok; MarkerNotFound when the requested id is not among the
/// detections (`blobs` still counts the markers detected); Degenerate when
/// solvePnP fails or the solution puts the marker behind the camera. When
/// the id is seen more than once, the largest instance (perimeter in the
/// image) is used.
///
/// Accuracy: the orientation is well determined when the marker is tilted
/// to the camera, but poorly when it faces the camera squarely, since
/// sub-pixel corner bias then swamps the perspective cue to its tilt
/// (figures: docs/benchmarks.md, "LED relative pose").
///
/// `covariance` is σ² (JᵀJ)⁻¹ of the left-perturbation twist of
/// T_camera_body, J the 8×6 Jacobian of the (undistorted) corner pixels and
/// σ² = Σr² / (8 − 6): with only two redundant measurements it is a rough
/// figure, as the LED tracker's is with few LEDs.
///
/// Thread-safety: one estimator per thread (estimate() reuses internal
/// buffers); distinct estimators are independent. A moved-from estimator
/// may only be destroyed or assigned to.
class ArucoPoseEstimator {
 public:
  /// Throws touchdown::InvalidArgument if `options` or `camera` do not
  /// validate (the message names the option), or if T_body_marker is not
  /// a finite rigid transform.
  ArucoPoseEstimator(const CameraModel& camera, const Eigen::Isometry3d& T_body_marker,
                     const ArucoOptions& options = {});
  ~ArucoPoseEstimator();
  ArucoPoseEstimator(ArucoPoseEstimator&&) noexcept;
  ArucoPoseEstimator& operator=(ArucoPoseEstimator&&) noexcept;
  ArucoPoseEstimator(const ArucoPoseEstimator&) = delete;
  ArucoPoseEstimator& operator=(const ArucoPoseEstimator&) = delete;

  /// Pose of the body in the camera frame from one BGR frame. The view is
  /// read in place (no copy). Throws touchdown::InvalidArgument if the view
  /// is empty, its stride is too small, or its size differs from the
  /// camera's (the calibration would not apply).
  PoseEstimate estimate(const BgrImageView& image);

  /// The pose step of estimate() alone: T_camera_body from the marker's
  /// four corners as the detector reports them (distorted pixels, order as
  /// in the file comment). For other detectors and for exact tests; `blobs`
  /// is 1. Status Ok or Degenerate.
  PoseEstimate estimate_from_corners(const std::array<Eigen::Vector2d, 4>& corners_px);

  [[nodiscard]] const ArucoOptions& options() const;
  [[nodiscard]] const CameraModel& camera() const;
  [[nodiscard]] const Eigen::Isometry3d& T_body_marker() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
