// One landing mission, closed loop (mission.hpp).
#include "touchdown/mission/mission.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <map>
#include <numbers>

#include "core/checks.hpp"
#include "mission/stance.hpp"
#include "touchdown/core/batch.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::positive;
using touchdown::detail::probability;

// The drone's position estimate: per axis a Kalman filter on [p, v] driven
// by the accelerometer, corrected by position measurements that arrive
// late. A delayed measurement is fused exactly: the filter goes back to its
// state at the capture time, takes the measurement there and replays the
// accelerometer samples since (a second of them is kept). An innovation
// beyond gate_sigma standard deviations is refused; after max_refused in a
// row the filter restarts at the measurement (EKF2's reset on a rejected
// external position).
class DroneEstimator {
 public:
  DroneEstimator(const Eigen::Vector3d& p, const Eigen::Vector3d& v, double sigma_p, double accel_sigma, double dt)
      : accel_var_(accel_sigma * accel_sigma), dt_(dt) {
    now_.p = p;
    now_.v = v;
    for (auto& P : now_.P) P = Eigen::Matrix2d{{sigma_p * sigma_p, 0}, {0, 0.04}};
  }
  // One step: the state at t (before this step's accelerometer sample `a`
  // moves it to t + dt) is stored, then propagated.
  void predict(double t, const Eigen::Vector3d& a) {
    now_.t = t;
    now_.a = a;
    history_.push_back(now_);
    while (history_.size() > 2 && history_.front().t < t - 1.0) history_.pop_front();
    propagate(now_, a);
    now_.t = t + dt_;
  }
  void correct(double t_capture, const Eigen::Vector3d& z, double sigma) {
    // The stored state at the capture time (the newest at or before it).
    auto it = history_.end();
    while (it != history_.begin() && std::prev(it)->t > t_capture) --it;
    if (it == history_.begin()) {
      update(now_, z, sigma);  // older than the history: as if now
      return;
    }
    --it;
    Sample s = *it;
    if (!update(s, z, sigma)) return;
    // Replay the accelerometer samples from there on, rewriting the history.
    for (auto k = it; k != history_.end(); ++k) {
      const Eigen::Vector3d a = k->a;
      const double t = k->t;
      *k = s;
      k->a = a;
      k->t = t;
      propagate(s, a);
      s.t = t + dt_;
    }
    now_.p = s.p;
    now_.v = s.v;
    now_.P = s.P;
  }
  [[nodiscard]] const Eigen::Vector3d& p() const { return now_.p; }
  [[nodiscard]] const Eigen::Vector3d& v() const { return now_.v; }

 private:
  static constexpr double kGateSigma = 5;
  static constexpr int kMaxRefused = 5;
  struct Sample {
    double t = 0;
    Eigen::Vector3d a = Eigen::Vector3d::Zero();  // the accelerometer sample taken at t
    Eigen::Vector3d p = Eigen::Vector3d::Zero(), v = Eigen::Vector3d::Zero();
    std::array<Eigen::Matrix2d, 3> P{};
  };
  void propagate(Sample& s, const Eigen::Vector3d& a) const {
    const double dt = dt_;
    s.p += s.v * dt + 0.5 * a * dt * dt;
    s.v += a * dt;
    const Eigen::Matrix2d F{{1, dt}, {0, 1}};
    const Eigen::Vector2d G(0.5 * dt * dt, dt);
    for (auto& P : s.P)
      P = F * P * F.transpose() + G * G.transpose() * accel_var_ + Eigen::Matrix2d{{1e-9, 0}, {0, 1e-7}};
  }
  // The update of `s`; false when the gate refused it.
  bool update(Sample& s, const Eigen::Vector3d& z, double sigma) {
    const double r = std::max(sigma * sigma, 1e-8);
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
      const double innovation = z[i] - s.p[i];
      inside = inside && innovation * innovation <= kGateSigma * kGateSigma * (s.P[i](0, 0) + r);
    }
    if (!inside && ++refused_ < kMaxRefused) return false;
    if (!inside) {  // the filter lost it: restart at the measurement
      for (int i = 0; i < 3; ++i) s.P[i] = Eigen::Matrix2d{{r, 0}, {0, s.P[i](1, 1)}};
      s.p = z;
      refused_ = 0;
      return true;
    }
    refused_ = 0;
    for (int i = 0; i < 3; ++i) {
      Eigen::Matrix2d& P = s.P[i];
      const double innovation = z[i] - s.p[i];
      const double k_den = P(0, 0) + r;
      const Eigen::Vector2d k = P.col(0) / k_den;
      s.p[i] += k[0] * innovation;
      s.v[i] += k[1] * innovation;
      P -= k * P.row(0);
    }
    return true;
  }

  double accel_var_, dt_;
  Sample now_;
  std::deque<Sample> history_;
  int refused_ = 0;
};

// A message in flight over the link.
template <typename T>
struct InFlight {
  double arrives;
  T payload;
};

struct TimedSetpoint {
  double sent = 0;
  twin::Setpoint setpoint;
  bool motors_off = false;
};

struct PositionFix {
  double t_capture = 0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  double sigma = 0;
};

double nutation_between(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return std::acos(std::clamp((R_a.col(2)).dot(R_b.col(2)), -1.0, 1.0));
}

}  // namespace

Registry<PerceptionFactory>& perception_registry() {
  static Registry<PerceptionFactory>* registry = [] {
    auto* r = new Registry<PerceptionFactory>("mission perception");  // never destroyed: used until exit
    r->add("model", "the fitted model of led_pose: range-dependent noise, bias, latency, drop-outs, field of view",
           [](const MissionOptions& o, std::uint64_t seed) {
             return std::make_unique<PerceptionModel>(o.perception_options(), seed);
           });
    r->add("render", "renders the camera's frames and runs the LED tracker on them (slower)",
           [](const MissionOptions& o, std::uint64_t seed) {
             const PerceptionModelOptions model = o.perception_options();
             return std::make_unique<RenderPerception>(o.render, model.camera.T_pad_camera,
                                                       o.drone.airframe.centre_of_mass(), model.rate_hz, model.latency,
                                                       seed);
           });
    return r;
  }();
  return *registry;
}

std::unique_ptr<Perception> make_default_perception(const MissionOptions& o, std::uint64_t seed) {
  auto p = perception_registry().get(o.perception).factory(o, seed);
  if (!p) throw InvalidArgument("perception '" + o.perception + "': its factory returned no perception");
  return p;
}

PerceptionModelOptions MissionOptions::perception_options() const {
  PerceptionModelOptions o = perception_model;
  if (guidance.planner.corridor && guidance.planner.corridor->camera) o.camera = *guidance.planner.corridor->camera;
  return o;
}

bool MissionOptions::validate(std::string* why) const {
  if (!vehicle.validate(why) || !drone.validate(why) || !guidance.validate(why)) return false;
  std::string w;
  if (!machine.validate(&w)) return invalid(why, "state_machine." + w);
  if (!perception_options().validate(why)) return false;
  if (!perception_registry().find(perception)) {
    return invalid(why, "perception.mode: " + perception_registry().unknown(perception));
  }
  if (perception == "render" && !render.validate(why)) return false;
  if (!(pad.size.allFinite() && pad.size.minCoeff() > 0)) return invalid(why, "pad.size: must be positive [m]");
  if (!(pad.hold_force >= 0) || !std::isfinite(pad.hold_force)) return invalid(why, "pad.hold_force: must be >= 0 [N]");
  if (!(positive(pad.thickness))) return invalid(why, "pad.thickness: must be positive [m]");
  if (!wind.validate(why)) return false;
  if (!(link.latency >= 0 && link.latency <= 1)) return invalid(why, "link.latency: must be in [0, 1] s");
  if (!probability(link.dropout)) return invalid(why, "link.dropout: must be in [0, 1)");
  if (!positive(link.setpoint_timeout)) return invalid(why, "link.setpoint_timeout: must be positive [s]");
  if (!positive(fix.rate_hz)) return invalid(why, "fix.rate_hz: must be positive");
  if (!(fix.sigma >= 0) || !std::isfinite(fix.sigma)) return invalid(why, "fix.sigma: must be >= 0 [m]");
  if (!positive(fix.correlation_time)) return invalid(why, "fix.correlation_time: must be positive [s]");
  if (!drone_start.allFinite() || !(drone_start.z() > 1)) {
    return invalid(why, "drone.start: must be finite and above 1 m");
  }
  if (!(ground_rate_hz >= 10 && ground_rate_hz <= 1000)) return invalid(why, "ground_rate_hz: must be in [10, 1000]");
  if (!(imu_accel_sigma >= 0) || !std::isfinite(imu_accel_sigma)) {
    return invalid(why, "drone.imu_accel_sigma: must be >= 0 [m/s^2]");
  }
  if (!positive(timeout)) return invalid(why, "timeout: must be positive [s]");
  // The drone must be able to follow the vehicle: its speed (the pad's, plus
  // the rendezvous point's on the turn) within the planner's per-axis limit
  // and the controller's.
  const double turn = vehicle.path == VehiclePath::Line ? 0.0 : 1.0 / vehicle.radius;
  const double offset = std::max(machine.rendezvous_point.head<2>().norm(), guidance.tracking_point.head<2>().norm());
  const bool log = vehicle.path == VehiclePath::Log;
  const double top_speed =
      log ? vehicle.log->top_speed(offset)
          : (vehicle.speed + (vehicle.path == VehiclePath::Random ? 2 * vehicle.random_speed_sigma : 0)) *
                (1 + turn * offset);
  if (top_speed > guidance.planner.v_max * std::sqrt(2.0) || top_speed > drone.controller.xy_vel_max) {
    return invalid(why, std::string(log ? "vehicle.log" : "vehicle.speed") + ": the drone would need " +
                            std::to_string(top_speed) +
                            " m/s to follow, beyond guidance.planner.v_max per axis or the controller's xy_vel_max");
  }
  // The camera must see the points the drone waits at.
  const PerceptionModel camera(perception_options(), 0);
  if (!camera.visible(machine.rendezvous_point)) {
    return invalid(why, "state_machine.rendezvous_point: outside the camera's field of view or range");
  }
  if (!camera.visible(guidance.tracking_point)) {
    return invalid(why, "guidance.tracking_point: outside the camera's field of view or range");
  }
  return true;
}

namespace {

// One mission in flight: the loop of mission.hpp at the physics step, its
// parts one method each (camera frames, the fix, the ground station, the
// drone, the bookkeeping, the end).
class Flight {
 public:
  Flight(const MissionOptions& o, std::uint64_t seed, std::uint64_t run, bool record, const PerceptionFactory& make)
      : o_(o),
        record_(record),
        vehicle_(o.vehicle, Rng(seed, 8 * run).next()),
        perception_(make ? make(o, Rng(seed, 8 * run + 1).next())
                         : make_default_perception(o, Rng(seed, 8 * run + 1).next())),
        wind_(o.wind, Rng(seed, 8 * run + 2), Rng(seed, 8 * run + 6)),
        link_rng_(seed, 8 * run + 3),
        fix_rng_(seed, 8 * run + 4),
        imu_rng_(seed, 8 * run + 5),
        drone_(o.drone, o.pad),
        machine_(o.machine),
        landed_com_height_(o.drone.airframe.centre_of_mass().z() - o.drone.airframe.ground_z()),
        stance_(detail::stance_of(o.drone.airframe)),
        tilt_acceleration_(twin::kStandardGravity * std::tan(deg_to_rad(o.drone.controller.tilt_max_air_deg))),
        guidance_(o.guidance, landed_com_height_),
        dt_(o.drone.step),
        ground_every_(every(1.0 / o.ground_rate_hz)),
        frame_every_(every(1.0 / perception_->rate_hz())),
        fix_every_(every(1.0 / o.fix.rate_hz)),
        sample_every_(every(0.02)),
        estimator_(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1, 1, o.drone.step) {
    last_pad_v_ = vehicle_.pad_velocity();
    read_pad();
    pad_.acceleration = Eigen::Vector3d::Zero();
    pad_.yaw_acceleration = 0;
    drone_.set_pad(pad_.T_world_pad, pad_.velocity, vehicle_.pad_angular_velocity());
    Eigen::Isometry3d T_start = Eigen::Isometry3d::Identity();
    T_start.translation() = o.drone_start - o.drone.airframe.centre_of_mass();
    drone_.place(T_start, Eigen::Vector3d::Zero(), true);
    // Errors of the fix (Gauss–Markov per axis).
    fix_error_ = normal_vector3(fix_rng_) * o.fix.sigma;
    estimator_ = DroneEstimator(drone_.state().position + fix_error_, Eigen::Vector3d::Zero(),
                                std::max(o.fix.sigma, 0.05), std::max(o.imu_accel_sigma, 0.05), dt_);
    active_.setpoint.position = drone_.state().position;
    p_fix_pad_ = world_to_pad(pad_, {drone_.state().position + fix_error_, {}, {}}).p;
    res_.v_limit = o.guidance.planner.v_max;
    res_.a_limit = o.guidance.planner.a_max;
  }

  MissionResult fly() {
    const long max_steps = static_cast<long>(std::ceil(o_.timeout / dt_));
    // Motors off before the timeout: the verdict waits for the drone to
    // rest (at most 3 s), a landing is not a timeout for ending late.
    const long settle_steps = static_cast<long>(std::ceil(3.2 / dt_));
    long step = 0;
    for (; !done_ && (step < max_steps || (shutdown_time_ >= 0 && step < max_steps + settle_steps)); ++step) {
      this->step(step);
    }
    if (!done_) {
      res_.duration = static_cast<double>(step) * dt_;
      res_.message = "no landing within the timeout";
    }
    res_.landing_attempts = machine_.landing_attempts();
    res_.replan_median_ms = upper_median(replan_ms_);
    if (!pose_errors_.empty()) {
      res_.pose_error_max = *std::max_element(pose_errors_.begin(), pose_errors_.end());
      res_.pose_error_median = upper_median(std::move(pose_errors_));
    }
    return std::move(res_);
  }

 private:
  // Perception → ground station: a frame with the truth and the pad's pose
  // at its capture.
  struct Frame {
    PoseMeasurement m;
    Eigen::Vector3d truth;
    Eigen::Isometry3d T_world_pad;
  };

  [[nodiscard]] long every(double period) const { return std::max(1L, std::lround(period / o_.drone.step)); }

  // The pad's state from the vehicle's (its acceleration by differences).
  void read_pad() {
    pad_.T_world_pad = vehicle_.T_world_pad();
    pad_.velocity = vehicle_.pad_velocity();
    pad_.acceleration = (pad_.velocity - last_pad_v_) / dt_;
    pad_.yaw_acceleration = (vehicle_.state().yaw_rate - pad_.yaw_rate) / dt_;
    pad_.yaw_rate = vehicle_.state().yaw_rate;
  }

  void end(MissionOutcome outcome, const std::string& message, double t) {
    res_.outcome = outcome;
    res_.message = message;
    res_.duration = t;
    done_ = true;
  }

  void step(long step) {
    const double t = static_cast<double>(step) * dt_;
    truth_ = drone_.state();
    if (!truth_.position.allFinite() || !truth_.velocity.allFinite() || truth_.velocity.norm() > 50) {
      end(MissionOutcome::Crashed, "unstable: non-finite or runaway state", t);
      return;
    }
    rel_truth_ = world_to_pad(pad_, {truth_.position, truth_.velocity, truth_.acceleration});
    if (step % frame_every_ == 0) capture(t);
    if (step % fix_every_ == 0) update_fix(t);
    if (step % ground_every_ == 0 && !ground_station(t)) return;
    const twin::Setpoint flown = fly_drone(t);
    keep_books(t, step, flown);
    check_end(t);
  }

  // The camera's frame.
  void capture(double t) {
    PerceptionTruth pt;
    pt.t = t;
    pt.T_pad_body = pad_.T_world_pad.inverse() * drone_.T_world_body();
    pt.p_pad_com = rel_truth_.p;
    // The drone's attitude telemetry (its IMU's gravity direction) reaches
    // the ground station over the link: the one from link.latency ago.
    attitude_.emplace_back(t, truth_.R_world_body.transpose() * -Eigen::Vector3d::UnitZ());
    while (attitude_.size() > 1 && attitude_[1].first <= t - o_.link.latency) attitude_.pop_front();
    pt.g_body = attitude_.front().second;
    pt.state = state_;
    frames_.push_back({perception_->capture(pt), rel_truth_.p, pad_.T_world_pad});
  }

  // The external fix (its error wanders as a Gauss–Markov process), sent
  // to the drone before the tracker locks.
  void update_fix(double t) {
    const double fdt = static_cast<double>(fix_every_) * dt_;
    const double a = std::exp(-fdt / o_.fix.correlation_time), b = std::sqrt(1 - a * a);
    for (int i = 0; i < 3; ++i) fix_error_[i] = a * fix_error_[i] + b * o_.fix.sigma * fix_rng_.normal();
    p_fix_pad_ = rel_truth_.p + fix_error_;
    if ((state_ == MissionState::Searching || state_ == MissionState::Rendezvous) &&
        link_rng_.uniform() >= o_.link.dropout) {
      to_drone_fixes_.push_back(
          {t + o_.link.latency, {t, pad_.T_world_pad * p_fix_pad_, std::max(o_.fix.sigma, 0.01)}});
    }
  }

  // The pose frames that arrived: counted, their errors kept, sent on to
  // the drone. Sets the state machine's pose inputs.
  void receive_frames(double t, StateMachineInputs& in) {
    while (!frames_.empty() && frames_.front().m.t_available <= t) {
      const auto [m, at_capture, T_pad_then] = frames_.front();
      frames_.pop_front();
      in.new_pose = true;
      in.pose_ok = in.pose_ok || m.ok;
      const bool counted = state_ == MissionState::Tracking || state_ == MissionState::Landing;
      res_.pose_frames += counted ? 1 : 0;
      if (!m.ok) continue;
      last_pose_error_ = (m.p_pad - at_capture).norm();
      pose_errors_.push_back(last_pose_error_);
      if (record_) res_.poses.push_back({m.t_capture, at_capture, m.p_pad});
      res_.pose_ok += counted ? 1 : 0;
      if (link_rng_.uniform() >= o_.link.dropout && state_ != MissionState::Searching) {
        to_drone_fixes_.push_back({t + o_.link.latency, {m.t_capture, T_pad_then * m.p_pad, m.sigma}});
      }
    }
  }

  // The ground station: state machine, guidance, a setpoint over the link.
  // False when the mission ends here (the machine gave up).
  bool ground_station(double t) {
    StateMachineInputs in;
    in.t = t;
    in.p_fix = p_fix_pad_;
    receive_frames(t, in);
    // The drone's acceleration is not estimated: relative to the pad it is
    // taken as what the guidance asks of it (zero while it holds a point),
    // not as a world-frame zero, which in a turning frame reads as the
    // pad's centripetal acceleration backwards and started every landing's
    // first plan swinging outward (0.4 m sideways at 4 m/s on the 8 m circle).
    plan::KinematicState est = world_to_pad(pad_, {estimator_.p(), estimator_.v(), Eigen::Vector3d::Zero()});
    est.a = guide_.reference.a;
    in.p_estimate = est.p;
    in.v_estimate = est.v;
    // The lowest foot above the pad, from the estimate and the attitude (the
    // IMU's): a drone leaning into the airflow touches with a leading foot
    // while its centre of mass is still well above its landed height.
    const Eigen::Matrix3d R_pad_body = pad_.T_world_pad.linear().transpose() * truth_.R_world_body;
    in.height = est.p.z() + detail::lowest_support(stance_, R_pad_body);
    in.tracking_error = (guide_.reference.p - est.p).norm();
    in.replan = guide_.replan;
    in.have_plan = guide_.have_plan;
    in.commanded_descent = -guide_.reference.v.z();
    in.vehicle_acceleration = pad_.acceleration.head<2>().norm();
    in.vehicle_yaw_rate = vehicle_.state().yaw_rate;
    in.tracking_point = o_.guidance.tracking_point;
    // What would upset the drone on the pad: the drag of the (estimated)
    // wind relative to the pad and the pad's own acceleration, against what
    // holds the landed, unpowered drone (friction, its stance) and against
    // the tilt that would put a propeller on the pad while it flies down
    // holding station (stance.hpp).
    // The wind is its 2 s mean and, as a margin, a gust of twice the
    // estimate's spread about that mean along the air's direction.
    const double k = std::min(1.0, 1.0 / (2.0 * o_.ground_rate_hz));
    wind_mean_ += k * (observer_.wind() - wind_mean_);
    gust_variance_ += k * ((observer_.wind() - wind_mean_).head<2>().squaredNorm() - gust_variance_);
    const Eigen::Vector3d air = pad_.velocity - wind_mean_;
    const double gust = 2 * std::sqrt(gust_variance_);
    const double pad_push = mass_ * pad_.acceleration.head<2>().norm();
    // Landed, it rides the vehicle on: a vehicle that turns meets the wind
    // from every side, so the air it must stand is the vehicle's speed plus
    // the wind's (and the gust), whatever their directions now.
    const double worst_air = pad_.velocity.head<2>().norm() + wind_mean_.head<2>().norm() + gust;
    const double side_landed = observer_.drag(Eigen::Vector3d(worst_air, 0, 0)).norm() + pad_push;
    in.slide_ratio = detail::upset_ratio(stance_, side_landed, mass_, o_.drone.pad_friction, o_.pad.hold_force);
    // Where to put the drone down: it flies tilted to hold station over the
    // pad (its thrust's horizontal part m a_pad − D(air)), touches with its
    // leading feet and levels about them, its centre of mass moving back by
    // d (1 − cos θ) + h sin θ (stance.hpp): aim that far ahead (low-passed).
    const Eigen::Vector3d drag_now = observer_.drag(air);
    const Eigen::Vector3d lean = mass_ * pad_.acceleration - drag_now;
    const Eigen::Vector2d lean_pad = (pad_.T_world_pad.linear().transpose() * lean).head<2>();
    const double tilt = std::atan2(lean_pad.norm(), mass_ * twin::kStandardGravity);
    const Eigen::Vector2d aim = lean_pad.norm() > 1e-9
                                    ? Eigen::Vector2d(lean_pad.normalized() * detail::levelling_shift(stance_, tilt))
                                    : Eigen::Vector2d::Zero();
    touchdown_point_ += std::min(1.0, 1.0 / (0.5 * o_.ground_rate_hz)) * (aim - touchdown_point_);
    in.touchdown_point = touchdown_point_;
    guidance_.set_touchdown_point(touchdown_point_);
    // The wind in the guidance's prediction: what the airframe's tilt limit
    // leaves beyond the estimated wind's drag at the pad's speed.
    guidance_.set_acceleration_capacity(tilt_acceleration_ - drag_now.head<2>().norm() / mass_);
    if (state_ == MissionState::Tracking) in.tracking_error = (o_.guidance.tracking_point - est.p).norm();
    const StateMachineOutput sm = machine_.step(in);
    if (sm.transitioned) res_.transitions.push_back(sm.transition);
    state_ = sm.state;
    if (sm.gave_up) {
      const bool from_tracking = sm.transitioned && sm.transition.from == MissionState::Tracking;
      end(MissionOutcome::Aborted,
          from_tracking ? "never cleared to land in tracking within state_machine.max_tracking_time (most often: " +
                              std::string(to_string(sm.transition.reason)) + ")"
                        : "gave up after " + std::to_string(machine_.landing_attempts()) + " aborted landings",
          t);
      return false;
    }
    guide_ = guidance_.update(t, state_, sm.transitioned, pad_, est, p_fix_pad_, o_.machine);
    if (guide_.replan != ReplanOutcome::None) {
      ++res_.replans;
      res_.replan_failures += guide_.replan == ReplanOutcome::Failed ? 1 : 0;
      replan_ms_.push_back(guide_.replan_ms);
    }
    if (sm.motors_off && shutdown_time_ < 0) shutdown_time_ = t;
    if (link_rng_.uniform() >= o_.link.dropout) {
      to_drone_setpoints_.push_back({t + o_.link.latency, {t, guide_.setpoint, sm.motors_off}});
    }
    return true;
  }

  // The drone: what reached it over the link, its estimator, its
  // controller, the wind, one physics step (with the vehicle's). The
  // setpoint it flew.
  twin::Setpoint fly_drone(double t) {
    while (!to_drone_setpoints_.empty() && to_drone_setpoints_.front().arrives <= t) {
      active_ = to_drone_setpoints_.front().payload;
      to_drone_setpoints_.pop_front();
      received_setpoint_ = true;
      if (active_.motors_off) armed_ = false;
    }
    while (!to_drone_fixes_.empty() && to_drone_fixes_.front().arrives <= t) {
      const PositionFix& f = to_drone_fixes_.front().payload;
      estimator_.correct(f.t_capture, f.p_world, f.sigma);
      to_drone_fixes_.pop_front();
    }
    twin::Setpoint flown = active_.setpoint;
    if (received_setpoint_) {
      // Timestamped setpoints, extrapolated to now (up to the timeout; then
      // hold where the extrapolation ended).
      const double age = std::min(t - active_.sent, o_.link.setpoint_timeout);
      if (flown.position.allFinite()) flown.position += flown.velocity * age + 0.5 * flown.acceleration * age * age;
      flown.velocity += flown.acceleration * age;
      if (t - active_.sent > o_.link.setpoint_timeout) {
        flown.velocity.setZero();
        flown.acceleration.setZero();
      }
    }
    const Eigen::Vector3d wind = wind_.step(t, dt_, truth_.position.z(), truth_.velocity);
    wind_now_ = wind;
    const Eigen::Vector3d accel = truth_.acceleration + o_.imu_accel_sigma * normal_vector3(imu_rng_);
    estimator_.predict(t, accel);
    // The wind (wind.hpp): estimated in free flight from the last step's
    // acceleration and thrust, its drag flown as acceleration feed-forward.
    twin::Setpoint commanded = flown;
    if (o_.drone.wind_observer_time > 0) {
      if (armed_ && thrust_axis_known_ && drone_.contacts().contacts == 0) {
        observer_.update(dt_, accel, thrust_axis_ * drone_.motor_thrusts().sum() / mass_, estimator_.v());
      }
      thrust_axis_ = truth_.R_world_body.col(2);
      thrust_axis_known_ = true;
      if (!o_.drone.drag_feed_forward) commanded.acceleration += observer_.feed_forward(estimator_.v());
    }
    if (o_.drone.drag_feed_forward) commanded.acceleration -= observer_.drag(flown.velocity - observer_.wind()) / mass_;
    if (o_.drone.turn_feed_forward) {
      // The velocity loop's derivative acts on the measured acceleration,
      // low-passed at MPC_VELD_LP: the setpoint's own acceleration through
      // the same low-pass, times its gain, is added back, so the derivative
      // damps the acceleration error, not the acceleration the setpoint asks.
      setpoint_accel_lp_ += setpoint_accel_gain_ * (flown.acceleration.head<2>() - setpoint_accel_lp_);
      commanded.acceleration.head<2>() += o_.drone.controller.xy_vel_d * setpoint_accel_lp_;
    }
    vehicle_.step(dt_);
    last_pad_v_ = pad_.velocity;
    read_pad();
    drone_.set_pad(pad_.T_world_pad, pad_.velocity, vehicle_.pad_angular_velocity());
    drone_.step(commanded, estimator_.p(), estimator_.v(), armed_, wind);
    return flown;
  }

  void keep_books(double t, long step, const twin::Setpoint& flown) {
    res_.time_in_state[static_cast<std::size_t>(state_)] += dt_;
    // Tracking error: the guidance's reference (pad frame, without the
    // pad-frame integral's offset) against where the drone is.
    const double tracking_error = (guide_.reference.p - rel_truth_.p).norm();
    if (state_ == MissionState::Landing && !touched_) {
      res_.max_tracking_error = std::max(res_.max_tracking_error, tracking_error);
      res_.max_axis_speed = std::max(res_.max_axis_speed, truth_.velocity.cwiseAbs().maxCoeff());
      res_.max_axis_acceleration = std::max(res_.max_axis_acceleration, truth_.acceleration.cwiseAbs().maxCoeff());
    }
    if (!record_ || step % sample_every_ != 0) return;
    MissionSample s;
    s.t = t;
    s.state = state_;
    s.drone = truth_.position;
    s.drone_v = truth_.velocity;
    s.estimate = estimator_.p();
    s.estimate_v = estimator_.v();
    s.setpoint = flown.position;
    s.setpoint_v = flown.velocity;
    s.pad = pad_.T_world_pad.translation();
    s.pad_v = pad_.velocity;
    s.pad_yaw = std::atan2(pad_.T_world_pad.linear()(1, 0), pad_.T_world_pad.linear()(0, 0));
    s.relative = rel_truth_.p;
    s.pose_error = last_pose_error_;
    s.tracking_error = tracking_error;
    s.tilt = std::acos(std::clamp(truth_.R_world_body(2, 2), -1.0, 1.0));
    s.thrust = drone_.motor_thrusts().sum();
    s.wind = wind_now_;
    s.wind_estimate = observer_.wind();
    res_.trace.push_back(s);
  }

  // Contacts and the end of the mission: a crash as soon as it happens;
  // after shutdown, the verdict once the drone rests on the pad (or 3 s on).
  void check_end(double t) {
    const ContactState& c = drone_.contacts();
    if (c.on_ground) return end(MissionOutcome::Crashed, "touched the ground", t);
    if (c.strike_on_pad) return end(MissionOutcome::Crashed, "struck the pad with a propeller, an arm or the body", t);
    const DroneState now = drone_.state();
    if (c.support_on_pad && !touched_) {
      touched_ = true;
      res_.touchdown_velocity = world_to_pad(pad_, {now.position, now.velocity, {}}).v;
    }
    if (armed_) return;
    const Eigen::Vector3d rel_v = world_to_pad(pad_, {now.position, now.velocity, {}}).v;
    rest_timer_ = rel_v.norm() < 0.05 ? rest_timer_ + dt_ : 0;
    const bool settled = rest_timer_ >= 0.3;
    if (!settled && t - shutdown_time_ <= 3.0) return;
    const Eigen::Isometry3d T = pad_.T_world_pad.inverse() * drone_.T_world_body();
    const Eigen::Vector2d half = 0.5 * o_.pad.size;
    const bool inside = std::abs(T.translation().x()) <= half.x() && std::abs(T.translation().y()) <= half.y();
    const double tilt = nutation_between(pad_.T_world_pad.linear(), drone_.T_world_body().linear());
    res_.touchdown_error = T.translation().head<2>().norm();
    if (!settled) return end(MissionOutcome::Crashed, "still moving on the pad 3 s after shutdown", t);
    if (!c.support_on_pad) return end(MissionOutcome::Crashed, "came to rest without its feet on the pad", t);
    if (!inside) return end(MissionOutcome::Crashed, "came to rest off the pad's area", t);
    if (tilt > 0.35) return end(MissionOutcome::Crashed, "tipped over on the pad", t);
    end(MissionOutcome::Landed, "", t);
  }

  const MissionOptions& o_;
  const bool record_;
  MissionResult res_;
  GroundVehicle vehicle_;
  std::unique_ptr<Perception> perception_;
  WindModel wind_;
  double mass_ = o_.drone.airframe.total_mass();
  WindObserver observer_{o_.drone.wind_observer_time, mass_, o_.drone.drag_linear, o_.drone.drag_quadratic};
  Eigen::Vector3d thrust_axis_ = Eigen::Vector3d::UnitZ();  // body z over the last step
  bool thrust_axis_known_ = false;
  Rng link_rng_, fix_rng_, imu_rng_;
  DroneSimulation drone_;
  StateMachine machine_;
  const double landed_com_height_;
  const detail::Stance stance_;     ///< how the landed drone stands (the upset guard)
  const double tilt_acceleration_;  ///< g tan(tilt_max_air): the horizontal acceleration the tilt limit allows
  Eigen::Vector2d touchdown_point_ = Eigen::Vector2d::Zero();  ///< pad frame
  Eigen::Vector3d wind_mean_ = Eigen::Vector3d::Zero();        ///< the wind estimate's 2 s mean (world)
  double gust_variance_ = 0;                                   ///< of the estimate about it, horizontal [m²/s²]
  Guidance guidance_;
  const double dt_;
  const long ground_every_, frame_every_, fix_every_, sample_every_;
  DroneEstimator estimator_;
  PadState pad_;
  Eigen::Vector3d last_pad_v_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d setpoint_accel_lp_ = Eigen::Vector2d::Zero();  ///< drone.turn_feed_forward's low-pass
  /// Its gain per step: the controller's derivative low-pass (flight_control.cpp).
  const double setpoint_accel_gain_ =
      1.0 - std::exp(-2.0 * std::numbers::pi * o_.drone.controller.vel_deriv_lp_hz * o_.drone.step);
  Eigen::Vector3d fix_error_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_fix_pad_ = Eigen::Vector3d::Zero();
  DroneState truth_;
  plan::KinematicState rel_truth_;
  std::deque<Frame> frames_;
  std::deque<std::pair<double, Eigen::Vector3d>> attitude_;  // the drone's gravity direction, by time
  std::deque<InFlight<PositionFix>> to_drone_fixes_;
  std::deque<InFlight<TimedSetpoint>> to_drone_setpoints_;
  TimedSetpoint active_;  // what the drone flies
  bool armed_ = true, received_setpoint_ = false, touched_ = false, done_ = false;
  GuidanceOutput guide_;
  MissionState state_ = MissionState::Searching;
  std::vector<double> replan_ms_, pose_errors_;
  double last_pose_error_ = -1, rest_timer_ = 0, shutdown_time_ = -1;
  Eigen::Vector3d wind_now_ = Eigen::Vector3d::Zero();  ///< the wind at the drone in the last step (the trace's)
};

}  // namespace

MissionResult run_mission(const MissionOptions& options, std::uint64_t seed, std::uint64_t run, bool record,
                          const PerceptionFactory& make_perception) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  return Flight(options, seed, run, record, make_perception).fly();
}

std::vector<MissionResult> run_missions(const MissionOptions& options, int runs, std::uint64_t seed, int threads,
                                        const PerceptionFactory& perception, const ProgressCallback& progress) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (runs < 1) throw InvalidArgument("runs: must be >= 1");
  std::vector<MissionResult> results(static_cast<std::size_t>(runs));
  BatchOptions batch;
  batch.threads = threads;
  batch.progress = progress;
  run_batch(results.size(), batch, [&](std::size_t i, std::size_t) {
    results[i] = run_mission(options, seed, static_cast<std::uint64_t>(i), false, perception);
  });
  return results;
}

namespace {

// The guards that abort (a landing, a lock) rather than advance.
bool is_abort(TransitionReason r) {
  switch (r) {
    case TransitionReason::RendezvousTimeout:
    case TransitionReason::PoseLost:
    case TransitionReason::PlanInfeasible:
    case TransitionReason::VehicleAccelerating:
    case TransitionReason::VehicleTurning:
    case TransitionReason::LowWithoutPlan:
    case TransitionReason::LowOffCentre:
    case TransitionReason::WindTooStrong:
    case TransitionReason::NotStable:
      return true;
    default:
      return false;
  }
}

}  // namespace

std::string failure_reason(const MissionResult& r) {
  switch (r.outcome) {
    case MissionOutcome::Landed:
      return "";
    case MissionOutcome::Crashed:
      return r.message.empty() ? std::string("crashed") : "crashed: " + r.message;
    case MissionOutcome::Aborted: {
      for (auto it = r.transitions.rbegin(); it != r.transitions.rend(); ++it) {
        if (is_abort(it->reason)) return "gave up: " + std::string(to_string(it->reason));
      }
      return "gave up";
    }
    case MissionOutcome::Timeout:
      break;
  }
  if (r.transitions.empty()) return "timeout in " + std::string(to_string(MissionState::Searching));
  const Transition& last = r.transitions.back();
  std::string out = "timeout in " + std::string(to_string(last.to));
  if (is_abort(last.reason)) out += " after " + std::string(to_string(last.reason));
  return out;
}

namespace {

FailureCounts most_frequent_first(const std::map<std::string, int>& counts) {
  FailureCounts out(counts.begin(), counts.end());
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  return out;
}

}  // namespace

FailureCounts count_failure_reasons(const std::vector<MissionResult>& results) {
  std::map<std::string, int> counts;
  for (const MissionResult& r : results) {
    if (!r.landed()) ++counts[failure_reason(r)];
  }
  return most_frequent_first(counts);
}

FailureCounts merge_failure_reasons(const FailureCounts& a, const FailureCounts& b) {
  std::map<std::string, int> counts;
  for (const auto* list : {&a, &b}) {
    for (const auto& [why, n] : *list) counts[why] += n;
  }
  return most_frequent_first(counts);
}

}  // namespace touchdown::mission
