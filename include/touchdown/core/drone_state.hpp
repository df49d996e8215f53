#pragma once
/// \file
/// The one drone state of every closed loop: what the sweep twin's flight
/// controller is given each step, what the mission's rigid-body drone
/// reports, and what the test world hands a landing system under test. One
/// message, as PX4's vehicle_local_position, vehicle_attitude,
/// vehicle_angular_velocity and vehicle_land_detected give it together;
/// world frame, z up, SI units (yaw in degrees, as in the scenario files).
///
/// Who fills what: every loop fills the kinematics (position, velocity,
/// attitude, body rates); the test world and the mission drone also time,
/// acceleration, yaw and on_ground; land_mode and landed come from a land
/// detector, which the test world has (PX4's LNDMC_TRIG_TIME rule) and the
/// mission keeps in its state machine (mission::MissionState), so there
/// they stay false.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace touchdown {

struct DroneState {
  double t = 0;                                            ///< since the loop began [s]
  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< the body's centre (of mass) [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< [m/s]
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< over the last step [m/s²]
  Eigen::Matrix3d R_world_body = Eigen::Matrix3d::Identity();
  Eigen::Vector3d w_body = Eigen::Vector3d::Zero();  ///< angular velocity in body axes [rad/s]
  double yaw_deg = 0;                                ///< heading: the body x axis' azimuth [deg]
  bool land_mode = false;                            ///< land mode latched (PX4's AUTO_LAND)
  bool on_ground = false;                            ///< resting on the ground or the pad
  bool landed = false;                               ///< the land detector's verdict (PX4 disarms)

  /// The body's pose at `position` with `R_world_body`.
  [[nodiscard]] Eigen::Isometry3d T_world_body() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R_world_body;
    T.translation() = position;
    return T;
  }
};

}  // namespace touchdown
