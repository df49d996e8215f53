// The mission's quadrotor on ODE with the moving pad (drone.hpp). Contacts
// between the airframe's primitives and the pad box or the ground plane
// come from ODE's own primitive colliders (no trimesh: thread-safe).
#include "touchdown/mission/drone.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/checks.hpp"
#include "core/ode_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::positive;
using touchdown::detail::rotation_of;
using touchdown::detail::to_ode;
using touchdown::detail::vec_of;

enum class Part { Foot, Leg, Arm, Propeller, Body };

// A rotation taking z onto `axis` (for capsules and cylinders, whose ODE
// axis is their local z).
Eigen::Matrix3d z_onto(const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis.normalized()).toRotationMatrix();
}

}  // namespace

bool DroneOptions::validate(std::string* why) const {
  std::string af;
  if (!airframe.validate(&af)) return invalid(why, "drone.airframe: " + af);
  if (!(step > 0 && step <= 0.01)) return invalid(why, "drone.step: must be in (0, 0.01] s");
  if (!(drag_linear >= 0) || !std::isfinite(drag_linear)) return invalid(why, "drone.drag_linear: must be >= 0");
  if (!(drag_quadratic >= 0) || !std::isfinite(drag_quadratic)) {
    return invalid(why, "drone.drag_quadratic: must be >= 0");
  }
  if (!positive(contact_stiffness)) return invalid(why, "drone.contact_stiffness: must be positive [N/m]");
  if (!(contact_damping >= 0) || !std::isfinite(contact_damping)) {
    return invalid(why, "drone.contact_damping: must be >= 0 [N s/m]");
  }
  // > 0: the landed, unpowered drone must be held (the slide guard divides by it).
  if (!positive(pad_friction)) return invalid(why, "drone.pad_friction: must be > 0 (what holds the landed drone)");
  if (!(ground_friction >= 0) || !std::isfinite(ground_friction)) {
    return invalid(why, "drone.ground_friction: must be >= 0");
  }
  if (!(wind_observer_time >= 0 && wind_observer_time <= 10)) {
    return invalid(why, "drone.wind_observer_time: must be in [0, 10] s (0 = no wind estimate)");
  }
  if (!(spool_down >= 0 && spool_down <= 5)) return invalid(why, "drone.spool_down: must be in [0, 5] s (0 = cut)");
  return true;
}

struct DroneSimulation::Impl {
  Impl(DroneOptions o, PadGeometry p)
      : options(std::move(o)),
        pad(p),
        af(options.airframe),
        com(af.centre_of_mass()),
        mixer(af, com),
        controller(options.controller, af.total_mass(), af.inertia_about_com(), options.step),
        motor_alpha(1.0 - std::exp(-options.step / af.motor_time_constant)) {
    world = touchdown::detail::create_world(twin::kStandardGravity, &threading);
    contact_group = dJointGroupCreate(0);
    body = touchdown::detail::create_rigid_body(world, af.total_mass(), af.inertia_about_com());
    touchdown::detail::soft_params(options.step, options.contact_stiffness, options.contact_damping, erp, cfm);
    // The airframe's collision parts, offset from the centre of mass.
    auto attach = [&](dGeomID g, const Eigen::Vector3d& centre, const Eigen::Matrix3d& R, Part kind) {
      dGeomSetBody(g, body);
      const Eigen::Vector3d c = centre - com;
      dGeomSetOffsetPosition(g, c.x(), c.y(), c.z());
      dMatrix3 r;
      to_ode(R, r);
      dGeomSetOffsetRotation(g, r);
      geoms.push_back(g);
      kinds.push_back(kind);
      reach = std::max(reach, c.norm());
    };
    const std::size_t n = af.motor_count();
    for (std::size_t i = 0; i < n; ++i) {
      motor_r.push_back(af.motor_position(i) - com);
      const twin::Capsule a = af.arm(i);
      const double length = (a.b - a.a).norm();
      attach(dCreateCapsule(nullptr, a.radius, length), 0.5 * (a.a + a.b), z_onto(a.b - a.a), Part::Arm);
      reach = std::max(reach, (a.b - com).norm() + a.radius);
      const twin::Disk d = af.propeller(i);
      attach(dCreateCylinder(nullptr, d.radius, 2 * d.half_thickness), d.centre, z_onto(d.axis), Part::Propeller);
      reach = std::max(reach, (d.centre - com).norm() + d.radius + d.half_thickness);
    }
    for (std::size_t i = 0; i < af.legs.size(); ++i) {
      const twin::Sphere f = af.foot(i);
      attach(dCreateSphere(nullptr, f.radius), f.centre, Eigen::Matrix3d::Identity(), Part::Foot);
      reach = std::max(reach, (f.centre - com).norm() + f.radius);
      const twin::Capsule l = af.leg(i);
      attach(dCreateCapsule(nullptr, l.radius, std::max((l.b - l.a).norm(), 1e-4)), 0.5 * (l.a + l.b),
             z_onto(l.b - l.a), Part::Leg);
    }
    const twin::Box b = af.body_box();
    attach(dCreateBox(nullptr, 2 * b.half_extents.x(), 2 * b.half_extents.y(), 2 * b.half_extents.z()), b.centre,
           Eigen::Matrix3d::Identity(), Part::Body);
    reach = std::max(reach, (b.centre - com).norm() + b.half_extents.norm());
    // The pad: a kinematic body (moved, not pushed) carrying a box below
    // its top face; the ground plane z = 0.
    pad_body = dBodyCreate(world);
    dBodySetKinematic(pad_body);
    pad_geom = dCreateBox(nullptr, pad.size.x(), pad.size.y(), pad.thickness);
    dGeomSetBody(pad_geom, pad_body);
    dGeomSetOffsetPosition(pad_geom, 0, 0, -0.5 * pad.thickness);
    ground = dCreatePlane(nullptr, 0, 0, 1, 0);
    motor = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
    support = af.support_points();
  }
  ~Impl() {
    for (dGeomID g : geoms) dGeomDestroy(g);
    dGeomDestroy(pad_geom);
    dGeomDestroy(ground);
    dJointGroupDestroy(contact_group);
    dWorldDestroy(world);
    dThreadingFreeImplementation(threading);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  DroneState read() const {
    DroneState s;
    s.t = t;
    s.position = vec_of(dBodyGetPosition(body));
    s.velocity = vec_of(dBodyGetLinearVel(body));
    s.R_world_body = rotation_of(body);
    s.w_body = s.R_world_body.transpose() * vec_of(dBodyGetAngularVel(body));
    s.acceleration = accel;
    s.yaw_deg = rad_to_deg(std::atan2(s.R_world_body(1, 0), s.R_world_body(0, 0)));
    s.on_ground = contact_state.on_ground || contact_state.support_on_pad || contact_state.strike_on_pad;
    return s;
  }

  // Contacts of every part with the pad and the ground, as ODE contact
  // joints for this step.
  void collide() {
    contact_state = {};
    const Eigen::Vector3d p = vec_of(dBodyGetPosition(body));
    const Eigen::Vector3d p_pad = T_pad.inverse() * p;
    const double half_diagonal = 0.5 * pad.size.norm();
    const bool near_pad = p_pad.z() < reach + pad.thickness && p_pad.head<2>().norm() < reach + half_diagonal;
    const bool near_ground = p.z() < reach;
    if (!near_pad && !near_ground) return;
    std::array<dContactGeom, 4> found{};
    for (std::size_t i = 0; i < geoms.size(); ++i) {
      for (int target = 0; target < 2; ++target) {
        if ((target == 0 && !near_pad) || (target == 1 && !near_ground)) continue;
        const int k = dCollide(geoms[i], target == 0 ? pad_geom : ground, static_cast<int>(found.size()), found.data(),
                               sizeof(dContactGeom));
        for (int c = 0; c < k; ++c) {
          dContact contact{};
          contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
          contact.surface.mu = target == 0 ? options.pad_friction : options.ground_friction;
          contact.surface.soft_erp = erp;
          contact.surface.soft_cfm = cfm;
          contact.geom = found[static_cast<std::size_t>(c)];
          // dCollide's normal points from the second geom into the first
          // (the drone part): pushes the drone out.
          const dJointID j = dJointCreateContact(world, contact_group, &contact);
          dJointAttach(j, body, target == 0 ? pad_body : nullptr);
          ++contact_state.contacts;
          if (target == 1) {
            contact_state.on_ground = true;
          } else if (kinds[i] == Part::Foot || kinds[i] == Part::Leg ||
                     (kinds[i] == Part::Body && !af.has_landing_gear())) {
            contact_state.support_on_pad = true;
          } else {
            contact_state.strike_on_pad = true;
          }
        }
      }
    }
  }

  DroneOptions options;
  PadGeometry pad;
  const twin::Airframe& af;
  Eigen::Vector3d com;
  twin::Mixer mixer;
  twin::LandController controller;
  double motor_alpha;
  dWorldID world{};
  dThreadingImplementationID threading{};
  dJointGroupID contact_group{};
  dBodyID body{}, pad_body{};
  dGeomID pad_geom{}, ground{};
  std::vector<dGeomID> geoms;
  std::vector<Part> kinds;
  std::vector<Eigen::Vector3d> motor_r, support;
  double reach = 0, erp = 0.2, cfm = 1e-5;
  Eigen::VectorXd motor;
  Eigen::Isometry3d T_pad = Eigen::Isometry3d::Identity();
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();
  double t = 0;  // since place() [s]
  // The spool-down after the motors-off command: its time so far (< 0:
  // armed), the collective thrust it ramps from, the attitude it holds.
  double spool_time = 0, spool_thrust = 0;
  Eigen::Matrix3d spool_attitude = Eigen::Matrix3d::Identity();
  ContactState contact_state;
};

DroneSimulation::DroneSimulation(DroneOptions options, PadGeometry pad) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!(pad.size.allFinite() && pad.size.minCoeff() > 0 && pad.thickness > 0 && std::isfinite(pad.thickness))) {
    throw InvalidArgument("pad: size and thickness must be positive");
  }
  if (!(pad.hold_force >= 0) || !std::isfinite(pad.hold_force))
    throw InvalidArgument("pad.hold_force: must be >= 0 [N]");
  impl_ = std::make_unique<Impl>(std::move(options), pad);
}

DroneSimulation::~DroneSimulation() = default;

void DroneSimulation::place(const Eigen::Isometry3d& T_world_body, const Eigen::Vector3d& v, bool armed) {
  Impl& m = *impl_;
  const Eigen::Vector3d p = T_world_body * m.com;
  dBodySetPosition(m.body, p.x(), p.y(), p.z());
  dMatrix3 R;
  to_ode(T_world_body.linear(), R);
  dBodySetRotation(m.body, R);
  dBodySetLinearVel(m.body, v.x(), v.y(), v.z());
  dBodySetAngularVel(m.body, 0, 0, 0);
  const double hover = m.af.total_mass() * twin::kStandardGravity / static_cast<double>(m.motor.size());
  m.motor.setConstant(armed ? hover : 0.0);
  m.spool_time = armed ? -1.0 : m.options.spool_down;
  m.controller.reset();
  m.controller.idle(v);
  m.accel.setZero();
  m.t = 0;
}

void DroneSimulation::set_pad(const Eigen::Isometry3d& T_world_pad, const Eigen::Vector3d& v,
                              const Eigen::Vector3d& w) {
  Impl& m = *impl_;
  m.T_pad = T_world_pad;
  const Eigen::Vector3d& p = T_world_pad.translation();
  dBodySetPosition(m.pad_body, p.x(), p.y(), p.z());
  dMatrix3 R;
  to_ode(T_world_pad.linear(), R);
  dBodySetRotation(m.pad_body, R);
  dBodySetLinearVel(m.pad_body, v.x(), v.y(), v.z());
  dBodySetAngularVel(m.pad_body, w.x(), w.y(), w.z());
}

void DroneSimulation::step(const twin::Setpoint& setpoint, const Eigen::Vector3d& p_estimate,
                           const Eigen::Vector3d& v_estimate, bool armed, const Eigen::Vector3d& wind) {
  Impl& m = *impl_;
  const double dt = m.options.step;
  const DroneState s = m.read();
  if (armed) {
    const twin::LandController::Output u = m.controller.update(
        {.position = p_estimate, .velocity = v_estimate, .R_world_body = s.R_world_body, .w_body = s.w_body}, setpoint,
        false);
    const Eigen::VectorXd& cmd = m.mixer.mix_in_place(u.thrust, u.torque);
    m.motor += (cmd - m.motor) * m.motor_alpha;
    m.spool_time = -1;
  } else if (m.spool_time < m.options.spool_down) {
    // Spool-down: the collective thrust ramped from what it was to 0, the
    // attitude held where it was at the command (its lean keeps the share
    // of the side force friction cannot take yet).
    if (m.spool_time < 0) {
      m.spool_time = 0;
      m.spool_thrust = m.motor.sum();
      m.spool_attitude = s.R_world_body;
    }
    m.controller.idle(v_estimate);
    const double thrust = m.spool_thrust * std::max(0.0, 1.0 - m.spool_time / m.options.spool_down);
    const Eigen::VectorXd& cmd =
        m.mixer.mix_in_place(thrust, m.controller.attitude_torque(s.R_world_body, s.w_body, m.spool_attitude, true));
    m.motor += (cmd - m.motor) * m.motor_alpha;
    m.spool_time += dt;
  } else {
    m.controller.idle(v_estimate);
    m.motor -= m.motor * m.motor_alpha;  // disarmed: spin down
  }
  for (Eigen::Index i = 0; i < m.motor.size(); ++i) {
    const Eigen::Vector3d& r = m.motor_r[static_cast<std::size_t>(i)];
    dBodyAddRelForceAtRelPos(m.body, 0, 0, m.motor[i], r.x(), r.y(), r.z());
    dBodyAddRelTorque(m.body, 0, 0, -m.af.spin[static_cast<std::size_t>(i)] * m.af.torque_coefficient * m.motor[i]);
  }
  // The pad's magnets, once the motors are off and a foot touched it in the
  // last step: pulled along the pad's -z at every support point.
  if (!armed && m.pad.hold_force > 0 && m.contact_state.support_on_pad) {
    const Eigen::Vector3d pull = -m.T_pad.linear().col(2) * (m.pad.hold_force / static_cast<double>(m.support.size()));
    for (const Eigen::Vector3d& q : m.support) {
      const Eigen::Vector3d r = q - m.com;
      dBodyAddForceAtRelPos(m.body, pull.x(), pull.y(), pull.z(), r.x(), r.y(), r.z());
    }
  }
  // Drag against the air: linear + quadratic in the airspeed.
  const Eigen::Vector3d air = s.velocity - wind;
  const Eigen::Vector3d drag = -(m.options.drag_linear + m.options.drag_quadratic * air.norm()) * air;
  dBodyAddForce(m.body, drag.x(), drag.y(), drag.z());
  m.collide();
  dWorldStep(m.world, dt);
  dJointGroupEmpty(m.contact_group);
  m.accel = (vec_of(dBodyGetLinearVel(m.body)) - s.velocity) / dt;
  m.t += dt;
}

DroneState DroneSimulation::state() const { return impl_->read(); }
const ContactState& DroneSimulation::contacts() const { return impl_->contact_state; }
const DroneOptions& DroneSimulation::options() const { return impl_->options; }
const Eigen::VectorXd& DroneSimulation::motor_thrusts() const { return impl_->motor; }

Eigen::Isometry3d DroneSimulation::T_world_body() const {
  const DroneState s = impl_->read();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = s.R_world_body;
  T.translation() = s.position - s.R_world_body * impl_->com;
  return T;
}

double DroneSimulation::support_height_above_pad() const {
  const Impl& m = *impl_;
  const Eigen::Isometry3d T = m.T_pad.inverse() * T_world_body();
  double lowest = 1e300;
  for (const Eigen::Vector3d& q : m.support) lowest = std::min(lowest, (T * q).z());
  return lowest - m.af.support_radius();
}

}  // namespace touchdown::mission
