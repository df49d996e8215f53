// One landing mission, closed loop (mission.hpp).
#include "touchdown/mission/mission.hpp"

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <mutex>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

namespace touchdown::mission {
namespace {

bool positive(double x) { return x > 0 && std::isfinite(x); }
bool probability(double x) { return x >= 0 && x < 1; }

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

double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double nutation_between(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return std::acos(std::clamp((R_a.col(2)).dot(R_b.col(2)), -1.0, 1.0));
}

}  // namespace

std::unique_ptr<Perception> make_default_perception(const MissionOptions& o, std::uint64_t seed) {
  const PerceptionModelOptions model = o.perception_options();
  if (o.perception == PerceptionMode::Model) return std::make_unique<PerceptionModel>(model, seed);
  return std::make_unique<RenderPerception>(o.render, model.camera.T_pad_camera, o.drone.airframe.centre_of_mass(),
                                            model.rate_hz, model.latency, seed);
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
  if (perception == PerceptionMode::Render && !render.validate(why)) return false;
  if (!(pad.size.allFinite() && pad.size.minCoeff() > 0)) return invalid(why, "pad.size: must be positive [m]");
  if (!(positive(pad.thickness))) return invalid(why, "pad.thickness: must be positive [m]");
  if (!wind.mean.allFinite()) return invalid(why, "wind.mean: must be finite [m/s]");
  if (!(wind.gust_sigma >= 0) || !std::isfinite(wind.gust_sigma)) return invalid(why, "wind.gust_sigma: must be >= 0");
  if (!positive(wind.gust_time)) return invalid(why, "wind.gust_time: must be positive [s]");
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
  const double top_speed =
      (vehicle.speed + (vehicle.path == VehiclePath::Random ? 2 * vehicle.random_speed_sigma : 0)) *
      (1 + turn * offset);
  if (top_speed > guidance.planner.v_max * std::sqrt(2.0) || top_speed > drone.controller.xy_vel_max) {
    return invalid(why, "vehicle.speed: the drone would need " + std::to_string(top_speed) +
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

MissionResult run_mission(const MissionOptions& options, std::uint64_t seed, std::uint64_t run, bool record,
                          const PerceptionFactory& make_perception) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  const MissionOptions& o = options;
  MissionResult res;
  // One random stream per purpose, from (seed, run).
  const std::uint64_t stream = 8 * run;
  GroundVehicle vehicle(o.vehicle, Rng(seed, stream).next());
  std::unique_ptr<Perception> perception = make_perception ? make_perception(o, Rng(seed, stream + 1).next())
                                                           : make_default_perception(o, Rng(seed, stream + 1).next());
  Rng wind_rng(seed, stream + 2), link_rng(seed, stream + 3), fix_rng(seed, stream + 4), imu_rng(seed, stream + 5);
  DroneSimulation drone(o.drone, o.pad);
  StateMachine machine(o.machine);
  const twin::Airframe& af = o.drone.airframe;
  const double landed_com_height = af.centre_of_mass().z() - af.ground_z();
  Guidance guidance(o.guidance, landed_com_height);
  const double dt = o.drone.step;
  const long ground_every = std::max(1L, std::lround(1.0 / (o.ground_rate_hz * dt)));
  const long frame_every = std::max(1L, std::lround(1.0 / (perception->rate_hz() * dt)));
  const long fix_every = std::max(1L, std::lround(1.0 / (o.fix.rate_hz * dt)));
  const long sample_every = std::max(1L, std::lround(0.02 / dt));
  const long max_steps = static_cast<long>(std::ceil(o.timeout / dt));

  // The pad's state from the vehicle's (its acceleration by differences).
  PadState pad;
  Eigen::Vector3d last_pad_v = vehicle.pad_velocity();
  auto read_pad = [&]() {
    pad.T_world_pad = vehicle.T_world_pad();
    pad.velocity = vehicle.pad_velocity();
    pad.acceleration = (pad.velocity - last_pad_v) / dt;
    pad.yaw_rate = vehicle.state().yaw_rate;
  };
  read_pad();
  pad.acceleration = Eigen::Vector3d::Zero();
  drone.set_pad(pad.T_world_pad, pad.velocity, vehicle.pad_angular_velocity());
  Eigen::Isometry3d T_start = Eigen::Isometry3d::Identity();
  T_start.translation() = o.drone_start - af.centre_of_mass();
  drone.place(T_start, Eigen::Vector3d::Zero(), true);
  // Errors of the fix (Gauss–Markov per axis) and the wind's gusts.
  Eigen::Vector3d fix_error(fix_rng.normal(), fix_rng.normal(), fix_rng.normal());
  fix_error *= o.fix.sigma;
  Eigen::Vector3d gust(wind_rng.normal(), wind_rng.normal(), 0.5 * wind_rng.normal());
  gust *= o.wind.gust_sigma;
  DroneEstimator estimator(drone.state().p + fix_error, Eigen::Vector3d::Zero(), std::max(o.fix.sigma, 0.05),
                           std::max(o.imu_accel_sigma, 0.05), dt);

  // Perception → ground station: each frame with the truth and the pad's pose at its capture.
  struct Frame {
    PoseMeasurement m;
    Eigen::Vector3d truth;
    Eigen::Isometry3d T_world_pad;
  };
  std::deque<Frame> frames;
  std::deque<InFlight<PositionFix>> to_drone_fixes;  // ground station → drone
  std::deque<InFlight<TimedSetpoint>> to_drone_setpoints;
  TimedSetpoint active;  // what the drone flies
  active.setpoint.position = drone.state().p;
  bool armed = true, received_setpoint = false;
  Eigen::Vector3d p_fix_pad = world_to_pad(pad, {drone.state().p + fix_error, {}, {}}).p;
  GuidanceOutput guide;
  bool entered = true;
  MissionState state = MissionState::Searching;
  std::vector<double> replan_ms, pose_errors;
  double last_pose_error = -1;
  bool touched = false;
  double rest_timer = 0, shutdown_time = -1;
  const auto& planner = o.guidance.planner;
  res.v_limit = planner.v_max;
  res.a_limit = planner.a_max;

  auto crash = [&](const std::string& message, double t) {
    res.outcome = MissionOutcome::Crashed;
    res.message = message;
    res.duration = t;
  };

  long step = 0;
  bool done = false;
  for (; step < max_steps && !done; ++step) {
    const double t = static_cast<double>(step) * dt;
    const DroneState truth = drone.state();
    if (!truth.p.allFinite() || !truth.v.allFinite() || truth.v.norm() > 50) {
      crash("unstable: non-finite or runaway state", t);
      break;
    }
    plan::KinematicState truth_world{truth.p, truth.v, truth.a};
    const plan::KinematicState rel_truth = world_to_pad(pad, truth_world);
    const Eigen::Isometry3d T_pad_body = pad.T_world_pad.inverse() * drone.T_world_body();

    // The camera's frames.
    if (step % frame_every == 0) {
      PerceptionTruth pt;
      pt.t = t;
      pt.T_pad_body = T_pad_body;
      pt.p_pad_com = rel_truth.p;
      pt.g_body = truth.R.transpose() * -Eigen::Vector3d::UnitZ();
      pt.state = state;
      frames.push_back({perception->capture(pt), rel_truth.p, pad.T_world_pad});
    }
    // The external fix (its error wanders as a Gauss–Markov process).
    if (step % fix_every == 0) {
      const double fdt = static_cast<double>(fix_every) * dt;
      const double a = std::exp(-fdt / o.fix.correlation_time), b = std::sqrt(1 - a * a);
      for (int i = 0; i < 3; ++i) fix_error[i] = a * fix_error[i] + b * o.fix.sigma * fix_rng.normal();
      p_fix_pad = rel_truth.p + fix_error;
      if (state == MissionState::Searching || state == MissionState::Rendezvous) {
        if (link_rng.uniform() >= o.link.dropout) {
          to_drone_fixes.push_back({t + o.link.latency, {t, pad.T_world_pad * p_fix_pad, std::max(o.fix.sigma, 0.01)}});
        }
      }
    }

    // The ground station.
    if (step % ground_every == 0) {
      StateMachineInputs in;
      in.t = t;
      in.p_fix = p_fix_pad;
      while (!frames.empty() && frames.front().m.t_available <= t) {
        const auto [m, at_capture, T_pad_then] = frames.front();
        frames.pop_front();
        in.new_pose = true;
        in.pose_ok = in.pose_ok || m.ok;
        const bool counted = state == MissionState::Tracking || state == MissionState::Landing;
        res.pose_frames += counted ? 1 : 0;
        if (m.ok) {
          last_pose_error = (m.p_pad - at_capture).norm();
          pose_errors.push_back(last_pose_error);
          res.pose_ok += counted ? 1 : 0;
          if (link_rng.uniform() >= o.link.dropout && state != MissionState::Searching) {
            to_drone_fixes.push_back({t + o.link.latency, {m.t_capture, T_pad_then * m.p_pad, m.sigma}});
          }
        }
      }
      const plan::KinematicState est_rel = world_to_pad(pad, {estimator.p(), estimator.v(), Eigen::Vector3d::Zero()});
      in.p_estimate = est_rel.p;
      in.v_estimate = est_rel.v;
      in.height = est_rel.p.z() - landed_com_height;
      in.tracking_error = (guide.reference.p - est_rel.p).norm();
      in.replan = guide.replan;
      in.have_plan = guide.have_plan;
      in.vehicle_acceleration = pad.acceleration.head<2>().norm();
      in.vehicle_yaw_rate = vehicle.state().yaw_rate;
      in.tracking_point = o.guidance.tracking_point;
      if (state == MissionState::Tracking) in.tracking_error = (o.guidance.tracking_point - est_rel.p).norm();
      const StateMachineOutput sm = machine.step(in);
      if (sm.transitioned) res.transitions.push_back(sm.transition);
      entered = sm.transitioned;
      state = sm.state;
      if (sm.gave_up) {
        res.outcome = MissionOutcome::Aborted;
        res.message = "gave up after " + std::to_string(machine.landing_attempts()) + " aborted landings";
        res.duration = t;
        break;
      }
      guide = guidance.update(t, state, entered, pad, est_rel, p_fix_pad, o.machine);
      if (guide.replan != ReplanOutcome::None) {
        ++res.replans;
        res.replan_failures += guide.replan == ReplanOutcome::Failed ? 1 : 0;
        replan_ms.push_back(guide.replan_ms);
      }
      TimedSetpoint msg{t, guide.setpoint, sm.motors_off};
      if (sm.motors_off && shutdown_time < 0) shutdown_time = t;
      if (link_rng.uniform() >= o.link.dropout) to_drone_setpoints.push_back({t + o.link.latency, msg});
    }

    // The drone: what reached it, its estimator, its controller.
    while (!to_drone_setpoints.empty() && to_drone_setpoints.front().arrives <= t) {
      active = to_drone_setpoints.front().payload;
      to_drone_setpoints.pop_front();
      received_setpoint = true;
      if (active.motors_off) armed = false;
    }
    while (!to_drone_fixes.empty() && to_drone_fixes.front().arrives <= t) {
      const PositionFix& f = to_drone_fixes.front().payload;
      estimator.correct(f.t_capture, f.p_world, f.sigma);
      to_drone_fixes.pop_front();
    }
    twin::Setpoint flown = active.setpoint;
    if (received_setpoint) {
      // Timestamped setpoints, extrapolated to now (up to the timeout; then
      // hold where the extrapolation ended).
      const double age = std::min(t - active.sent, o.link.setpoint_timeout);
      if (flown.position.allFinite()) {
        flown.position += flown.velocity * age + 0.5 * flown.acceleration * age * age;
      }
      flown.velocity += flown.acceleration * age;
      if (t - active.sent > o.link.setpoint_timeout) {
        flown.velocity.setZero();
        flown.acceleration.setZero();
      }
    }
    // Wind: the mean plus gusts.
    const double ga = std::exp(-dt / o.wind.gust_time), gb = std::sqrt(1 - ga * ga);
    for (int i = 0; i < 3; ++i) {
      gust[i] = ga * gust[i] + gb * o.wind.gust_sigma * (i == 2 ? 0.5 : 1.0) * wind_rng.normal();
    }
    const Eigen::Vector3d accel_measured =
        truth.a + o.imu_accel_sigma * Eigen::Vector3d(imu_rng.normal(), imu_rng.normal(), imu_rng.normal());
    estimator.predict(t, accel_measured);
    vehicle.step(dt);
    last_pad_v = pad.velocity;
    read_pad();
    drone.set_pad(pad.T_world_pad, pad.velocity, vehicle.pad_angular_velocity());
    drone.step(flown, estimator.p(), estimator.v(), armed, o.wind.mean + gust);

    // Bookkeeping.
    res.time_in_state[static_cast<std::size_t>(state)] += dt;
    // Tracking error: the guidance's reference (pad frame, without the
    // pad-frame integral's offset) against where the drone is.
    const double tracking_error = (guide.reference.p - rel_truth.p).norm();
    if (state == MissionState::Landing && !touched) {
      res.max_tracking_error = std::max(res.max_tracking_error, tracking_error);
      res.max_axis_speed = std::max(res.max_axis_speed, truth.v.cwiseAbs().maxCoeff());
      res.max_axis_acceleration = std::max(res.max_axis_acceleration, truth.a.cwiseAbs().maxCoeff());
    }
    if (record && step % sample_every == 0) {
      MissionSample s;
      s.t = t;
      s.state = state;
      s.drone = truth.p;
      s.drone_v = truth.v;
      s.estimate = estimator.p();
      s.estimate_v = estimator.v();
      s.setpoint = flown.position;
      s.setpoint_v = flown.velocity;
      s.pad = pad.T_world_pad.translation();
      s.pad_v = pad.velocity;
      s.pad_yaw = std::atan2(pad.T_world_pad.linear()(1, 0), pad.T_world_pad.linear()(0, 0));
      s.relative = rel_truth.p;
      s.pose_error = last_pose_error;
      s.tracking_error = tracking_error;
      res.trace.push_back(s);
    }

    // Contacts and the end of the mission.
    const ContactState& c = drone.contacts();
    if (c.on_ground) {
      crash("touched the ground", t);
      break;
    }
    if (c.strike_on_pad) {
      crash("struck the pad with a propeller, an arm or the body", t);
      break;
    }
    if (c.support_on_pad && !touched) {
      touched = true;
      res.touchdown_velocity = world_to_pad(pad, {drone.state().p, drone.state().v, {}}).v;
    }
    if (!armed) {
      const DroneState now = drone.state();
      const Eigen::Vector3d rel_v = world_to_pad(pad, {now.p, now.v, {}}).v;
      rest_timer = rel_v.norm() < 0.05 ? rest_timer + dt : 0;
      const bool settled = rest_timer >= 0.3;
      if (settled || t - shutdown_time > 3.0) {
        const Eigen::Isometry3d T = pad.T_world_pad.inverse() * drone.T_world_body();
        const Eigen::Vector2d half = 0.5 * o.pad.size;
        const bool inside = std::abs(T.translation().x()) <= half.x() && std::abs(T.translation().y()) <= half.y();
        const double tilt = nutation_between(pad.T_world_pad.linear(), drone.T_world_body().linear());
        res.duration = t;
        res.touchdown_error = T.translation().head<2>().norm();
        if (!settled) {
          crash("still moving on the pad 3 s after shutdown", t);
        } else if (!c.support_on_pad) {
          crash("came to rest without its feet on the pad", t);
        } else if (!inside) {
          crash("came to rest off the pad's area", t);
        } else if (tilt > 0.35) {
          crash("tipped over on the pad", t);
        } else {
          res.outcome = MissionOutcome::Landed;
        }
        done = true;
      }
    }
  }
  if (!done && res.message.empty() && res.outcome == MissionOutcome::Timeout) {
    res.duration = static_cast<double>(step) * dt;
    res.message = "no landing within the timeout";
  }
  res.landing_attempts = machine.landing_attempts();
  res.replan_median_ms = median_of(replan_ms);
  if (!pose_errors.empty()) {
    res.pose_error_max = *std::max_element(pose_errors.begin(), pose_errors.end());
    res.pose_error_median = median_of(std::move(pose_errors));
  }
  return res;
}

std::vector<MissionResult> run_missions(const MissionOptions& options, int runs, std::uint64_t seed, int threads,
                                        const PerceptionFactory& perception,
                                        const std::function<void(int done, int total)>& progress) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (runs < 1) throw InvalidArgument("runs: must be >= 1");
  std::vector<MissionResult> results(static_cast<std::size_t>(runs));
  std::mutex mutex;
  int done = 0;
  auto body = [&](int i) {
    results[static_cast<std::size_t>(i)] = run_mission(options, seed, static_cast<std::uint64_t>(i), false, perception);
    if (progress) {
      const std::lock_guard lock(mutex);
      progress(++done, runs);
    }
  };
  const int n = threads > 0 ? threads : static_cast<int>(tbb::this_task_arena::max_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(std::max(1, n)));
  tbb::parallel_for(0, runs, body);
  return results;
}

}  // namespace touchdown::mission
