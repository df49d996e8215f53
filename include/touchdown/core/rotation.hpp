#pragma once
/// \file
/// Roll–pitch–yaw rotations, the one convention of every touchdown file:
/// R = Rz(yaw) · Ry(pitch) · Rx(roll), fixed axes x, y, z, radians inside the
/// library (degrees in YAML, key `rpy`/`rpy_deg`). SE(3) exp/log live in
/// touchdown/pose/se3.hpp.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace touchdown {

/// R = Rz(yaw) · Ry(pitch) · Rx(roll) [rad].
Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw);
inline Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy) {
  return rotation_from_rpy(rpy.x(), rpy.y(), rpy.z());
}

/// The rigid transform with translation `xyz` [m] and rotation `rpy` [rad].
Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy);

/// (roll, pitch, yaw) [rad] of R = Rz(yaw) Ry(pitch) Rx(roll), pitch in
/// [−π/2, π/2]; at gimbal lock (|pitch| = π/2) roll is 0 and yaw carries
/// the whole rotation about z.
Eigen::Vector3d rpy_from_rotation(const Eigen::Matrix3d& R);

}  // namespace touchdown
