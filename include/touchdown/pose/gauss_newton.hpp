#pragma once
/// \file
/// Part of touchdown::pose.
/// Gauss–Newton refinement of a camera pose from 2-D/3-D correspondences on
/// SE(3) with the exponential-map parametrisation and analytic Jacobians
/// (the non-robocentric landing paper's eq. 8), optionally with a Huber
/// loss and measured depths; reports the reprojection RMS and the pose
/// covariance.
///
/// Allocation: none inside the iterations (normal equations are accumulated
/// point by point into fixed-size 6×6 matrices). Thread-safe: pure functions.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/se3.hpp"

namespace touchdown::pose {

struct GaussNewtonOptions {
  int max_iterations = 20;
  double step_tolerance = 1e-12;  ///< stop when |Δξ| falls below this
  double huber_px = 0;            ///< Huber threshold [px]; 0 = plain least squares
  /// After convergence, the measured depth (DepthConstraints) farthest off
  /// the fit, if more than this many of its σ, is left out and the fit
  /// repeated from there; up to 3 depths. A depth camera at an LED often
  /// sees something else (a housing in front of it, an edge, a saturated
  /// spot). Judged at the fit that still holds the depth, so consistent
  /// depths outvote one bad one. 0 = every depth counts.
  double depth_outlier_sigma = 4;
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class RefineStatus {
  Converged,
  MaxIterations,
  Degenerate,  ///< fewer than 3 points, a point behind the camera, or singular normal equations
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::RefineStatus> {
  static constexpr std::array<std::string_view, 3> names{"converged", "max_iterations", "degenerate"};
};

namespace touchdown::pose {

inline std::string_view to_string(RefineStatus status) { return enum_name(status); }

struct PoseRefinement {
  RefineStatus status = RefineStatus::Degenerate;
  Eigen::Isometry3d T_camera_body = Eigen::Isometry3d::Identity();
  double rms_px = 0;  ///< reprojection RMS after the last step [px]
  int iterations = 0;
  Matrix6d covariance = Matrix6d::Zero();       ///< of the left-perturbation twist, σ² (JᵀWJ)⁻¹
  Matrix6d unit_covariance = Matrix6d::Zero();  ///< (JᵀWJ)⁻¹: the covariance for 1 px² of pixel noise
  double noise_variance = 0;                    ///< σ² = Σ w r² / (2n − 6) [px²], the residuals' estimate
  /// The degrees of freedom noise_variance rests on: 2n − 6, plus one per
  /// fused depth and two for an attitude constraint (0: no estimate).
  double degrees_of_freedom = 0;
  /// The information (inverse covariance) the fit's measurements carry, in
  /// two parts: the reprojections' Σ w JᵀJ for 1 px² of pixel noise, and
  /// that of the depths and the attitude in their own σ (the pixel scale of
  /// their residuals taken out). covariance_for(σ²) combines them for a
  /// pixel noise σ² without rescaling the other measurements' σ.
  Matrix6d pixel_information = Matrix6d::Zero();
  Matrix6d constraint_information = Matrix6d::Zero();
  /// Σ vᵢ JᵢᵀJᵢ over the points with a bias_variance vᵢ > 0 (Jᵢ the
  /// reprojection's 2×6 Jacobian at the final pose) [px² · px²/twist²]:
  /// the errors of single blobs that do not average out (a neighbour's
  /// glow pulling a centre), carried into the covariance (covariance_for).
  Matrix6d pixel_bias_moment = Matrix6d::Zero();
  /// The twist covariance for a pixel noise variance σ² [px²]: with the
  /// information I = pixel_information / σ² + constraint_information,
  /// I⁻¹ + I⁻¹ (pixel_bias_moment / σ⁴) I⁻¹ — the fit's estimate is
  /// unchanged by the points' bias variances, its covariance carries them
  /// (the sandwich form of a least-squares estimate's covariance).
  [[nodiscard]] Matrix6d covariance_for(double pixel_variance) const;
  /// As every touchdown Result: true when it holds a usable answer (here a
  /// pose, also when the iteration limit stopped it before step_tolerance).
  [[nodiscard]] bool ok() const { return status != RefineStatus::Degenerate; }
  /// The status's fixed text: refining a pose never allocates.
  [[nodiscard]] std::string_view message() const { return to_string(status); }
};

/// Residual r = π(T p) − uv [px] and its Jacobian with respect to a left
/// perturbation T ← exp(ξ^) T (2×6). False if p is behind the camera.
bool reprojection_residual(const PinholeCamera& camera, const Eigen::Isometry3d& T_camera_body,
                           const Eigen::Vector3d& p_body, const Eigen::Vector2d& uv_px, Eigen::Vector2d& residual,
                           Eigen::Matrix<double, 2, 6>* jacobian);

/// Measured depths of the points (an RGB-D camera's depth at the blobs),
/// fused with the reprojection: each point with a finite z_m[i] adds the
/// residual (z_pred − z_m[i]) · pixel_sigma_px / sigma_m[i], a depth error
/// in the units of a pixel error of σ = pixel_sigma_px, so the normal
/// equations weigh both by their noise (and the Huber threshold applies
/// alike). Empty spans: no depth.
struct DepthConstraints {
  std::span<const double> z_m;      ///< per point: measured depth [m], NaN = none
  std::span<const double> sigma_m;  ///< per point: its 1-σ [m] (> 0)
  double pixel_sigma_px = 0.2;      ///< the pixel noise the depths are scaled to [px]
};

/// The gravity ("down") direction measured in both frames — by the
/// camera's own IMU in the camera frame and by the body's (the drone's
/// flight controller) in the body frame — as a prior on the rotation:
/// the residual R_camera_body·g_body − g_camera, 1-σ `sigma_rad` per
/// component (the two vectors' noise combined: √2 × each one's σ when
/// they are alike), in the units of a pixel error of σ = pixel_sigma_px
/// like DepthConstraints. It fixes the rotation's two tilt angles, not the
/// rotation about gravity, nor the position. sigma_rad = 0: no prior.
struct AttitudeConstraint {
  Eigen::Vector3d g_camera = Eigen::Vector3d::Zero();  ///< unit
  Eigen::Vector3d g_body = Eigen::Vector3d::Zero();    ///< unit
  double sigma_rad = 0;                                ///< > 0 when in use
  double pixel_sigma_px = 0.2;                         ///< the pixel noise the residual is scaled to [px]
  [[nodiscard]] bool active() const { return sigma_rad > 0; }
  /// χ² of a rotation against the prior: |R g_body − g_camera|² / σ² (2
  /// degrees of freedom); 0 when not active.
  [[nodiscard]] double chi2(const Eigen::Matrix3d& R_camera_body) const;
};

/// Residual of the attitude prior in pixel units (3 components, rank 2)
/// and its 3×6 Jacobian for the left perturbation: ∂(R g)/∂φ = −[R g]×.
void attitude_residual(const Eigen::Isometry3d& T_camera_body, const AttitudeConstraint& attitude,
                       Eigen::Vector3d& residual, Eigen::Matrix<double, 3, 6>* jacobian);

/// Residual of a measured depth (DepthConstraints) in pixel units and its
/// 1×6 Jacobian for the left perturbation. False if p is behind the camera.
bool depth_residual(const Eigen::Isometry3d& T_camera_body, const Eigen::Vector3d& p_body, double z_m, double scale,
                    double& residual, Eigen::Matrix<double, 1, 6>* jacobian);

/// Refines `initial` (body → camera) to minimise the reprojection error
/// (and the depth error, with `depth`, and the attitude prior's, with
/// `attitude`). rms_px is the reprojection's only; the covariance and the
/// noise estimate count the depth and attitude residuals.
/// `bias_variance` (empty = none): per point, an error of its own [px²]
/// beyond the common pixel noise (blob_bias_variance() of its blob); it
/// does not weigh the fit, it widens the covariance (pixel_bias_moment).
PoseRefinement refine_pose_gauss_newton(const PinholeCamera& camera, std::span<const Eigen::Vector3d> p_body,
                                        std::span<const Eigen::Vector2d> uv_px, const Eigen::Isometry3d& initial,
                                        const GaussNewtonOptions& options = {}, const DepthConstraints& depth = {},
                                        const AttitudeConstraint& attitude = {},
                                        std::span<const double> bias_variance = {});

}  // namespace touchdown::pose
