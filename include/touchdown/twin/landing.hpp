#pragma once
/// \file
/// One landing of the twin: ODE rigid-body dynamics of the whole airframe on
/// the terrain, driven by an emulation of PX4's land mode (cascaded
/// position/velocity/attitude/rate control, four motor thrusts with
/// first-order lag, the three-stage land detector, thrust ramp-down and
/// disarm). Thread-safe: every run builds its own ODE world.
#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/terrain_model.hpp"

namespace touchdown::twin {

/// Controller gains and limits; each default mirrors the PX4 (v1.14)
/// parameter named beside it.
struct ControllerParams {
  double xy_p = 0.95;          ///< MPC_XY_P [1/s]
  double xy_vel_p = 1.8;       ///< MPC_XY_VEL_P_ACC [1/s]
  double xy_vel_i = 0.4;       ///< MPC_XY_VEL_I_ACC [1/s²]
  double xy_vel_d = 0.2;       ///< MPC_XY_VEL_D_ACC
  double xy_vel_max = 12.0;    ///< MPC_XY_VEL_MAX [m/s]
  double z_vel_p = 4.0;        ///< MPC_Z_VEL_P_ACC [1/s]
  double z_vel_i = 2.0;        ///< MPC_Z_VEL_I_ACC [1/s²]
  double tilt_max_deg = 12.0;  ///< MPC_TILTMAX_LND (the tilt limit of land mode)
  // Outside land mode (flight_control.hpp, Setpoint::land false):
  double z_p = 1.0;                        ///< MPC_Z_P [1/s]
  double z_vel_max_up = 3.0;               ///< MPC_Z_VEL_MAX_UP [m/s]
  double z_vel_max_down = 1.5;             ///< MPC_Z_VEL_MAX_DN [m/s]
  double tilt_max_air_deg = 45.0;          ///< MPC_TILTMAX_AIR
  double roll_pitch_rate_max_deg = 220.0;  ///< MC_ROLLRATE_MAX, MC_PITCHRATE_MAX [deg/s]
  /// Largest acceleration the horizontal velocity integral may hold [m/s²]
  /// (PX4 bounds it by the thrust's margin; a steady wind's drag must fit).
  double xy_vel_int_max_acc = 0.8;
  double vel_deriv_lp_hz = 5.0;     ///< MPC_VELD_LP: low-pass of the velocity derivative [Hz]
  double roll_p = 6.5;              ///< MC_ROLL_P [1/s]
  double pitch_p = 6.5;             ///< MC_PITCH_P [1/s]
  double yaw_p = 2.8;               ///< MC_YAW_P [1/s]
  double yaw_rate_max_deg = 200.0;  ///< MC_YAWRATE_MAX [deg/s]
  /// Rate-loop bandwidths [1/s]: the physical equivalent of PX4's
  /// airframe-normalised MC_ROLLRATE_P / MC_PITCHRATE_P / MC_YAWRATE_P.
  double rate_p_roll_pitch = 20.0;
  double rate_p_yaw = 8.0;
  double land_speed = 0.7;  ///< MPC_LAND_SPEED [m/s]
  // Land detector (PX4 MulticopterLandDetector).
  double land_z_vel_max = 0.25;      ///< LNDMC_Z_VEL_MAX [m/s]
  double land_rot_max_deg = 20.0;    ///< LNDMC_ROT_MAX [deg/s]
  double land_trigger_time = 1.0;    ///< LNDMC_TRIG_TIME [s]: each of the three stages is held a third of it
  double low_thrust_fraction = 0.3;  ///< LNDMC_LOW_T_THR: "low thrust" below this fraction of hover thrust
  double thrust_ramp_time = 0.25;    ///< [s] thrust ramps to zero after ground contact
};

/// How the twin's parts meet the terrain (issue 57, item 3;
/// docs/architecture.md, "Contacts").
enum class TerrainContact {
  /// The bucket grid over the triangles, every distinct contact kept (up to
  /// 4 a part): the twin before issue 57, whose decisions
  /// tests/twin/golden/sweep_decisions_trimesh.txt freezes.
  Trimesh,
  /// The default. The height field where the terrain is one
  /// (TerrainModel::height_field: a depth camera's cloud, or a mesh made
  /// from one): candidates by grid index, and a part's contacts that stand
  /// for one patch of surface (within a cell and 25° of a deeper one)
  /// merged into it with their springs. As Trimesh on any other terrain.
  /// On 50 random terrains the same verdicts as Trimesh, headings flipped
  /// within the noise of the runs, a landing 1.7× faster (median;
  /// docs/benchmarks.md).
  HeightField,
};

}  // namespace touchdown::twin

template <>
struct touchdown::EnumNames<touchdown::twin::TerrainContact> {
  static constexpr std::array<std::string_view, 2> names{"trimesh", "height-field"};
};

namespace touchdown::twin {

inline std::string_view to_string(TerrainContact contact) { return enum_name(contact); }

/// Physics settings of a run.
struct SimulationOptions {
  double step = 0.002;          ///< s (the step-halving test in tests/twin justifies 2 ms)
  double timeout = 15.0;        ///< s of simulated time
  double still_time = 0.5;      ///< s still (after disarm) that ends a run
  double still_linear = 0.01;   ///< m/s
  double still_angular = 0.02;  ///< rad/s
  /// A run also ends (settled) once the twin has been at rest after disarm
  /// for rest_time: below rest_linear and rest_angular, tighter than the
  /// still_* speeds. What the rest of still_time could still add is then
  /// below rest_angular · still_time (0.5 mrad; measured over the bundled
  /// terrains: final nutations within 0.45 mrad of running the whole
  /// still_time, docs/benchmarks.md). rest_time > still_time turns it off.
  double rest_time = 0.05;           ///< s
  double rest_linear = 0.001;        ///< m/s
  double rest_angular = 0.001;       ///< rad/s
  double contact_stiffness = 2.0e4;  ///< N/m per contact (ODE ERP/CFM from stiffness and damping)
  double contact_damping = 300.0;    ///< N s/m per contact
  int solver_iterations = 20;        ///< ODE QuickStep iterations
  /// Nutation above which a run counts as tipped over (the tip threshold).
  double tip_nutation = 0.5;
  ControllerParams controller{};
  TerrainContact contact = TerrainContact::HeightField;
  bool record_trace = false;  ///< keep a 50 Hz trace of the run
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// One run's (perturbed) conditions.
struct LandingConditions {
  Eigen::Vector2d landing_point = Eigen::Vector2d::Zero();  ///< commanded (x_lp, y_lp)
  Eigen::Vector2d start_offset = Eigen::Vector2d::Zero();   ///< horizontal position error at the start
  double ground_z = 0.0;                                    ///< z_lp: top of the terrain under the footprint
  double hover_offset = 0.8;                                ///< Δz: feet this high above z_lp at the start [m]
  double heading = 0.0;                                     ///< commanded yaw ψ [rad]
  double heading_error = 0.0;                               ///< initial yaw error [rad]
  double roll = 0.0, pitch = 0.0;                           ///< initial attitude [rad]
  double land_speed = 0.7;                                  ///< [m/s]
  double friction = 0.8;                                    ///< Coulomb μ of the terrain contacts
};

enum class RunStatus {
  Settled,   ///< came to rest after disarm
  Timeout,   ///< did not settle in time (reported, never scored as safe)
  Unstable,  ///< NaN, fell through or off the mapped terrain, or blew up (invalid, never safe)
};

}  // namespace touchdown::twin

template <>
struct touchdown::EnumNames<touchdown::twin::RunStatus> {
  static constexpr std::array<std::string_view, 3> names{"settled", "timeout", "unstable"};
};

namespace touchdown::twin {

inline std::string_view to_string(RunStatus status) { return enum_name(status); }

struct TracePoint {
  double t;
  Eigen::Vector3d position;
  double nutation;
  int stage;  ///< 0 flying, 1 ground contact, 2 maybe landed, 3 landed (disarmed)
};

struct RunResult {
  RunStatus status = RunStatus::Unstable;
  /// Why a run is not `Settled` (e.g. "left the mapped terrain"); empty for
  /// a settled run.
  std::string message;
  double roll = 0, pitch = 0, yaw = 0;  ///< final attitude [rad]
  double nutation = 0;                  ///< eq. (3): N = acos(cos φ · cos θ), final
  double max_touchdown_nutation = 0;    ///< largest N from first contact to the end
  double offset = 0;                    ///< final horizontal distance from the landing point [m]
  /// Parts that should not touch did: propellers, arms, the body box (not
  /// for an airframe without landing gear, which stands on its body).
  bool prop_strike = false, arm_strike = false, body_strike = false;
  bool tipped = false;  ///< final nutation above SimulationOptions::tip_nutation
  /// Every foot touching the terrain at rest (without landing gear: every
  /// bottom corner of the body).
  bool all_feet_in_contact = false;
  double sim_time = 0;  ///< simulated seconds
  long steps = 0;
  Eigen::Vector3d final_position = Eigen::Vector3d::Zero();  ///< centre of mass
  std::vector<TracePoint> trace;
  [[nodiscard]] bool strike() const { return prop_strike || arm_strike || body_strike; }
  [[nodiscard]] bool ok() const { return status == RunStatus::Settled; }
};

class LandingSimulator {
 public:
  /// Throws InvalidArgument for an invalid airframe or options.
  LandingSimulator(Airframe airframe, std::shared_ptr<const TerrainModel> terrain, SimulationOptions options);

  /// Flies one landing.
  [[nodiscard]] RunResult land(const LandingConditions& conditions) const;

  /// Releases the disarmed twin at rest in `pose` (body frame → world, body
  /// frame as in the airframe YAML) and lets it settle: for the tip-over
  /// validation of the safety threshold.
  [[nodiscard]] RunResult release(const Eigen::Isometry3d& pose, double friction) const;

  [[nodiscard]] const Airframe& airframe() const { return airframe_; }
  [[nodiscard]] const SimulationOptions& options() const { return options_; }
  [[nodiscard]] const TerrainModel& terrain() const { return *terrain_; }

 private:
  Airframe airframe_;
  std::shared_ptr<const TerrainModel> terrain_;
  SimulationOptions options_;
};

}  // namespace touchdown::twin
