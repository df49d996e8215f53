#pragma once
/// \file
/// The ground vehicle that carries the pad and the camera: a skid-steer
/// platform (like the paper's AgileX Scout Mini) driven by its own path
/// follower (pure pursuit on the path, Coulter 1992) and speed controller,
/// with acceleration and wheel-speed limits and first-order wheel drives.
/// Or a car: a kinematic bicycle (Rajamani, "Vehicle Dynamics and Control",
/// 2nd ed., §2.2, about the rear axle) with steering angle and rate limits.
/// Paths: a circle, a straight line, a figure-eight (two tangent circles),
/// a road (straights, lane changes and long bends, repeating), a seeded
/// random drive (curvature and speed as bounded random walks) and
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
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/mission/vehicle_log.hpp"

namespace touchdown::mission {

enum class VehiclePath { Circle, Line, FigureEight, Random, Log, Road };

/// How the vehicle steers: the Scout Mini's skid steering, or a car's front
/// wheels (kinematic bicycle).
enum class VehicleModel { SkidSteer, Bicycle };

}  // namespace touchdown::mission

template <>
struct touchdown::EnumNames<touchdown::mission::VehiclePath> {
  static constexpr std::array<std::string_view, 6> names{"circle", "line", "figure_eight", "random", "log", "road"};
};

template <>
struct touchdown::EnumNames<touchdown::mission::VehicleModel> {
  static constexpr std::array<std::string_view, 2> names{"skid_steer", "bicycle"};
};

namespace touchdown::mission {

inline std::string_view to_string(VehiclePath p) { return enum_name(p); }
inline std::string_view to_string(VehicleModel m) { return enum_name(m); }

struct VehicleOptions {
  VehiclePath path = VehiclePath::Circle;
  VehicleModel model = VehicleModel::SkidSteer;
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
  /// bicycle: rear axle to front axle [m]; the vehicle frame's origin is
  /// then on the ground under the rear axle's centre (it moves forward
  /// only, as the skid-steer's centre does).
  double wheelbase = 2.7;
  double max_steer = 0.61;       ///< bicycle: front wheels' largest angle [rad] (35°)
  double max_steer_rate = 0.70;  ///< bicycle: how fast they turn [rad/s] (40°/s)
  /// road: the length of its straights [m]; the road repeats straight,
  /// lane change left, straight / 2, a 90° bend left (radius `radius`,
  /// entered and left on 20 m clothoids), straight, lane change right,
  /// straight / 2, a 90° bend right.
  double road_straight = 150;
  double lane_width = 3.5;           ///< road: the lane change's sideways step [m]
  double lane_change_length = 60.0;  ///< road: along the road [m]
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
  /// bicycle: the front wheels' angle [rad] (left positive).
  [[nodiscard]] double steer() const { return steer_; }

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
  double steer_ = 0;          ///< bicycle: front wheels' angle [rad]
  /// road: one period of it, about every 0.1 m of arc (arc length, x, y,
  /// heading, curvature), and where a period ends relative to its start.
  std::vector<std::array<double, 5>> road_;
  Eigen::Vector2d road_shift_ = Eigen::Vector2d::Zero();
};

}  // namespace touchdown::mission
