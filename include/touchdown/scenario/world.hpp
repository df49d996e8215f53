#pragma once
/// \file
/// The landing world at fixed steps: a velocity-controlled multirotor with
/// acceleration limits and a PX4-like land mode, the scenario's moving
/// objects (scripted or driven by an external controller), collisions of the
/// drone's real shape with every object (FCL), and landing detection.
/// Same scenario and commands → bit-identical states.
///
/// Thread-safety: one World per thread. step() does not allocate.
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/drone_state.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/geometry.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/twin/airframe.hpp"

namespace touchdown::scenario {

/// The flight model's limits, after PX4's multicopter position controller
/// parameters (MPC_XY_VEL_MAX, MPC_Z_VEL_MAX_UP/DN, MPC_ACC_HOR, MPC_LAND_SPEED, ...).
struct FlightOptions {
  twin::Airframe airframe;              ///< the drone's shape (default F450-like)
  double rate_hz = 50;                  ///< physics steps per second
  double max_speed_xy = 5;              ///< [m/s]
  double max_speed_up = 3;              ///< [m/s]
  double max_speed_down = 1.5;          ///< [m/s]
  double max_accel_xy = 3;              ///< [m/s²]
  double max_accel_z = 2;               ///< [m/s²]
  double velocity_time_constant = 0.3;  ///< first-order response to the setpoint [s]
  double max_yaw_rate_deg = 60;         ///< [deg/s]
  double land_speed = 0.7;              ///< land mode descent near the ground [m/s] (MPC_LAND_SPEED)
  /// Land mode descends at max_speed_down above this height and at
  /// land_speed below it (MPC_LAND_ALT2) [m].
  double land_slow_altitude = 2.0;
  double land_detect_time = 0.5;  ///< on the ground this long = landed (LNDMC_TRIG_TIME)

  [[nodiscard]] bool validate(std::string* why) const;
};

/// What a landing system commands. In land mode the vehicle descends at the
/// land speed and the horizontal velocity setpoint still applies (PX4 lets
/// the pilot or an offboard system nudge the position during landing).
struct DroneCommand {
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();  ///< [m/s]; z ignored in land mode
  double yaw_rate_deg = 0;
  bool land = false;  ///< switch to land mode (latched)
};

/// External control of a moving object, as the RLaGA paper's RL agent:
/// one action per step, at the object's speed, in world axes (up = +y).
enum class ObjectAction { Stay, Up, Down, Left, Right };

}  // namespace touchdown::scenario

template <>
struct touchdown::EnumNames<touchdown::scenario::ObjectAction> {
  static constexpr std::array<std::string_view, 5> names{"stay", "up", "down", "left", "right"};
};

namespace touchdown::scenario {

inline std::string_view to_string(ObjectAction action) { return enum_name(action); }

/// The test world's drone is a point mass with PX4-like velocity control;
/// its attitude follows from the acceleration it flies plus gravity (the
/// thrust direction) at its yaw (differential flatness, Mellinger & Kumar
/// 2011). The World keeps DroneState::R_world_body equal to this after each
/// step; w_body stays zero (the model has no rotational dynamics).
[[nodiscard]] Eigen::Matrix3d thrust_attitude(const DroneState& state);

struct CollisionEvent {
  double t = 0;
  int object = -1;                                  ///< index in static_objects, then dynamic_objects
  std::string what;                                 ///< e.g. "static_objects[1] (pole)"
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< contact on the drone [m]
};

struct NearestObject {
  int object = -1;                                            ///< index in static_objects, then dynamic_objects
  std::string what;                                           ///< e.g. "static_objects[1] (pole)"
  double distance = std::numeric_limits<double>::infinity();  ///< [m]
};

class World {
 public:
  World(const Scenario& scenario, const FlightOptions& flight = {});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  /// One step of 1/rate_hz. `actions` has one entry per dynamic object with
  /// motion `external` (in order); empty = all stay. After a collision or a
  /// landing the world no longer moves the drone.
  void step(const DroneCommand& command, std::span<const ObjectAction> actions = {});

  [[nodiscard]] double time() const;
  [[nodiscard]] double dt() const;
  [[nodiscard]] const DroneState& drone() const;
  /// Poses of the dynamic objects (origin under the object's middle, x along its heading).
  [[nodiscard]] const std::vector<Eigen::Isometry3d>& dynamic_poses() const;
  [[nodiscard]] const std::vector<Eigen::Vector3d>& dynamic_velocities() const;
  /// The first collision, if any (the run stops there).
  [[nodiscard]] const CollisionEvent* collision() const;
  /// The object nearest the drone now (FCL distance between the drone's
  /// solids and the object's, 0 in contact); `object` = -1 and an infinite
  /// distance when the scene has none.
  [[nodiscard]] NearestObject nearest_object() const;
  [[nodiscard]] const Scenario& scenario() const;
  /// Number of dynamic objects with motion `external`.
  [[nodiscard]] int external_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::scenario
