#pragma once
/// \file
/// The ground vehicle that carries the pad and the camera: a skid-steer
/// platform (like the paper's AgileX Scout Mini) driven by its own path
/// follower (pure pursuit on the path, Coulter 1992) and speed controller,
/// with acceleration and wheel-speed limits and first-order wheel drives.
/// Paths: a circle, a straight line, a figure-eight (two tangent circles),
/// a seeded random drive (curvature and speed as bounded random walks) and
/// a recorded drive replayed as it was (vehicle_log.hpp: the vehicle is
/// where the log says, its drives and limits play no part).
///
/// World frame: z up, the vehicle starts at the origin heading +x. Vehicle
/// frame: x forward, y left, z up, origin on the ground under the centre.
/// Deterministic: the random drive draws from Rng(seed). No allocation in
/// step(). Thread-safety: one instance per mission.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/mission/vehicle_log.hpp"

namespace touchdown::mission {

enum class VehiclePath { Circle, Line, FigureEight, Random, Log };

}  // namespace touchdown::mission

template <>
struct touchdown::EnumNames<touchdown::mission::VehiclePath> {
  static constexpr std::array<std::string_view, 5> names{"circle", "line", "figure_eight", "random", "log"};
};

namespace touchdown::mission {

inline std::string_view to_string(VehiclePath p) { return enum_name(p); }

struct VehicleOptions {
  VehiclePath path = VehiclePath::Circle;
  double speed = 2.0;                  ///< commanded speed [m/s], > 0 (random: the mean)
  double radius = 8.0;                 ///< circle radius, figure-eight lobe radius, random drive's tightest turn [m]
  bool counter_clockwise = true;       ///< the circle's (and the figure-eight's first lobe's) sense
  double max_acceleration = 1.5;       ///< longitudinal [m/s²]
  double max_wheel_speed = 2.7 * 2.0;  ///< per side [m/s] (Scout Mini: ~20 km/h)
  double track_width = 0.49;           ///< between the wheel centres [m]
  double drive_time_constant = 0.15;   ///< wheel drives' first-order lag [s]
  double lookahead = 2.0;              ///< pure pursuit lookahead [m]
  bool start_at_speed = true;          ///< the mission starts with the vehicle on its path at `speed`
  double random_speed_sigma = 0.3;     ///< random drive: speed varies ± this [m/s]
  double random_change_time = 4.0;     ///< random drive: time scale of its changes [s]
  /// path log: the drive (vehicle_log.hpp); `speed` is then not used.
  std::shared_ptr<const VehicleLog> log;
  /// Pad centre (on its surface) in the vehicle frame [m]: height above the
  /// ground in z.
  Eigen::Vector3d pad_position{-0.1, 0.0, 0.40};
  /// False (with "vehicle.key: problem" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The vehicle's state in the world.
struct VehicleState {
  double t = 0;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< [m]
  double yaw = 0;                                      ///< heading [rad]
  double speed = 0;                                    ///< forward [m/s]
  double yaw_rate = 0;                                 ///< [rad/s]
  double acceleration = 0;                             ///< forward [m/s²]
  double wheel_left = 0, wheel_right = 0;              ///< track speeds [m/s]
  /// World acceleration of the vehicle's origin (forward and centripetal) [m/s²].
  [[nodiscard]] Eigen::Vector2d world_acceleration() const;
  [[nodiscard]] Eigen::Isometry3d T_world_vehicle() const;
};

class GroundVehicle {
 public:
  /// Throws InvalidArgument for invalid options.
  GroundVehicle(const VehicleOptions& options, std::uint64_t seed);

  /// Advances by dt [s] (> 0).
  void step(double dt);

  [[nodiscard]] const VehicleState& state() const { return state_; }
  [[nodiscard]] const VehicleOptions& options() const { return options_; }
  /// The pad frame (x forward, y left, z up, origin at the pad centre on
  /// its surface) in the world, its world velocity and angular velocity.
  [[nodiscard]] Eigen::Isometry3d T_world_pad() const;
  [[nodiscard]] Eigen::Vector3d pad_velocity() const;
  [[nodiscard]] Eigen::Vector3d pad_angular_velocity() const { return {0, 0, state_.yaw_rate}; }
  /// The path's point at arc length s (the reference the follower tracks;
  /// the random drive has none and gives the vehicle's position).
  [[nodiscard]] Eigen::Vector2d path_point(double s) const;
  /// The path's curvature at arc length s [1/m] (signed, left positive).
  [[nodiscard]] double path_curvature(double s) const;

 private:
  void commands(double dt, double* v_cmd, double* w_cmd);
  void replay();  // path log: the state at state_.t from the log

  VehicleOptions options_;
  VehicleState state_;
  Rng rng_;
  double s_ = 0;             ///< arc length of the closest path point (monotone search)
  double random_speed_ = 0;  ///< random drive's current speed target
  double random_curvature_ = 0;
  double speed_command_ = 0;  ///< the ramped speed command [m/s]
};

}  // namespace touchdown::mission
