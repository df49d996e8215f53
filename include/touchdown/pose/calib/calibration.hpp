#pragma once
/// \file
/// Part of touchdown::pose_calib.
/// LED constellation calibration by bundle adjustment: refines the LED
/// positions (body frame) from views of the drone in which each LED's pixel
/// is known, with known camera poses (motion capture, a calibration rig),
/// unknown ones, or a mix. The published pipeline measured the LEDs with
/// motion capture; this estimates them from images instead.
///
/// Method (Triggs, McLauchlan, Hartley & Fitzgibbon, "Bundle Adjustment — A
/// Modern Synthesis", 2000): unknown poses are initialised with `solve_pnp`
/// from the initial constellation, then LED positions and unknown poses
/// minimise the reprojection error (optionally Huber-robustified) with
/// Ceres' Levenberg–Marquardt with a Schur-complement solver (dense QR when every pose is known).
///
/// Gauge (Triggs et al. sec. 9): the images determine the LEDs only up to
/// the transforms the unknown poses can absorb.
///  - Known poses with at least two distinct camera centres: no freedom; the
///    result is metric and in the known poses' body frame.
///  - Known poses that all share one camera centre (typically exactly one
///    known pose): the scale about that centre is unobservable (monocular).
///  - No known pose: a similarity (7 DoF: rotation, translation, scale).
/// In the last two cases the result is returned in the gauge of `initial`:
/// the member of the family of equally good solutions closest (least
/// squares) to the initial LEDs — for no known pose the Umeyama (1991)
/// similarity alignment. In particular **the scale then comes from the
/// initial constellation**: its errors in scale are not corrected. Give two
/// known poses, or fix the result's scale with a known distance, when the
/// metric size matters.
///
/// Thread-safe: pure function (Ceres runs single-threaded, so results are
/// deterministic). Allocates.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"

namespace touchdown::pose {

/// One LED seen in one view.
struct LedObservation {
  int led = 0;                                      ///< index into Constellation::leds
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();  ///< undistorted pixel
};

/// One image of the drone: its LED observations (each LED at most once) and,
/// if known, the camera pose, which is then held fixed.
struct CalibrationView {
  std::vector<LedObservation> observations;
  std::optional<Eigen::Isometry3d> T_camera_body;  ///< known pose (body → camera), held fixed
};

struct CalibrationOptions {
  int max_iterations = 100;           ///< Levenberg–Marquardt iterations
  double huber_px = 2.0;              ///< Huber threshold on the reprojection error [px]; 0 = squared loss
  double function_tolerance = 1e-12;  ///< Ceres' relative cost-change stopping threshold
  /// False with a reason naming the option if a value is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class CalibrationStatus {
  Converged,
  NoConvergence,     ///< iteration limit, solver failure, or an invalid (degenerate) result; see message
  InsufficientData,  ///< see calibrate_constellation: too few views per LED, unknown pose with < 4 LEDs, no PnP
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::CalibrationStatus> {
  static constexpr std::array<std::string_view, 3> names{"converged", "no_convergence", "insufficient_data"};
};

namespace touchdown::pose {

inline std::string_view to_string(CalibrationStatus status) { return enum_name(status); }

struct CalibrationResult {
  CalibrationStatus status = CalibrationStatus::InsufficientData;
  std::string message;
  [[nodiscard]] bool ok() const { return status == CalibrationStatus::Converged; }
  /// The calibrated LEDs; colours and T_body_marker are copied from the
  /// initial constellation. Equals `initial` when status is InsufficientData.
  Constellation constellation;
  /// One pose per view (known ones unchanged, in the result's gauge);
  /// empty when status is InsufficientData.
  std::vector<Eigen::Isometry3d> T_camera_body;
  double initial_rms_px = 0;  ///< reprojection RMS at the initial LEDs and poses [px]
  double final_rms_px = 0;    ///< reprojection RMS at the result [px] (outliers included)
  int iterations = 0;
  /// Per LED, sqrt(σx² + σy² + σz²) [m]: the position's standard deviation
  /// from the Ceres covariance of the solution, scaled by the a-posteriori
  /// residual variance. Where the gauge is free it is the first-order
  /// covariance of the returned (aligned) LEDs: the gauge directions are
  /// projected out, so it describes the shape, not the unobservable
  /// placement and scale. Empty if
  /// the covariance could not be computed (too few redundant observations,
  /// rank-deficient Jacobian).
  std::vector<double> led_sigma_m;
};

/// Refines `initial`'s LED positions from `views` (undistorted pixels of
/// `camera`). Throws InvalidArgument for misuse: invalid options or initial
/// constellation, an LED index out of range or repeated within a view, a
/// non-finite pixel or pose, an LED behind the camera under a known pose.
/// Data that cannot determine the LEDs give status InsufficientData.
CalibrationResult calibrate_constellation(const PinholeCamera& camera, const Constellation& initial,
                                          std::span<const CalibrationView> views,
                                          const CalibrationOptions& options = {});

}  // namespace touchdown::pose
