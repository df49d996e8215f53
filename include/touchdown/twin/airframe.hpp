#pragma once
/// \file
/// The drone's digital twin: geometry, masses and motors of an airframe, as
/// read from an airframe YAML (data/airframes/f450.yaml, docs/formats.md).
/// Body frame: x forward, y left, z up, origin at the centre of the body box.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace touchdown::twin {

/// Collision primitives of the twin, in the body frame.
struct Sphere {
  Eigen::Vector3d centre;
  double radius;
};
struct Capsule {
  Eigen::Vector3d a, b;  ///< segment end points
  double radius;
};
struct Box {
  Eigen::Vector3d centre;
  Eigen::Vector3d half_extents;  ///< axis-aligned in the body frame
};
struct Disk {
  Eigen::Vector3d centre;
  Eigen::Vector3d axis;  ///< unit normal
  double radius;
  double half_thickness;
};

struct Airframe {
  std::string name = "unnamed";
  // body box
  Eigen::Vector3d body_size{0.14, 0.14, 0.06};
  double body_mass = 0.95;
  // arms and motors
  std::vector<double> arm_angles_deg{45, 135, 225, 315};
  double motor_radius = 0.225;
  double motor_z = 0.03;
  /// Per-motor z (coaxial layouts: a motor above and one below each arm
  /// end); empty = motor_z for every motor. YAML: `arms.motor_z` as a list.
  std::vector<double> motor_zs;
  double arm_radius = 0.012;
  double motor_mass = 0.05;
  std::vector<int> spin{1, -1, 1, -1};  ///< +1 counter-clockwise seen from above
  double max_thrust = 8.0;              ///< N per motor
  double motor_time_constant = 0.04;    ///< s
  double torque_coefficient = 0.016;    ///< m, yaw reaction torque per newton of thrust
  // propellers
  double prop_radius = 0.127;
  double prop_thickness = 0.01;
  double prop_height = 0.02;  ///< disk centre above the motor
  // landing gear; `legs` empty = no landing gear (YAML `landing_gear: none`):
  // the airframe rests on the bottom face of its body box, and the gear
  // fields below are not used
  double gear_mass = 0.35;
  double gear_top_z = -0.03;
  double foot_z = -0.17;
  double leg_radius = 0.008;
  double foot_radius = 0.01;
  std::vector<Eigen::Vector2d> legs{{0.15, 0.08}, {0.15, -0.08}, {-0.15, -0.08}, {-0.15, 0.08}};

  /// The default airframe (a DJI F450; the numbers of data/airframes/f450.yaml).
  static Airframe f450();
  /// A 180 mm quadrotor with 4-inch propellers and a short landing gear:
  /// the landing mission's drone (the numbers of data/airframes/quad180.yaml).
  static Airframe quad180();

  /// Least max-thrust-to-weight ratio validate() accepts (hover plus
  /// control margin).
  static constexpr double kMinThrustToWeight = 1.3;

  /// False, with "key: problem", when the airframe is not physical or
  /// cannot fly: a non-positive mass or size, legs not below the body, feet
  /// above the propellers, fewer than 3 legs, a non-convex support set, the
  /// centre of mass outside it, (without landing gear) arms or propellers
  /// reaching below the body, mismatched motor lists, thrust below
  /// kMinThrustToWeight × weight, motors that cannot set thrust, roll, pitch
  /// and yaw independently (fewer than 4, all spinning one way, no reaction
  /// torque, on one line), overlapping propellers.
  [[nodiscard]] bool validate(std::string* why) const;
  /// Empty, or "key: problem" when the motors cannot control thrust, roll,
  /// pitch and yaw independently (part of validate()).
  [[nodiscard]] std::string control_problem() const;
  /// The 4 × n control allocation about `com`: column i is the [thrust;
  /// roll, pitch, yaw torque] of 1 N from motor i (the mixer's matrix).
  [[nodiscard]] Eigen::MatrixXd control_allocation(const Eigen::Vector3d& com) const;

  [[nodiscard]] std::size_t motor_count() const { return arm_angles_deg.size(); }
  [[nodiscard]] double total_mass() const;
  [[nodiscard]] Eigen::Vector3d centre_of_mass() const;     ///< body frame
  [[nodiscard]] Eigen::Matrix3d inertia_about_com() const;  ///< body axes, kg m²
  [[nodiscard]] Eigen::Vector3d motor_position(std::size_t i) const;
  /// The airframe has legs; without, it stands on its body box.
  [[nodiscard]] bool has_landing_gear() const { return !legs.empty(); }
  /// What the airframe stands on when level, in the body frame: the foot
  /// sphere centres, or without landing gear the four bottom corners of the
  /// body box. Their convex hull is the support polygon.
  [[nodiscard]] std::vector<Eigen::Vector3d> support_points() const;
  /// Radius of the support points (the foot radius; 0 for body corners).
  [[nodiscard]] double support_radius() const { return has_landing_gear() ? foot_radius : 0.0; }
  /// Lowest point of the feet, or of the body without landing gear (z of
  /// the ground plane when standing level).
  [[nodiscard]] double ground_z() const { return has_landing_gear() ? foot_z - foot_radius : -0.5 * body_size.z(); }
  /// The largest k ≤ 12 such that turning the airframe by 360°/k about z
  /// maps every part that can touch the ground onto a part of the same
  /// kind: feet onto feet, motors (propeller disks, arms) onto motors, the
  /// body box onto itself. Motor spin directions do not count: they change
  /// the yaw reaction torque, not what touches the terrain where. Headings ψ
  /// and ψ + 360°/k then land the same shape, so a sweep needs only
  /// [0, 360°/k) (a hexacopter with six legs: 60°; the F450: 180°).
  [[nodiscard]] int symmetry_order() const;
  /// symmetry_order() is even.
  [[nodiscard]] bool symmetric_under_half_turn() const { return symmetry_order() % 2 == 0; }

  [[nodiscard]] Box body_box() const;
  /// Radius of everything the twin covers seen from above, about the body
  /// origin: the farthest propeller disk edge, foot or body corner.
  [[nodiscard]] double footprint_radius() const;
  [[nodiscard]] Capsule arm(std::size_t i) const;
  [[nodiscard]] Disk propeller(std::size_t i) const;
  [[nodiscard]] Capsule leg(std::size_t i) const;
  [[nodiscard]] Sphere foot(std::size_t i) const;
};

/// Parses an airframe YAML; throws touchdown::ParseError naming the file,
/// line and key (also for values that fail validate()).
Airframe parse_airframe(std::string_view yaml_text, std::string_view source);
Airframe load_airframe(const std::filesystem::path& path);

}  // namespace touchdown::twin
