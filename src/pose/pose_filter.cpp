#include "pose/pose_filter.hpp"

#include <Eigen/Cholesky>

namespace touchdown::pose::detail {

Matrix6d left_to_body(const Eigen::Isometry3d& T) {
  // exp(ξ)·T = T·exp(η) with η = (Rᵀρ − Rᵀ[t]×φ, Rᵀφ).
  const Eigen::Matrix3d Rt = T.linear().transpose();
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = Rt;
  A.topRightCorner<3, 3>() = -Rt * hat(T.translation());
  A.bottomRightCorner<3, 3>() = Rt;
  return A;
}

void PoseFilter::start(const Eigen::Isometry3d& T, const Matrix6d& body_covariance) {
  T_ = T;
  v_.setZero();
  P_.setZero();
  P_.topLeftCorner<6, 6>() = body_covariance;
  const double vp = o_.initial_velocity_position_m, vr = o_.initial_velocity_rotation_rad;
  P_.bottomRightCorner<6, 6>().diagonal() << vp * vp, vp * vp, vp * vp, vr * vr, vr * vr, vr * vr;
  started_ = true;
}

bool PoseFilter::update(const Eigen::Isometry3d& T, const Matrix6d& covariance) {
  const Matrix6d A = left_to_body(T);
  const Matrix6d R = A * covariance * A.transpose();  // measurement noise, body frame at T
  if (!started_) {
    start(T, R);
    return true;
  }
  // Predict: T ← T·exp(v), P ← F P Fᵀ + Q.
  Eigen::Isometry3d T_pred = T_ * se3_exp(v_);
  T_pred.linear() = Eigen::Quaterniond(T_pred.linear()).normalized().toRotationMatrix();
  Eigen::Matrix<double, 12, 12> F = Eigen::Matrix<double, 12, 12>::Identity();
  F.topRightCorner<6, 6>().setIdentity();
  P_ = F * P_ * F.transpose();
  const double ap = o_.accel_position_m, ar = o_.accel_rotation_rad;
  P_.bottomRightCorner<6, 6>().diagonal() +=
      (Vector6d() << ap * ap, ap * ap, ap * ap, ar * ar, ar * ar, ar * ar).finished();
  // Update with the measured pose: innovation d = log(T_pred⁻¹ T), H = [I 0].
  const Vector6d d = se3_log(T_pred.inverse() * T);
  const Matrix6d S = P_.topLeftCorner<6, 6>() + R;
  const Eigen::LDLT<Matrix6d> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(d.dot(ldlt.solve(d)) <= o_.gate_chi2)) {
    start(T, R);  // the motion broke the model (or the track jumped): start over
    return false;
  }
  const Eigen::Matrix<double, 12, 6> K = P_.leftCols<6>() * ldlt.solve(Matrix6d::Identity());
  const Eigen::Matrix<double, 12, 1> dx = K * d;
  T_ = T_pred * se3_exp(dx.head<6>());
  T_.linear() = Eigen::Quaterniond(T_.linear()).normalized().toRotationMatrix();
  v_ += dx.tail<6>();
  // Joseph form keeps P symmetric and positive: (I − KH) P (I − KH)ᵀ + K R Kᵀ.
  Eigen::Matrix<double, 12, 12> IKH = Eigen::Matrix<double, 12, 12>::Identity();
  IKH.leftCols<6>() -= K;
  P_ = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  return true;
}

Matrix6d PoseFilter::covariance() const {
  const Matrix6d A = left_to_body(T_);
  const Matrix6d Ainv = A.inverse();
  return Ainv * P_.topLeftCorner<6, 6>() * Ainv.transpose();
}

}  // namespace touchdown::pose::detail
