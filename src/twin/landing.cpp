// One landing of the twin. Dynamics: ODE (world, one rigid body, contact
// joints). Contacts: src/twin/contacts.cpp. Flight control: an emulation of
// PX4's multicopter land mode — position → velocity → acceleration/thrust
// (mc_pos_control), attitude → rate (mc_att_control, geometric attitude
// error as in Lee, Leok & McClamroch 2010), rate → torque, a control
// allocation to the motors, first-order motor lag — and PX4's three-stage
// land detector (MulticopterLandDetector: ground contact → maybe landed →
// landed), the thrust ramp-down after ground contact, and disarm.
#include "touchdown/twin/landing.hpp"

#include <ode/ode.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <mutex>
#include <numbers>

#include "contacts.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::twin {
namespace {

constexpr double kGravity = 9.80665;

void ensure_ode() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    // ODE prints solver notes (e.g. "LCP internal error, s <= 0" when a
    // pivot degenerates; the step still completes) to stderr, which would
    // corrupt the apps' output. Instability is detected from the state instead.
    dSetMessageHandler([](int, const char*, va_list) {});
  });
  dAllocateODEDataForThread(dAllocateMaskAll);
}

Eigen::Matrix3d rotation_of(dBodyID b) {
  const dReal* r = dBodyGetRotation(b);  // 3x4 row-major
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = r[i * 4 + j];
  return R;
}

Eigen::Vector3d vec_of(const dReal* v) { return {v[0], v[1], v[2]}; }

double nutation_of(const Eigen::Matrix3d& R) { return std::acos(std::clamp(R(2, 2), -1.0, 1.0)); }

Eigen::Vector3d vee(const Eigen::Matrix3d& S) { return {S(2, 1), S(0, 2), S(1, 0)}; }

// ODE's ERP/CFM for a spring-damper contact (ODE manual, "Joint error and
// the error reduction parameter", "Soft constraint and constraint force mixing").
void soft_params(double h, double kp, double kd, double& erp, double& cfm) {
  erp = h * kp / (h * kp + kd);
  cfm = 1.0 / (h * kp + kd);
}

enum class PartKind { Foot, Leg, Arm, Propeller, Body };

// Everything of one run: ODE objects, controller state, bookkeeping.
class Run {
 public:
  Run(const LandingSimulator& sim, double friction) : sim_(sim), af_(sim.airframe()), opt_(sim.options()) {
    ensure_ode();
    com_ = af_.centre_of_mass();
    world_ = dWorldCreate();
    // Each world gets its own (single-threaded) stepping implementation: the
    // library-wide default one is shared and must not step two worlds at once.
    threading_ = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_), threading_);
    dWorldSetGravity(world_, 0, 0, -kGravity);
    dWorldSetQuickStepNumIterations(world_, opt_.solver_iterations);
    dWorldSetContactSurfaceLayer(world_, 0.0005);
    dWorldSetContactMaxCorrectingVel(world_, 1.0);
    dWorldSetAutoDisableFlag(world_, 0);
    contacts_group_ = dJointGroupCreate(0);
    body_ = dBodyCreate(world_);
    dMass m;
    const Eigen::Matrix3d I = af_.inertia_about_com();
    dMassSetParameters(&m, af_.total_mass(), 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    dBodySetMass(body_, &m);
    friction_ = friction;
    soft_params(opt_.step, opt_.contact_stiffness, opt_.contact_damping, erp_, cfm_);
    // Allocation matrix: [thrust; torque] = A f, motor positions about the CoM.
    const std::size_t n = af_.motor_count();
    alloc_.resize(4, static_cast<Eigen::Index>(n));
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d r = af_.motor_position(i) - com_;
      const auto c = static_cast<Eigen::Index>(i);
      alloc_(0, c) = 1.0;
      alloc_(1, c) = r.y();                                  // roll torque of a thrust along +z at r
      alloc_(2, c) = -r.x();                                 // pitch torque
      alloc_(3, c) = -af_.spin[i] * af_.torque_coefficient;  // reaction torque opposes the spin
    }
    alloc_pinv_ = alloc_.transpose() * (alloc_ * alloc_.transpose()).inverse();
    hover_thrust_ = af_.total_mass() * kGravity;
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
    const Eigen::Matrix3d M = T_world_body.linear();
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) R[i * 4 + j] = M(i, j);
      R[i * 4 + 3] = 0;
    }
    dBodySetRotation(body_, R);
    dBodySetLinearVel(body_, 0, 0, 0);
    dBodySetAngularVel(body_, 0, 0, 0);
  }

  void set_motors_hover() {
    std::fill(motor_.begin(), motor_.end(), hover_thrust_ / static_cast<double>(motor_.size()));
  }

  RunResult fly(const LandingConditions& lc, bool armed) {
    RunResult res;
    const auto& cp = opt_.controller;
    const double dt = opt_.step;
    const long max_steps = static_cast<long>(std::ceil(opt_.timeout / dt));
    const double stage_time = cp.land_trigger_time / 3.0;
    const double motor_alpha = 1.0 - std::exp(-dt / af_.motor_time_constant);
    Eigen::Vector2d vel_int = Eigen::Vector2d::Zero();
    double vz_int = 0;
    Eigen::Vector3d v_prev = Eigen::Vector3d::Zero(), accel_lp = Eigen::Vector3d::Zero();
    int stage = armed ? 0 : 3;
    double stage_timer = 0, still_timer = 0, ramp = 1.0, thrust_at_contact = hover_thrust_;
    bool touched = false;
    const double terrain_floor = sim_.terrain().bounds().min.z() - 1.0;
    std::vector<detail::Contact> contacts;
    std::vector<PartKind> contact_kind;
    std::vector<int> contact_foot;
    detail::Scratch scratch;
    std::vector<bool> foot_touch(af_.legs.size());

    for (long step = 0; step < max_steps; ++step) {
      const Eigen::Vector3d p = vec_of(dBodyGetPosition(body_));
      const Eigen::Vector3d v = vec_of(dBodyGetLinearVel(body_));
      const Eigen::Vector3d w_world = vec_of(dBodyGetAngularVel(body_));
      const Eigen::Matrix3d R = rotation_of(body_);
      const auto& tb = sim_.terrain().bounds();
      const bool off_map = p.x() < tb.min.x() || p.x() > tb.max.x() || p.y() < tb.min.y() || p.y() > tb.max.y();
      if (!p.allFinite() || !v.allFinite() || !R.allFinite() || p.z() < terrain_floor || off_map || v.norm() > 30.0 ||
          w_world.norm() > 200.0) {
        res.status = RunStatus::Unstable;
        res.steps = step;
        res.sim_time = static_cast<double>(step) * dt;
        return res;
      }
      const Eigen::Vector3d w = R.transpose() * w_world;
      const double nut = nutation_of(R);
      if (touched) res.max_touchdown_nutation = std::max(res.max_touchdown_nutation, nut);

      // ---- flight controller -------------------------------------------------
      if (stage < 3) {
        // Position → velocity (PX4 PositionControl::_positionControl).
        Eigen::Vector2d v_sp = cp.xy_p * (lc.landing_point - p.head<2>());
        if (v_sp.norm() > cp.xy_vel_max) v_sp *= cp.xy_vel_max / v_sp.norm();
        const double vz_sp = -lc.land_speed;
        // Velocity → acceleration (PositionControl::_velocityControl), PID
        // with the derivative low-passed at MPC_VELD_LP (touchdown shocks
        // must not become tilt commands).
        const double lp = 1.0 - std::exp(-2.0 * std::numbers::pi * cp.vel_deriv_lp_hz * dt);
        accel_lp += lp * ((v - v_prev) / dt - accel_lp);
        const Eigen::Vector3d& accel = accel_lp;
        const Eigen::Vector2d e_xy = v_sp - v.head<2>();
        vel_int += e_xy * dt;
        vel_int = vel_int.cwiseMax(-2.0).cwiseMin(2.0);
        Eigen::Vector2d a_xy = cp.xy_vel_p * e_xy + cp.xy_vel_i * vel_int - cp.xy_vel_d * accel.head<2>();
        const double e_z = vz_sp - v.z();
        vz_int = std::clamp(vz_int + e_z * dt, -3.0, 3.0);
        const double a_z = cp.z_vel_p * e_z + cp.z_vel_i * vz_int;
        // Thrust vector with the tilt limit (MPC_TILTMAX_AIR).
        Eigen::Vector3d F(a_xy.x(), a_xy.y(), a_z + kGravity);
        F *= af_.total_mass();
        F.z() = std::max(F.z(), 0.1 * hover_thrust_);
        const double max_h = F.z() * std::tan(deg_to_rad(cp.tilt_max_deg));
        if (F.head<2>().norm() > max_h) F.head<2>() *= max_h / F.head<2>().norm();
        // Desired attitude: body z along F, heading ψ.
        const Eigen::Vector3d zb = F.normalized();
        const Eigen::Vector3d xc(std::cos(lc.heading), std::sin(lc.heading), 0.0);
        const Eigen::Vector3d yb = zb.cross(xc).normalized();
        Eigen::Matrix3d Rd;
        Rd.col(0) = yb.cross(zb);
        Rd.col(1) = yb;
        Rd.col(2) = zb;
        // Attitude → rates (geometric error), rates → torque.
        if (stage >= 1) {
          // After ground contact PX4 (mc_pos_control limit_thrust_during_landing)
          // takes the collective thrust to zero, commands a level attitude at
          // the current heading and resets the integrators.
          const Eigen::Vector3d xc2(std::cos(lc.heading), std::sin(lc.heading), 0.0);
          Rd.col(2) = Eigen::Vector3d::UnitZ();
          Rd.col(1) = Eigen::Vector3d::UnitZ().cross(xc2).normalized();
          Rd.col(0) = Rd.col(1).cross(Rd.col(2));
        }
        const Eigen::Vector3d e_R = 0.5 * vee(Rd.transpose() * R - R.transpose() * Rd);
        Eigen::Vector3d w_sp(-cp.roll_p * e_R.x(), -cp.pitch_p * e_R.y(), -cp.yaw_p * e_R.z());
        const double yaw_rate_max = deg_to_rad(cp.yaw_rate_max_deg);
        w_sp.z() = std::clamp(w_sp.z(), -yaw_rate_max, yaw_rate_max);
        const Eigen::Vector3d alpha(cp.rate_p_roll_pitch * (w_sp.x() - w.x()),
                                    cp.rate_p_roll_pitch * (w_sp.y() - w.y()), cp.rate_p_yaw * (w_sp.z() - w.z()));
        const Eigen::Matrix3d J = af_.inertia_about_com();
        const Eigen::Vector3d tau = J * alpha + w.cross(J * w);
        double thrust = std::max(0.0, F.dot(R.col(2)));

        // ---- land detector (three stages, each held a third of LNDMC_TRIG_TIME)
        const bool slow_vertical = std::abs(v.z()) < cp.land_z_vel_max;
        const bool low_thrust = thrust * ramp < cp.low_thrust_fraction * hover_thrust_;
        const bool low_rotation = w.norm() < deg_to_rad(cp.land_rot_max_deg);
        if (stage == 0) {
          stage_timer = slow_vertical && vz_sp < 0 ? stage_timer + dt : 0.0;
          if (stage_timer >= stage_time) {
            stage = 1;  // ground contact: start the thrust ramp-down
            stage_timer = 0;
            vel_int.setZero();
            thrust_at_contact = thrust;
          }
        } else {
          ramp = std::max(0.0, ramp - dt / cp.thrust_ramp_time);
          const bool ok = slow_vertical && low_thrust && low_rotation;
          stage_timer = ok ? stage_timer + dt : 0.0;
          if (stage_timer >= stage_time) {
            ++stage;  // maybe landed → landed
            stage_timer = 0;
          }
        }
        if (stage >= 1) thrust = std::min(thrust, ramp * thrust_at_contact);
        // Allocation with saturation as PX4's mixer without airmode: keep the
        // collective thrust, scale the torques down until every motor command
        // is within [0, max_thrust] (so torque authority fades with thrust).
        thrust = std::min(thrust, af_.max_thrust * static_cast<double>(motor_.size()));
        const Eigen::VectorXd f_thrust = alloc_pinv_ * Eigen::Vector4d(thrust, 0, 0, 0);
        const Eigen::VectorXd f_torque = alloc_pinv_ * Eigen::Vector4d(0, tau.x(), tau.y(), tau.z());
        double scale = 1.0;
        for (Eigen::Index i = 0; i < f_thrust.size(); ++i) {
          const double ft = f_thrust[i], fq = f_torque[i];
          if (fq < 0 && ft + scale * fq < 0) scale = std::max(0.0, -ft / fq);
          if (fq > 0 && ft + scale * fq > af_.max_thrust) scale = std::max(0.0, (af_.max_thrust - ft) / fq);
        }
        Eigen::VectorXd f = f_thrust + scale * f_torque;
        for (Eigen::Index i = 0; i < f.size(); ++i) f[i] = std::clamp(f[i], 0.0, af_.max_thrust);
        for (std::size_t i = 0; i < motor_.size(); ++i) {
          const double cmd = stage >= 3 ? 0.0 : f[static_cast<Eigen::Index>(i)];
          motor_[i] += (cmd - motor_[i]) * motor_alpha;
        }
      } else {
        for (double& m : motor_) m += (0.0 - m) * motor_alpha;  // disarmed: spin down
      }
      v_prev = v;
      for (std::size_t i = 0; i < motor_.size(); ++i) {
        const Eigen::Vector3d& r = motor_r_[i];
        dBodyAddRelForceAtRelPos(body_, 0, 0, motor_[i], r.x(), r.y(), r.z());
        dBodyAddRelTorque(body_, 0, 0, -af_.spin[i] * af_.torque_coefficient * motor_[i]);
      }

      // ---- contacts ------------------------------------------------------------
      contacts.clear();
      contact_kind.clear();
      contact_foot.clear();
      auto world = [&](const Eigen::Vector3d& q) { return Eigen::Vector3d(p + R * (q - com_)); };
      auto tag = [&](std::size_t before, PartKind kind, int foot) {
        // At most kMaxContactsPerPart per part, the deepest: enough for a
        // stable support, and ODE's LCP cost grows with the cube of the
        // contact count.
        constexpr std::size_t kMaxContactsPerPart = 4;
        if (contacts.size() - before > kMaxContactsPerPart) {
          std::stable_sort(contacts.begin() + static_cast<std::ptrdiff_t>(before), contacts.end(),
                           [](const detail::Contact& a, const detail::Contact& b) { return a.depth > b.depth; });
          contacts.resize(before + kMaxContactsPerPart);
        }
        for (std::size_t k = before; k < contacts.size(); ++k) {
          contact_kind.push_back(kind);
          contact_foot.push_back(foot);
        }
      };
      const auto& terrain = sim_.terrain();
      // Whole-twin broad phase: a sphere around the centre of mass holding
      // every part; nothing to do while it is above all terrain below it.
      const Eigen::Vector3d reach = Eigen::Vector3d::Constant(reach_);
      const bool near = terrain.max_z_near(Eigen::AlignedBox3d(p - reach, p + reach)) >= p.z() - reach_;
      for (std::size_t i = 0; near && i < af_.legs.size(); ++i) {
        std::size_t before = contacts.size();
        const Sphere& s = feet_[i];
        detail::collide_sphere(terrain, world(s.centre), s.radius, scratch, contacts);
        tag(before, PartKind::Foot, static_cast<int>(i));
        before = contacts.size();
        const Capsule& c = legs_[i];
        detail::collide_capsule(terrain, world(c.a), world(c.b), c.radius, scratch, contacts);
        tag(before, PartKind::Leg, static_cast<int>(i));
      }
      for (std::size_t i = 0; near && i < af_.motor_count(); ++i) {
        std::size_t before = contacts.size();
        const Capsule& a = arms_[i];
        detail::collide_capsule(terrain, world(a.a), world(a.b), a.radius, scratch, contacts);
        tag(before, PartKind::Arm, -1);
        before = contacts.size();
        const Disk& d = props_[i];
        detail::collide_disk(terrain, world(d.centre), R * d.axis, d.radius, d.half_thickness, scratch, contacts);
        tag(before, PartKind::Propeller, -1);
      }
      if (near) {
        const std::size_t before = contacts.size();
        const Box b = af_.body_box();
        detail::collide_box(terrain, world(b.centre), R, b.half_extents, scratch, contacts);
        tag(before, PartKind::Body, -1);
      }
      std::fill(foot_touch.begin(), foot_touch.end(), false);
      for (std::size_t k = 0; k < contacts.size(); ++k) {
        switch (contact_kind[k]) {
          case PartKind::Foot:
          case PartKind::Leg:
            foot_touch[static_cast<std::size_t>(contact_foot[k])] = true;
            break;
          case PartKind::Arm:
            res.arm_strike = true;
            break;
          case PartKind::Propeller:
            res.prop_strike = true;
            break;
          case PartKind::Body:
            res.body_strike = true;
            break;
        }
        dContact c{};
        c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
        c.surface.mu = friction_;
        c.surface.soft_erp = erp_;
        c.surface.soft_cfm = cfm_;
        for (int a = 0; a < 3; ++a) {
          c.geom.pos[a] = contacts[k].position[a];
          c.geom.normal[a] = contacts[k].normal[a];
        }
        c.geom.depth = contacts[k].depth;
        dJointID j = dJointCreateContact(world_, contacts_group_, &c);
        dJointAttach(j, body_, nullptr);
      }
      if (!contacts.empty()) touched = true;

      dWorldStep(world_, dt);
      dJointGroupEmpty(contacts_group_);
      ++res.steps;

      if (opt_.record_trace && step % 20 == 0) res.trace.push_back({static_cast<double>(step) * dt, p, nut, stage});

      // ---- end of run: still for still_time after disarm ----------------------
      const Eigen::Vector3d v1 = vec_of(dBodyGetLinearVel(body_)), w1 = vec_of(dBodyGetAngularVel(body_));
      if (stage >= 3 && v1.norm() < opt_.still_linear && w1.norm() < opt_.still_angular) {
        still_timer += dt;
        if (still_timer >= opt_.still_time) {
          res.status = RunStatus::Settled;
          break;
        }
      } else {
        still_timer = 0;
      }
      if (step + 1 == max_steps) res.status = RunStatus::Timeout;
    }
    const Eigen::Matrix3d R = rotation_of(body_);
    const Eigen::Vector3d p = vec_of(dBodyGetPosition(body_));
    res.sim_time = static_cast<double>(res.steps) * dt;
    res.final_position = p;
    res.nutation = nutation_of(R);
    res.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
    res.roll = std::atan2(R(2, 1), R(2, 2));
    res.yaw = std::atan2(R(1, 0), R(0, 0));
    // Offset of the airframe's body origin from the landing point.
    const Eigen::Vector3d origin = p - R * com_;
    res.offset = (origin.head<2>() - lc.landing_point).norm();
    res.tipped = res.nutation > opt_.tip_nutation;
    res.all_feet_in_contact = std::all_of(foot_touch.begin(), foot_touch.end(), [](bool b) { return b; });
    if (!p.allFinite() || !R.allFinite()) res.status = RunStatus::Unstable;
    return res;
  }

 private:
  const LandingSimulator& sim_;
  const Airframe& af_;
  const SimulationOptions& opt_;
  Eigen::Vector3d com_;
  dWorldID world_;
  dThreadingImplementationID threading_;
  dJointGroupID contacts_group_;
  dBodyID body_;
  double friction_ = 0.8, erp_ = 0.2, cfm_ = 1e-5;
  Eigen::MatrixXd alloc_, alloc_pinv_;
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

std::string to_string(RunStatus status) {
  switch (status) {
    case RunStatus::Settled:
      return "settled";
    case RunStatus::Timeout:
      return "timeout";
    case RunStatus::Unstable:
      return "unstable";
  }
  return "?";
}

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
