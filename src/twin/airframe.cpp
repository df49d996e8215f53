#include "touchdown/twin/airframe.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "core/checks.hpp"
#include "core/convex_hull.hpp"
#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::twin {

using detail::format_general;

Airframe Airframe::f450() { return Airframe{}; }

Airframe Airframe::quad180() {
  Airframe a;
  a.name = "180 mm quadrotor, short landing gear";
  a.body_size = {0.08, 0.08, 0.035};
  a.body_mass = 0.30;
  a.motor_radius = 0.09;
  a.motor_z = 0.015;
  a.arm_radius = 0.006;
  a.motor_mass = 0.025;
  a.max_thrust = 3.5;
  a.motor_time_constant = 0.03;
  a.torque_coefficient = 0.012;
  a.prop_radius = 0.0508;
  a.prop_thickness = 0.006;
  a.prop_height = 0.012;
  a.gear_mass = 0.03;
  a.gear_top_z = -0.0175;
  a.foot_z = -0.055;
  a.leg_radius = 0.004;
  a.foot_radius = 0.006;
  a.legs = {{0.05, 0.05}, {0.05, -0.05}, {-0.05, -0.05}, {-0.05, 0.05}};
  return a;
}

double Airframe::total_mass() const {
  return body_mass + motor_mass * static_cast<double>(motor_count()) + (has_landing_gear() ? gear_mass : 0.0);
}

std::vector<Eigen::Vector3d> Airframe::support_points() const {
  std::vector<Eigen::Vector3d> p;
  if (has_landing_gear()) {
    for (std::size_t i = 0; i < legs.size(); ++i) p.push_back(foot(i).centre);
  } else {
    const Eigen::Vector3d h = 0.5 * body_size;
    for (const auto& [sx, sy] : {std::pair{1, 1}, std::pair{-1, 1}, std::pair{-1, -1}, std::pair{1, -1}}) {
      p.emplace_back(sx * h.x(), sy * h.y(), -h.z());
    }
  }
  return p;
}

Eigen::Vector3d Airframe::motor_position(std::size_t i) const {
  const double a = deg_to_rad(arm_angles_deg[i]);
  return {motor_radius * std::cos(a), motor_radius * std::sin(a), motor_zs.empty() ? motor_z : motor_zs[i]};
}

Eigen::Vector3d Airframe::centre_of_mass() const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();  // body box at the origin
  for (std::size_t i = 0; i < motor_count(); ++i) s += motor_mass * motor_position(i);
  const double leg_mass = legs.empty() ? 0.0 : gear_mass / static_cast<double>(legs.size());
  for (const auto& l : legs) s += leg_mass * Eigen::Vector3d(l.x(), l.y(), 0.5 * (gear_top_z + foot_z));
  return s / total_mass();
}

Eigen::Matrix3d Airframe::inertia_about_com() const {
  const Eigen::Vector3d c = centre_of_mass();
  // Parallel-axis shift of an inertia `I0` about a part's own centre `p`.
  auto shifted = [&](double m, const Eigen::Matrix3d& I0, const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - c;
    return Eigen::Matrix3d(I0 + m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose()));
  };
  const Eigen::Vector3d s2 = body_size.cwiseAbs2();
  Eigen::Matrix3d I = shifted(
      body_mass, Eigen::Vector3d(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal() * (body_mass / 12.0),
      Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < motor_count(); ++i) I += shifted(motor_mass, Eigen::Matrix3d::Zero(), motor_position(i));
  if (!legs.empty()) {
    const double m = gear_mass / static_cast<double>(legs.size());
    const double L = gear_top_z - foot_z;
    const Eigen::Matrix3d rod = Eigen::Vector3d(m * L * L / 12.0, m * L * L / 12.0, 0.0).asDiagonal();
    for (const auto& l : legs) I += shifted(m, rod, Eigen::Vector3d(l.x(), l.y(), 0.5 * (gear_top_z + foot_z)));
  }
  return I;
}

int Airframe::symmetry_order() const {
  // Points match within 0.1 mm (YAML angles in degrees are rarely exact).
  constexpr double tol = 1e-4;
  auto maps_onto = [&](const std::vector<Eigen::Vector2d>& pts, const Eigen::Rotation2Dd& R) {
    return std::all_of(pts.begin(), pts.end(), [&](const Eigen::Vector2d& p) {
      const Eigen::Vector2d q = R * p;
      return std::any_of(pts.begin(), pts.end(), [&](const Eigen::Vector2d& r) { return (r - q).norm() < tol; });
    });
  };
  std::vector<Eigen::Vector2d> motors;
  for (std::size_t i = 0; i < motor_count(); ++i) motors.push_back(motor_position(i).head<2>());
  const Eigen::Vector2d h = 0.5 * body_size.head<2>();
  const std::vector<Eigen::Vector2d> body{{h.x(), h.y()}, {-h.x(), h.y()}, {-h.x(), -h.y()}, {h.x(), -h.y()}};
  for (int k = 12; k > 1; --k) {
    const Eigen::Rotation2Dd R(2 * std::numbers::pi / k);
    if (maps_onto(legs, R) && maps_onto(motors, R) && maps_onto(body, R)) return k;
  }
  return 1;
}

Box Airframe::body_box() const { return {Eigen::Vector3d::Zero(), 0.5 * body_size}; }

double Airframe::footprint_radius() const {
  double r = 0;
  for (std::size_t i = 0; i < motor_count(); ++i) r = std::max(r, motor_position(i).head<2>().norm() + prop_radius);
  for (const auto& l : legs) r = std::max(r, l.norm() + foot_radius);
  return std::max(r, 0.5 * body_size.head<2>().norm());
}

Capsule Airframe::arm(std::size_t i) const {
  const Eigen::Vector3d m = motor_position(i);
  // From the edge of the body box to the motor.
  const Eigen::Vector3d dir(m.x(), m.y(), 0.0);
  const double inner = std::min(0.5 * body_size.x() / std::max(1e-9, std::abs(dir.normalized().x())),
                                0.5 * body_size.y() / std::max(1e-9, std::abs(dir.normalized().y())));
  const Eigen::Vector3d a = dir.normalized() * std::min(inner, dir.norm()) + Eigen::Vector3d(0, 0, m.z());
  return {a, m, arm_radius};
}

Disk Airframe::propeller(std::size_t i) const {
  return {motor_position(i) + Eigen::Vector3d(0, 0, prop_height), Eigen::Vector3d::UnitZ(), prop_radius,
          0.5 * prop_thickness};
}

Capsule Airframe::leg(std::size_t i) const {
  // The leg ends where the foot sphere begins to cover it: below, the foot
  // makes every contact, and the leg would only repeat them.
  const double bottom = std::min(gear_top_z, foot_z + foot_radius);
  return {Eigen::Vector3d(legs[i].x(), legs[i].y(), gear_top_z), Eigen::Vector3d(legs[i].x(), legs[i].y(), bottom),
          leg_radius};
}

Sphere Airframe::foot(std::size_t i) const { return {Eigen::Vector3d(legs[i].x(), legs[i].y(), foot_z), foot_radius}; }

// The motors alone (no tilting servo is modelled) must set thrust, roll,
// pitch and yaw independently: the 4 × n allocation matrix about the centre
// of mass (the mixer's, flight_control.cpp) must have rank 4. The common
// ways to lose a row get their own message.
std::string Airframe::control_problem() const {
  const std::size_t n = motor_count();
  if (n < 4) {
    return "arms.angles_deg: " + std::to_string(n) +
           " fixed motors cannot set thrust, roll, pitch and yaw independently (a tricopter needs a tilting yaw "
           "servo, which the twin does not model): use 4 or more arms";
  }
  if (std::all_of(spin.begin(), spin.end(), [&](int s) { return s == spin.front(); })) {
    return "motors.spin: every motor spins the same way, so their reaction torques cannot be balanced and the "
           "airframe cannot hold its heading: give about half of them -1";
  }
  Eigen::MatrixXd A = control_allocation(centre_of_mass());
  for (Eigen::Index r = 0; r < A.rows(); ++r) {  // rows scaled to O(1) for the rank test
    const double norm = A.row(r).norm();
    if (norm > 0) A.row(r) /= norm;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
  const auto& sv = svd.singularValues();
  if (sv(3) < 1e-6 * sv(0)) {
    return "arms.angles_deg: the motors cannot set roll, pitch and yaw independently (motors on one line, or spins "
           "that mirror the geometry): the control allocation has rank < 4";
  }
  return "";
}

Eigen::MatrixXd Airframe::control_allocation(const Eigen::Vector3d& com) const {
  const std::size_t n = motor_count();
  Eigen::MatrixXd A(4, static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d r = motor_position(i) - com;
    const auto c = static_cast<Eigen::Index>(i);
    A(0, c) = 1.0;
    A(1, c) = r.y();                          // roll torque of a thrust along +z at r
    A(2, c) = -r.x();                         // pitch torque
    A(3, c) = -spin[i] * torque_coefficient;  // reaction torque opposes the spin
  }
  return A;
}

bool Airframe::validate(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  using touchdown::detail::positive;
  if (!positive(body_mass)) return fail("body.mass: must be positive, got " + format_general(body_mass));
  // Masses are kilograms: a multirotor body over 100 kg, a motor over 10 kg
  // or landing gear over 50 kg was almost certainly written in grams.
  for (const auto& [key, mass, limit] :
       {std::tuple{"body.mass", body_mass, 100.0}, std::tuple{"motors.mass", motor_mass, 10.0},
        std::tuple{"landing_gear.mass", gear_mass, 50.0}}) {
    if (mass > limit) {
      return fail(std::string(key) + ": " + format_general(mass) + " kg is implausible for a multirotor (more than " +
                  format_general(limit) + " kg): masses are in kilograms, written in grams?");
    }
  }
  if (!motor_zs.empty() && motor_zs.size() != arm_angles_deg.size()) {
    return fail("arms.motor_z: a list needs one z per arm (" + std::to_string(arm_angles_deg.size()) + "), got " +
                std::to_string(motor_zs.size()));
  }
  for (const double z : motor_zs) {
    if (!std::isfinite(z)) return fail("arms.motor_z: must be finite");
  }
  if (!(body_size.array() > 0).all() || !body_size.allFinite())
    return fail("body.size: all three sizes must be positive");
  if (motor_count() < 3) return fail("arms.angles_deg: need at least 3 arms");
  if (!positive(motor_radius)) return fail("arms.motor_radius: must be positive");
  if (!(arm_radius >= 0)) return fail("arms.capsule_radius: must be >= 0");
  if (!positive(motor_mass)) return fail("motors.mass: must be positive, got " + format_general(motor_mass));
  if (spin.size() != motor_count()) {
    return fail("motors.spin: expected " + std::to_string(motor_count()) + " entries (one per arm), got " +
                std::to_string(spin.size()));
  }
  for (int s : spin) {
    if (s != 1 && s != -1) return fail("motors.spin: entries must be 1 or -1");
  }
  if (!positive(max_thrust)) return fail("motors.max_thrust: must be positive");
  const double thrust_to_weight = max_thrust * static_cast<double>(motor_count()) / (total_mass() * 9.80665);
  if (thrust_to_weight < kMinThrustToWeight) {
    return fail("motors.max_thrust: the motors lift " + format_general(thrust_to_weight) + " times the weight (" +
                format_general(total_mass()) + " kg), need at least " + format_general(kMinThrustToWeight) +
                " to hover with control margin");
  }
  if (!positive(motor_time_constant)) return fail("motors.time_constant: must be positive");
  if (!(torque_coefficient > 0) || !std::isfinite(torque_coefficient)) {
    return fail(
        "motors.torque_coefficient: must be > 0 (without the rotors' reaction torque nothing yaws the airframe), "
        "got " +
        format_general(torque_coefficient));
  }
  if (const std::string w = control_problem(); !w.empty()) return fail(w);
  if (!positive(prop_radius)) return fail("propellers.radius: must be positive");
  if (!positive(prop_thickness)) return fail("propellers.thickness: must be positive");
  for (std::size_t i = 0; i < motor_count(); ++i) {
    for (std::size_t j = i + 1; j < motor_count(); ++j) {
      const double d = (motor_position(i) - motor_position(j)).head<2>().norm();
      // Coaxial pairs share an axis but turn in planes apart by more than a
      // propeller's thickness.
      const double dz = std::abs(motor_position(i).z() - motor_position(j).z());
      if (d < 2 * prop_radius && dz < 2 * prop_thickness) {
        std::string hint;
        bool radians = true;
        for (const double a : arm_angles_deg) radians = radians && std::abs(a) <= 2 * std::numbers::pi + 1e-9;
        if (radians) hint = " (arms.angles_deg are all within ±2π: written in radians?)";
        return fail("propellers.radius: the propellers of arms " + std::to_string(i + 1) + " and " +
                    std::to_string(j + 1) + " overlap: motors " + format_general(d) + " m apart, need at least 2 × " +
                    format_general(prop_radius) + hint);
      }
    }
  }
  // A propeller turning through the body: its disk reaches into the body's
  // footprint within the body's height.
  for (std::size_t i = 0; i < motor_count(); ++i) {
    const Disk d = propeller(i);
    const Eigen::Vector2d h = 0.5 * body_size.head<2>();
    const Eigen::Vector2d out = (d.centre.head<2>().cwiseAbs() - h).cwiseMax(0.0);
    const bool in_height = std::abs(d.centre.z()) < 0.5 * body_size.z() + d.half_thickness;
    if (in_height && out.norm() < d.radius) {
      return fail("propellers.radius: the propeller of arm " + std::to_string(i + 1) +
                  " cuts into the body (its disk reaches " + format_general(d.radius - out.norm()) +
                  " m into body.size at the same height): lengthen arms.motor_radius or raise propellers.height");
    }
  }
  if (!has_landing_gear()) {
    // Without landing gear the body's bottom face must be the lowest part:
    // arms or propellers hanging below it would be what the airframe rests
    // on, and they are not landing gear.
    for (std::size_t i = 0; i < motor_count(); ++i) {
      const Disk d = propeller(i);
      const double prop_low = d.centre.z() - d.half_thickness, arm_low = motor_position(i).z() - arm_radius;
      if (!(ground_z() < std::min(prop_low, arm_low) - 1e-3)) {
        return fail("landing_gear: none, but the " + std::string(prop_low < arm_low ? "propeller" : "arm") +
                    " of arm " + std::to_string(i + 1) +
                    " reaches down to z = " + format_general(std::min(prop_low, arm_low)) +
                    ", not above the body's bottom (z = " + format_general(ground_z()) +
                    "): the airframe would rest on it; describe the legs or skids it stands on");
      }
    }
    // The body's bottom face is the support polygon.
    const Eigen::Vector2d c = centre_of_mass().head<2>(), h = 0.5 * body_size.head<2>();
    if (!(c.cwiseAbs().array() < h.array() - 1e-9).all()) {
      return fail("body.size: the centre of mass (" + format_general(c.x()) + ", " + format_general(c.y()) +
                  ") is not above the body's bottom face, which the airframe stands on (landing_gear: none)");
    }
    return true;
  }
  if (!positive(gear_mass)) return fail("landing_gear.mass: must be positive, got " + format_general(gear_mass));
  if (!positive(foot_radius)) return fail("landing_gear.foot_radius: must be positive");
  if (!(leg_radius >= 0)) return fail("landing_gear.leg_radius: must be >= 0");
  if (!(foot_z < gear_top_z)) return fail("landing_gear.foot_z: the feet must be below the legs' top_z");
  if (!(gear_top_z <= 0.5 * body_size.z() + 1e-12)) return fail("landing_gear.top_z: the legs start above the body");
  if (!(ground_z() < -0.5 * body_size.z())) return fail("landing_gear.foot_z: the feet are not below the body");
  for (std::size_t i = 0; i < motor_count(); ++i) {
    const Disk d = propeller(i);
    if (!(ground_z() < d.centre.z() - d.half_thickness - 1e-3)) {
      return fail("landing_gear.foot_z: the feet do not reach below the propellers");
    }
    if (!(ground_z() < motor_position(i).z() - arm_radius)) {
      return fail("landing_gear.foot_z: the feet do not reach below the arms");
    }
  }
  if (legs.size() < 3) {
    return fail(
        "landing_gear.legs: need at least 3 legs (or `landing_gear: none` for an airframe that stands on its body), "
        "got " +
        std::to_string(legs.size()));
  }
  const auto hull = detail::convex_hull_indices(legs);
  if (hull.size() < 3) return fail("landing_gear.legs: the legs are collinear: no support polygon");
  if (hull.size() != legs.size()) {
    for (std::size_t i = 0; i < legs.size(); ++i) {
      if (std::find(hull.begin(), hull.end(), i) == hull.end()) {
        return fail("landing_gear.legs: the support set is not convex (leg " + std::to_string(i + 1) + " at (" +
                    format_general(legs[i].x()) + ", " + format_general(legs[i].y()) + ") lies inside the others)");
      }
    }
  }
  const Eigen::Vector2d c = centre_of_mass().head<2>();
  for (std::size_t k = 0; k < hull.size(); ++k) {
    if (detail::cross(legs[hull[k]], legs[hull[(k + 1) % hull.size()]], c) <= 1e-9) {
      return fail("landing_gear.legs: the centre of mass (" + format_general(c.x()) + ", " + format_general(c.y()) +
                  ") is not inside the support polygon");
    }
  }
  return true;
}

Airframe parse_airframe(std::string_view yaml_text, std::string_view source) {
  return detail::parse_validated<Airframe>(
      yaml_text, source, [](const detail::YamlReader& r, const YAML::Node& root, Airframe& a) {
        r.only(root, "", {"name", "body", "arms", "motors", "propellers", "landing_gear"});
        if (root["name"]) a.name = root["name"].as<std::string>();
        const auto body = r.child(root, "", "body");
        r.only(body, "body.", {"size", "mass"});
        const auto size = r.vec3(r.child(body, "body.", "size"), "body.size");
        a.body_size = {size[0], size[1], size[2]};
        a.body_mass = r.number(r.child(body, "body.", "mass"), "body.mass");

        const auto arms = r.child(root, "", "arms");
        r.only(arms, "arms.", {"angles_deg", "motor_radius", "motor_z", "capsule_radius"});
        a.arm_angles_deg = r.numbers(r.child(arms, "arms.", "angles_deg"), "arms.angles_deg");
        a.motor_radius = r.number(r.child(arms, "arms.", "motor_radius"), "arms.motor_radius");
        const auto motor_z = r.child(arms, "arms.", "motor_z");
        if (motor_z.IsSequence()) {
          a.motor_zs = r.numbers(motor_z, "arms.motor_z");
          if (a.motor_zs.empty()) r.fail(motor_z, "arms.motor_z", "an empty list");
          a.motor_z = a.motor_zs.front();
        } else {
          a.motor_z = r.number(motor_z, "arms.motor_z");
        }
        a.arm_radius = r.number(r.child(arms, "arms.", "capsule_radius"), "arms.capsule_radius");

        const auto motors = r.child(root, "", "motors");
        r.only(motors, "motors.", {"mass", "spin", "max_thrust", "time_constant", "torque_coefficient"});
        a.motor_mass = r.number(r.child(motors, "motors.", "mass"), "motors.mass");
        if (motors["spin"]) {
          a.spin.clear();
          for (double s : r.numbers(motors["spin"], "motors.spin")) {
            // Checked before the cast: a huge number does not fit an int.
            if (s != 1 && s != -1)
              r.fail(motors["spin"], "motors.spin", "entries must be 1 or -1, got " + format_general(s));
            a.spin.push_back(static_cast<int>(s));
          }
        } else {
          a.spin.clear();
          for (std::size_t i = 0; i < a.arm_angles_deg.size(); ++i) a.spin.push_back(i % 2 ? -1 : 1);
        }
        a.max_thrust = r.number(r.child(motors, "motors.", "max_thrust"), "motors.max_thrust");
        a.motor_time_constant = r.number(r.child(motors, "motors.", "time_constant"), "motors.time_constant");
        a.torque_coefficient = r.number(r.child(motors, "motors.", "torque_coefficient"), "motors.torque_coefficient");

        const auto props = r.child(root, "", "propellers");
        r.only(props, "propellers.", {"radius", "thickness", "height"});
        a.prop_radius = r.number(r.child(props, "propellers.", "radius"), "propellers.radius");
        a.prop_thickness = r.number(r.child(props, "propellers.", "thickness"), "propellers.thickness");
        a.prop_height = r.number(r.child(props, "propellers.", "height"), "propellers.height");

        const auto gear = r.child(root, "", "landing_gear");
        if (gear.IsScalar()) {  // `landing_gear: none`: the airframe stands on its body box
          if (gear.Scalar() != "none") r.fail(gear, "landing_gear", "expected a mapping or `none`");
          a.legs.clear();
          a.gear_mass = 0;
          return;
        }
        r.only(gear, "landing_gear.", {"mass", "top_z", "foot_z", "leg_radius", "foot_radius", "legs"});
        a.gear_mass = r.number(r.child(gear, "landing_gear.", "mass"), "landing_gear.mass");
        a.gear_top_z = r.number(r.child(gear, "landing_gear.", "top_z"), "landing_gear.top_z");
        a.foot_z = r.number(r.child(gear, "landing_gear.", "foot_z"), "landing_gear.foot_z");
        a.leg_radius = r.number(r.child(gear, "landing_gear.", "leg_radius"), "landing_gear.leg_radius");
        a.foot_radius = r.number(r.child(gear, "landing_gear.", "foot_radius"), "landing_gear.foot_radius");
        const auto legs = r.child(gear, "landing_gear.", "legs");
        if (!legs.IsSequence()) r.fail(legs, "landing_gear.legs", "expected a list of [x, y] pairs");
        a.legs.clear();
        for (std::size_t i = 0; i < legs.size(); ++i) {
          const auto xy = r.numbers(legs[i], "landing_gear.legs");
          if (xy.size() != 2) r.fail(legs[i], "landing_gear.legs", "each leg is [x, y]");
          a.legs.emplace_back(xy[0], xy[1]);
        }
      });
}

Airframe load_airframe(const std::filesystem::path& path) {
  return parse_airframe(detail::read_text_file(path), path.string());
}

}  // namespace touchdown::twin
