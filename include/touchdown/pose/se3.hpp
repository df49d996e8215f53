#pragma once
/// \file
/// Part of touchdown::pose.
/// SE(3) tools for the LED pose pipeline: hat, exponential and logarithm
/// maps (twist ξ = (ρ, φ): translation part first), written from Barfoot,
/// "State Estimation for Robotics" (2017), sec. 7.1.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace touchdown::pose {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// [v]×: the skew-symmetric matrix with [v]× w = v × w.
Eigen::Matrix3d hat(const Eigen::Vector3d& v);

/// exp(ξ^) for ξ = (ρ, φ).
Eigen::Isometry3d se3_exp(const Vector6d& xi);

/// The inverse of se3_exp (rotation angle in [0, π]).
Vector6d se3_log(const Eigen::Isometry3d& T);

}  // namespace touchdown::pose
