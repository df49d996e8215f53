#pragma once
// Temporal fusion of the tracker's per-frame poses (internal to
// touchdown::pose): an extended Kalman filter on SE(3) with a constant
// body-velocity model, state (T, v) with T ← T·exp(v) per frame, errors as
// right (body-frame) perturbations δT, δv (Barfoot 2017, sec. 7.3, with the
// small-step Jacobian F = [[I, I], [0, I]]). A frame's Gauss–Newton fit is
// the measurement (its twist covariance); an innovation beyond the χ² gate
// restarts the filter from the measurement. Fixed-size: no allocation.
#include <Eigen/Geometry>

#include "touchdown/pose/se3.hpp"

namespace touchdown::pose::detail {

struct PoseFilterOptions {
  /// Per-frame random walk of the body velocity (1-σ per frame): how much
  /// the motion may change between frames [m/frame², rad/frame²].
  double accel_position_m = 0.004;
  double accel_rotation_rad = 0.012;
  /// 1-σ of the velocity when a track starts [m/frame, rad/frame].
  double initial_velocity_position_m = 0.1;
  double initial_velocity_rotation_rad = 0.1;
  /// Innovation gate: Mahalanobis² beyond this restarts the filter (χ²,
  /// 6 dof, 99.9 %).
  double gate_chi2 = 22.46;
};

class PoseFilter {
 public:
  explicit PoseFilter(const PoseFilterOptions& options = {}) : o_(options) {}
  void reset() { started_ = false; }
  [[nodiscard]] bool started() const { return started_; }
  // One frame: predict, then fuse the measured pose `T` whose left twist
  // covariance (ρ, φ) is `covariance`. Returns false when the innovation
  // failed the gate (the filter then restarts from the measurement).
  bool update(const Eigen::Isometry3d& T, const Matrix6d& covariance);
  [[nodiscard]] const Eigen::Isometry3d& pose() const { return T_; }
  // The fused pose's left twist covariance, as PoseRefinement reports it.
  [[nodiscard]] Matrix6d covariance() const;

 private:
  void start(const Eigen::Isometry3d& T, const Matrix6d& body_covariance);
  PoseFilterOptions o_;
  bool started_ = false;
  Eigen::Isometry3d T_ = Eigen::Isometry3d::Identity();
  Vector6d v_ = Vector6d::Zero();                           // body twist per frame
  Eigen::Matrix<double, 12, 12> P_ = decltype(P_)::Zero();  // (δT, δv), body frame
};

// Ad(T⁻¹): maps a left twist (ρ, φ) at T to the right (body-frame) twist.
Matrix6d left_to_body(const Eigen::Isometry3d& T);

}  // namespace touchdown::pose::detail
