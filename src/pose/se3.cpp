#include "touchdown/pose/se3.hpp"

#include <algorithm>
#include <cmath>

#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

Eigen::Matrix3d hat(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Isometry3d se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  const double theta = phi.norm();
  const Eigen::Matrix3d P = hat(phi), P2 = P * P;
  double a, b, c;  // sinθ/θ, (1−cosθ)/θ², (θ−sinθ)/θ³
  if (theta < 1e-5) {
    const double t2 = theta * theta;
    a = 1 - t2 / 6;
    b = 0.5 - t2 / 24;
    c = 1.0 / 6 - t2 / 120;
  } else {
    a = std::sin(theta) / theta;
    b = (1 - std::cos(theta)) / (theta * theta);
    c = (theta - std::sin(theta)) / (theta * theta * theta);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Matrix3d::Identity() + a * P + b * P2;
  T.translation() = (Eigen::Matrix3d::Identity() + b * P + c * P2) * rho;
  return T;
}

Vector6d se3_log(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd aa(T.linear());
  const Eigen::Vector3d phi = aa.axis() * aa.angle();
  const double theta = aa.angle();
  const Eigen::Matrix3d P = hat(phi), P2 = P * P;
  // V⁻¹ = I − ½Φ + (1/θ²)(1 − (θ/2) cot(θ/2)) Φ².
  double d;
  if (theta < 1e-5) {
    d = 1.0 / 12 + theta * theta / 720;
  } else {
    d = (1 - 0.5 * theta * std::cos(0.5 * theta) / std::sin(0.5 * theta)) / (theta * theta);
  }
  const Eigen::Matrix3d Vinv = Eigen::Matrix3d::Identity() - 0.5 * P + d * P2;
  Vector6d xi;
  xi.head<3>() = Vinv * T.translation();
  xi.tail<3>() = phi;
  return xi;
}

std::pair<double, double> pose_sigmas(const Matrix6d& cov, const Eigen::Isometry3d& T) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>().setIdentity();
  J.rightCols<3>() = -hat(T.translation());
  return {std::sqrt(std::max(0.0, (J * cov * J.transpose()).trace())),
          std::sqrt(std::max(0.0, cov.bottomRightCorner<3, 3>().trace()))};
}

}  // namespace touchdown::pose
