// One landing of the twin. Dynamics: ODE (world, one rigid body, contact
// joints). Contacts: src/twin/contacts.cpp. Flight control
// (flight_control.cpp): an emulation of PX4's multicopter land mode, PX4's
// three-stage land detector and the mixer; here only the first-order motor
// lag, the forces on the body and the end of the run.
#include "touchdown/twin/landing.hpp"

#include <ode/ode.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "contacts.hpp"
#include "core/ode_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/flight_control.hpp"

namespace touchdown::twin {
namespace {

using touchdown::detail::rotation_of;
using touchdown::detail::soft_params;
using touchdown::detail::vec_of;

double nutation_of(const Eigen::Matrix3d& R) { return std::acos(std::clamp(R(2, 2), -1.0, 1.0)); }

enum class PartKind { Foot, Leg, Arm, Propeller, Body };

// cos 25°: the widest angle between the normals of one patch's contacts.
constexpr double kPatchCos = 0.9063077870366499;

// Everything of one run: ODE objects, controller state, bookkeeping.
class Run {
 public:
  Run(const LandingSimulator& sim, double friction)
      : sim_(sim), af_(sim.airframe()), opt_(sim.options()), com_(af_.centre_of_mass()), mixer_(af_, com_) {
    world_ = touchdown::detail::create_world(kStandardGravity, &threading_);
    dWorldSetQuickStepNumIterations(world_, opt_.solver_iterations);
    contacts_group_ = dJointGroupCreate(0);
    body_ = touchdown::detail::create_rigid_body(world_, af_.total_mass(), af_.inertia_about_com());
    friction_ = friction;
    soft_params(opt_.step, opt_.contact_stiffness, opt_.contact_damping, erp_, cfm_);
    const std::size_t n = af_.motor_count();
    hover_thrust_ = af_.total_mass() * kStandardGravity;
    motor_.assign(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      motor_r_.push_back(af_.motor_position(i) - com_);
      arms_.push_back(af_.arm(i));
      props_.push_back(af_.propeller(i));
    }
    for (std::size_t i = 0; i < af_.legs.size(); ++i) {
      feet_.push_back(af_.foot(i));
      legs_.push_back(af_.leg(i));
    }
    // Radius of a sphere about the CoM holding every collision part.
    reach_ = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Disk d = af_.propeller(i);
      reach_ = std::max(reach_, (d.centre - com_).norm() + d.radius + d.half_thickness);
      const Capsule a = af_.arm(i);
      reach_ = std::max(reach_, (a.b - com_).norm() + a.radius);
    }
    for (std::size_t i = 0; i < af_.legs.size(); ++i) {
      reach_ = std::max(reach_, (af_.foot(i).centre - com_).norm() + af_.foot_radius);
      reach_ = std::max(reach_, (af_.leg(i).a - com_).norm() + af_.leg_radius);
    }
    reach_ = std::max(reach_, (0.5 * af_.body_size).norm() + com_.norm());
  }
  ~Run() {
    dJointGroupDestroy(contacts_group_);
    dWorldDestroy(world_);
    dThreadingFreeImplementation(threading_);
  }
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  // Pose of the airframe's body frame in the world → ODE body (at the CoM).
  void place(const Eigen::Isometry3d& T_world_body) {
    const Eigen::Vector3d p = T_world_body * com_;
    dBodySetPosition(body_, p.x(), p.y(), p.z());
    dMatrix3 R;
    touchdown::detail::to_ode(T_world_body.linear(), R);
    dBodySetRotation(body_, R);
    dBodySetLinearVel(body_, 0, 0, 0);
    dBodySetAngularVel(body_, 0, 0, 0);
  }

  void set_motors_hover() {
    std::fill(motor_.begin(), motor_.end(), hover_thrust_ / static_cast<double>(motor_.size()));
  }

  // One run from the placed state: each step checks the state, commands
  // the motors, finds the contacts and steps ODE, until the twin has been
  // still long enough after disarm, the timeout or an unstable state.
  RunResult fly(const LandingConditions& lc, bool armed) {
    Flight f(opt_, af_, hover_thrust_, sim_.terrain().bounds().min.z() - 1.0, armed);
    f.scratch.height_field = opt_.contact == TerrainContact::HeightField ? sim_.terrain().height_field() : nullptr;
    for (long step = 0; step < f.max_steps; ++step) {
      const DroneState s = body_state(step, f.dt);
      if (const char* why = instability_of(s, f.terrain_floor)) return f.unstable(step, why);
      const double nut = nutation_of(s.R_world_body);
      if (f.touched) f.res.max_touchdown_nutation = std::max(f.res.max_touchdown_nutation, nut);

      command_motors(f, lc, s);
      // A non-finite command must never reach ODE (its normalisation asserts
      // abort the process): the run ends as unstable instead.
      if (!std::all_of(motor_.begin(), motor_.end(), [](double m) { return std::isfinite(m); })) {
        return f.unstable(step, "non-finite motor command");
      }
      apply_motor_forces();

      find_contacts(f, s);
      add_contact_joints(f, s);
      if (!f.contacts.empty()) f.touched = true;

      dWorldStep(world_, f.dt);
      dJointGroupEmpty(contacts_group_);
      ++f.res.steps;

      if (opt_.record_trace && step % 20 == 0) {
        f.res.trace.push_back({s.t, s.position, nut, f.detector.stage()});
      }
      if (run_ended(f, step)) break;
    }
    return final_result(f, lc);
  }

 private:
  // The state of one flight that passes between the steps of fly().
  struct Flight {
    Flight(const SimulationOptions& opt, const Airframe& af, double hover_thrust, double floor, bool armed)
        : dt(opt.step),
          max_steps(static_cast<long>(std::ceil(opt.timeout / dt))),
          motor_alpha(1.0 - std::exp(-dt / af.motor_time_constant)),
          controller(opt.controller, af.total_mass(), af.inertia_about_com(), dt),
          detector(opt.controller, hover_thrust, dt, armed),
          terrain_floor(floor),
          foot_touch(af.support_points().size()) {}

    // Ends the run as unstable at `step`, saying why.
    RunResult unstable(long step, const char* why) {
      res.status = RunStatus::Unstable;
      res.message = why;
      res.steps = step;
      res.sim_time = static_cast<double>(step) * dt;
      return res;
    }

    RunResult res;
    const double dt;
    const long max_steps;
    const double motor_alpha;
    LandController controller;
    LandDetector detector;
    double still_timer = 0, rest_timer = 0;
    bool touched = false;
    const double terrain_floor;
    // This step's contacts, each with the part it is on and, for a foot or
    // leg, the foot's index.
    std::vector<detail::Contact> contacts;
    std::vector<PartKind> contact_kind;
    std::vector<int> contact_foot;
    detail::Scratch scratch;
    // One flag per support point: a foot, or without landing gear a bottom
    // corner of the body.
    std::vector<bool> foot_touch;
  };

  // The ODE body's state at the start of step `step` (world frame, at the
  // CoM; the flight controller's input).
  [[nodiscard]] DroneState body_state(long step, double dt) const {
    DroneState s;
    s.t = static_cast<double>(step) * dt;
    s.position = vec_of(dBodyGetPosition(body_));
    s.velocity = vec_of(dBodyGetLinearVel(body_));
    s.R_world_body = rotation_of(body_);
    s.w_body = s.R_world_body.transpose() * vec_of(dBodyGetAngularVel(body_));
    return s;
  }

  // Why the state ends the run as unstable, or nullptr.
  [[nodiscard]] const char* instability_of(const DroneState& s, double terrain_floor) const {
    const auto& tb = sim_.terrain().bounds();
    const Eigen::Vector3d& p = s.position;
    const bool off_map = p.x() < tb.min.x() || p.x() > tb.max.x() || p.y() < tb.min.y() || p.y() > tb.max.y();
    if (!p.allFinite() || !s.velocity.allFinite() || !s.R_world_body.allFinite()) return "non-finite state";
    if (p.z() < terrain_floor) return "fell through the terrain";
    if (off_map) return "left the mapped terrain";
    if (s.velocity.norm() > 30.0) return "speed above 30 m/s";
    if (s.w_body.norm() > 200.0) return "spin above 200 rad/s";
    return nullptr;
  }

  // Flight controller, land detector, mixer (flight_control.hpp) and the
  // motors' first-order lag.
  void command_motors(Flight& f, const LandingConditions& lc, const DroneState& s) {
    if (!f.detector.landed()) {
      const LandController::Output u = f.controller.update(s, lc.landing_point, lc.heading, lc.land_speed,
                                                           f.detector.stage() >= LandDetector::GroundContact);
      if (f.detector.update(u.thrust, s.velocity.z(), u.vz_setpoint, s.w_body.norm()))
        f.controller.reset_velocity_integrator();
      const Eigen::VectorXd& thrust = mixer_.mix_in_place(f.detector.limit_thrust(u.thrust), u.torque);
      for (std::size_t i = 0; i < motor_.size(); ++i) {
        const double cmd = f.detector.landed() ? 0.0 : thrust[static_cast<Eigen::Index>(i)];
        motor_[i] += (cmd - motor_[i]) * f.motor_alpha;
      }
    } else {
      f.controller.idle(s.velocity);
      for (double& m : motor_) m += (0.0 - m) * f.motor_alpha;  // disarmed: spin down
    }
  }

  // Motor thrusts and their reaction torques on the body.
  void apply_motor_forces() {
    for (std::size_t i = 0; i < motor_.size(); ++i) {
      const Eigen::Vector3d& r = motor_r_[i];
      dBodyAddRelForceAtRelPos(body_, 0, 0, motor_[i], r.x(), r.y(), r.z());
      dBodyAddRelTorque(body_, 0, 0, -af_.spin[i] * af_.torque_coefficient * motor_[i]);
    }
  }

  // A body-frame point of the airframe in the world.
  [[nodiscard]] Eigen::Vector3d to_world(const DroneState& s, const Eigen::Vector3d& q) const {
    return Eigen::Vector3d(s.position + s.R_world_body * (q - com_));
  }

  // Keeps the deepest contacts of one part (those from `before` on) and
  // tags them with the part.
  static void tag_contacts(Flight& f, std::size_t before, PartKind kind, int foot) {
    // On a height field a foot's contacts within a cell and 25° of a
    // deeper one are one patch of the sampled surface (on noisy ground it
    // touches several triangles a few millimetres apart, each with about
    // the same normal): one contact with their springs. Rows that repeat
    // another only slow ODE's LCP (5 rows a step cost 11.5 k cycles, 4
    // cost 7.9 k). Only the feet: a sphere's contact forces all pass
    // through its centre, so the merged one pushes along the same line; a
    // capsule's or a disk's do not, and a merged contact that moves to
    // whichever of two points is deeper rocks a body lying on an arm or a
    // propeller (it never came to rest on a step edge).
    if (f.scratch.height_field != nullptr && kind == PartKind::Foot) {
      detail::merge_patch_contacts(f.contacts, before, f.scratch.height_field->cell(), kPatchCos);
    }
    // At most 4 contacts per part (the body box: what collide_box
    // chose), the deepest: enough for a stable support, and ODE's LCP
    // cost grows with the cube of the contact count.
    const std::size_t max_contacts = kind == PartKind::Body ? detail::kMaxBoxContacts : 4;
    if (f.contacts.size() - before > max_contacts) {
      std::stable_sort(f.contacts.begin() + static_cast<std::ptrdiff_t>(before), f.contacts.end(),
                       [](const detail::Contact& a, const detail::Contact& b) { return a.depth > b.depth; });
      f.contacts.resize(before + max_contacts);
    }
    for (std::size_t k = before; k < f.contacts.size(); ++k) {
      f.contact_kind.push_back(kind);
      f.contact_foot.push_back(foot);
    }
  }

  // This step's contacts of every part with the terrain, in f.contacts.
  void find_contacts(Flight& f, const DroneState& s) {
    f.contacts.clear();
    f.contact_kind.clear();
    f.contact_foot.clear();
    const auto& terrain = sim_.terrain();
    // Whole-twin broad phase: a sphere around the centre of mass holding
    // every part; nothing to do while it is above all terrain below it.
    // Every part lies inside that sphere, so a part above the highest
    // terrain point under it has no candidate either (Scratch::z_top).
    const Eigen::Vector3d reach = Eigen::Vector3d::Constant(reach_);
    f.scratch.z_top = terrain.max_z_near(Eigen::AlignedBox3d(s.position - reach, s.position + reach));
    const bool near = f.scratch.z_top >= s.position.z() - reach_;
    for (std::size_t i = 0; near && i < af_.legs.size(); ++i) {
      std::size_t before = f.contacts.size();
      const Sphere& sphere = feet_[i];
      detail::collide_sphere(terrain, to_world(s, sphere.centre), sphere.radius, f.scratch, f.contacts);
      tag_contacts(f, before, PartKind::Foot, static_cast<int>(i));
      before = f.contacts.size();
      const Capsule& c = legs_[i];
      detail::collide_capsule(terrain, to_world(s, c.a), to_world(s, c.b), c.radius, f.scratch, f.contacts);
      tag_contacts(f, before, PartKind::Leg, static_cast<int>(i));
    }
    for (std::size_t i = 0; near && i < af_.motor_count(); ++i) {
      std::size_t before = f.contacts.size();
      const Capsule& a = arms_[i];
      detail::collide_capsule(terrain, to_world(s, a.a), to_world(s, a.b), a.radius, f.scratch, f.contacts);
      tag_contacts(f, before, PartKind::Arm, -1);
      before = f.contacts.size();
      const Disk& d = props_[i];
      detail::collide_disk(terrain, to_world(s, d.centre), s.R_world_body * d.axis, d.radius, d.half_thickness,
                           f.scratch, f.contacts);
      tag_contacts(f, before, PartKind::Propeller, -1);
    }
    if (near) {
      const std::size_t before = f.contacts.size();
      const Box b = af_.body_box();
      detail::collide_box(terrain, to_world(s, b.centre), s.R_world_body, b.half_extents, f.scratch, f.contacts);
      tag_contacts(f, before, PartKind::Body, -1);
    }
  }

  // Records which parts touch (feet, strikes) and hands each valid contact
  // to ODE as a soft contact joint for this step.
  void add_contact_joints(Flight& f, const DroneState& s) {
    std::fill(f.foot_touch.begin(), f.foot_touch.end(), false);
    for (std::size_t k = 0; k < f.contacts.size(); ++k) {
      const detail::Contact& contact = f.contacts[k];
      // A non-finite contact or one without a normal must never reach ODE
      // (as for motor commands: its normalisation asserts abort).
      if (!contact.position.allFinite() || !std::isfinite(contact.depth) ||
          !(std::abs(contact.normal.squaredNorm() - 1.0) < 1e-6)) {
        continue;
      }
      switch (f.contact_kind[k]) {
        case PartKind::Foot:
        case PartKind::Leg:
          f.foot_touch[static_cast<std::size_t>(f.contact_foot[k])] = true;
          break;
        case PartKind::Arm:
          f.res.arm_strike = true;
          break;
        case PartKind::Propeller:
          f.res.prop_strike = true;
          break;
        case PartKind::Body:
          // Without landing gear the body is what the airframe lands on:
          // touching is no strike, and its bottom corners stand in for the
          // feet.
          if (af_.has_landing_gear()) {
            f.res.body_strike = true;
          } else if (const int c =
                         bottom_corner_of(s.R_world_body.transpose() * (contact.position - s.position) + com_);
                     c >= 0) {
            f.foot_touch[static_cast<std::size_t>(c)] = true;
          }
          break;
      }
      dContact c{};
      c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
      c.surface.mu = friction_;
      c.surface.soft_erp = erp_;
      c.surface.soft_cfm = cfm_;
      if (contact.weight != 1) {
        // A merged patch keeps the springs of the contacts it stands for.
        const double w = contact.weight;
        touchdown::detail::soft_params(opt_.step, w * opt_.contact_stiffness, w * opt_.contact_damping,
                                       c.surface.soft_erp, c.surface.soft_cfm);
      }
      for (int a = 0; a < 3; ++a) {
        c.geom.pos[a] = contact.position[a];
        c.geom.normal[a] = contact.normal[a];
      }
      c.geom.depth = contact.depth;
      dJointID j = dJointCreateContact(world_, contacts_group_, &c);
      dJointAttach(j, body_, nullptr);
    }
  }

  // End of run: after disarm still for still_time or at rest for rest_time
  // (true: settled), or the timeout marked on the last step.
  bool run_ended(Flight& f, long step) {
    const double v1 = vec_of(dBodyGetLinearVel(body_)).norm(), w1 = vec_of(dBodyGetAngularVel(body_)).norm();
    const bool landed = f.detector.landed();
    f.still_timer = landed && v1 < opt_.still_linear && w1 < opt_.still_angular ? f.still_timer + f.dt : 0.0;
    f.rest_timer = landed && v1 < opt_.rest_linear && w1 < opt_.rest_angular ? f.rest_timer + f.dt : 0.0;
    if (f.still_timer >= opt_.still_time || f.rest_timer >= opt_.rest_time) {
      f.res.status = RunStatus::Settled;
      return true;
    }
    if (step + 1 == f.max_steps) {
      f.res.status = RunStatus::Timeout;
      f.res.message = "did not come to rest before the timeout";
    }
    return false;
  }

  // The figures of the final state: attitude, nutation, offset, feet.
  RunResult final_result(Flight& f, const LandingConditions& lc) const {
    RunResult& res = f.res;
    const Eigen::Matrix3d R = rotation_of(body_);
    const Eigen::Vector3d p = vec_of(dBodyGetPosition(body_));
    res.sim_time = static_cast<double>(res.steps) * f.dt;
    res.final_position = p;
    res.nutation = nutation_of(R);
    res.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    res.roll = std::atan2(R(2, 1), R(2, 2));
    res.yaw = std::atan2(R(1, 0), R(0, 0));
    // Offset of the airframe's body origin from the landing point.
    const Eigen::Vector3d origin = p - R * com_;
    res.offset = (origin.head<2>() - lc.landing_point).norm();
    res.tipped = res.nutation > opt_.tip_nutation;
    res.all_feet_in_contact = std::all_of(f.foot_touch.begin(), f.foot_touch.end(), [](bool b) { return b; });
    if (!p.allFinite() || !R.allFinite()) {
      res.status = RunStatus::Unstable;
      res.message = "non-finite state";
    }
    return std::move(res);
  }

  // Which bottom corner of the body box (0..3) a body-frame contact point
  // is at (within 1 mm), or -1.
  [[nodiscard]] int bottom_corner_of(const Eigen::Vector3d& q) const {
    const Eigen::Vector3d h = 0.5 * af_.body_size;
    constexpr double tol = 1e-3;
    if (std::abs(q.z() + h.z()) > tol || std::abs(std::abs(q.x()) - h.x()) > tol ||
        std::abs(std::abs(q.y()) - h.y()) > tol) {
      return -1;
    }
    return (q.x() > 0 ? 1 : 0) + (q.y() > 0 ? 2 : 0);
  }

  const LandingSimulator& sim_;
  const Airframe& af_;
  const SimulationOptions& opt_;
  Eigen::Vector3d com_;
  dWorldID world_;
  dThreadingImplementationID threading_;
  dJointGroupID contacts_group_;
  dBodyID body_;
  double friction_ = 0.8, erp_ = 0.2, cfm_ = 1e-5;
  Mixer mixer_;
  double hover_thrust_ = 0;
  double reach_ = 0;
  std::vector<double> motor_;
  // Parts in the airframe's body frame, computed once.
  std::vector<Eigen::Vector3d> motor_r_;
  std::vector<Capsule> arms_, legs_;
  std::vector<Disk> props_;
  std::vector<Sphere> feet_;
};

}  // namespace

LandingSimulator::LandingSimulator(Airframe airframe, std::shared_ptr<const TerrainModel> terrain,
                                   SimulationOptions options)
    : airframe_(std::move(airframe)), terrain_(std::move(terrain)), options_(options) {
  std::string why;
  if (!airframe_.validate(&why)) throw InvalidArgument("airframe: " + why);
  if (!terrain_) throw InvalidArgument("landing simulator: no terrain");
  if (!options_.validate(&why)) throw InvalidArgument("simulation options: " + why);
}

bool SimulationOptions::validate(std::string* why) const {
  if (!(step > 0 && step <= 0.01)) return invalid(why, "step: must be in (0, 0.01] s");
  if (!(timeout > 0) || !std::isfinite(timeout)) return invalid(why, "timeout: must be positive [s]");
  if (!(still_time >= 0) || !std::isfinite(still_time)) return invalid(why, "still_time: must be >= 0 s");
  if (!(still_linear > 0) || !std::isfinite(still_linear)) return invalid(why, "still_linear: must be positive [m/s]");
  if (!(still_angular > 0) || !std::isfinite(still_angular)) {
    return invalid(why, "still_angular: must be positive [rad/s]");
  }
  if (!(rest_time >= 0) || !std::isfinite(rest_time)) return invalid(why, "rest_time: must be >= 0 s");
  if (!(rest_linear > 0) || !std::isfinite(rest_linear)) return invalid(why, "rest_linear: must be positive [m/s]");
  if (!(rest_angular > 0) || !std::isfinite(rest_angular))
    return invalid(why, "rest_angular: must be positive [rad/s]");
  if (!(contact_stiffness > 0) || !std::isfinite(contact_stiffness)) {
    return invalid(why, "contact_stiffness: must be positive [N/m]");
  }
  if (!(contact_damping >= 0) || !std::isfinite(contact_damping)) {
    return invalid(why, "contact_damping: must be >= 0 [N s/m]");
  }
  if (solver_iterations < 1) return invalid(why, "solver_iterations: must be >= 1");
  if (!(tip_nutation > 0 && tip_nutation <= std::numbers::pi))
    return invalid(why, "tip_nutation: must be in (0, pi] rad");
  return true;
}

RunResult LandingSimulator::land(const LandingConditions& lc) const {
  Run run(*this, lc.friction);
  const Eigen::Vector2d xy = lc.landing_point + lc.start_offset;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation_from_rpy(lc.roll, lc.pitch, lc.heading + lc.heading_error);
  T.translation() = Eigen::Vector3d(xy.x(), xy.y(), lc.ground_z + lc.hover_offset - airframe_.ground_z());
  run.place(T);
  run.set_motors_hover();
  return run.fly(lc, true);
}

RunResult LandingSimulator::release(const Eigen::Isometry3d& pose, double friction) const {
  Run run(*this, friction);
  run.place(pose);
  LandingConditions lc;
  lc.landing_point = pose.translation().head<2>();
  return run.fly(lc, false);
}

}  // namespace touchdown::twin
