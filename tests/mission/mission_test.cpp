// The closed loop: a straight-line vehicle with perfect perception lands
// within 2 cm; results are bit-identical for any thread count and change
// with the seed; the guidance's frame algebra against rigid-body answers;
// the perception model's statistics; options the drone cannot fly refused.
#include "touchdown/mission/mission.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "touchdown/core/error.hpp"

namespace tdm = touchdown::mission;

namespace {

// Nothing random, nothing late: the drone sees itself exactly.
tdm::MissionOptions perfect(tdm::VehiclePath path) {
  tdm::MissionOptions o;
  o.vehicle.path = path;
  o.perception_model.sigma_a = o.perception_model.sigma_b = o.perception_model.bias_sigma = 0;
  o.perception_model.dropout = o.perception_model.dropout_b = 0;
  o.perception_model.latency = 0;
  o.link.latency = 0;
  o.link.dropout = 0;
  o.fix.sigma = 0;
  o.imu_accel_sigma = 0;
  return o;
}

void expect_same(const tdm::MissionResult& a, const tdm::MissionResult& b) {
  EXPECT_EQ(a.outcome, b.outcome);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.duration, b.duration);
  EXPECT_TRUE(a.touchdown_error == b.touchdown_error ||
              (std::isnan(a.touchdown_error) && std::isnan(b.touchdown_error)));
  EXPECT_EQ(a.max_tracking_error, b.max_tracking_error);
  EXPECT_EQ(a.replans, b.replans);
  EXPECT_EQ(a.pose_ok, b.pose_ok);
  ASSERT_EQ(a.transitions.size(), b.transitions.size());
  for (std::size_t i = 0; i < a.transitions.size(); ++i) {
    EXPECT_EQ(a.transitions[i].t, b.transitions[i].t);
    EXPECT_EQ(a.transitions[i].reason, b.transitions[i].reason);
  }
}

}  // namespace

// The drone follows the landing plan within 9 cm (0.078 m) and touches
// down within 3 cm of the pad centre (0.027 m) on its first pass: the
// terminal rule descends within 5 cm of its aim point, which leads the
// centre by the levelling shift. Without drone.turn_feed_forward the
// derivative term braked the plan's accelerations: 0.11 m off it and a hold
// over the pad to centre.
TEST(Mission, StraightLinePerfectPerceptionTracksThePlanAndLandsWithinThreeCentimetres) {
  const tdm::MissionResult r = tdm::run_mission(perfect(tdm::VehiclePath::Line), 1);
  ASSERT_EQ(r.outcome, tdm::MissionOutcome::Landed) << r.message;
  EXPECT_LT(r.touchdown_error, 0.03);
  EXPECT_LT(r.max_tracking_error, 0.09);
  EXPECT_LT(r.touchdown_speed(), 0.5);
  // Through every state once, in order.
  ASSERT_EQ(r.transitions.size(), 4u);
  EXPECT_EQ(r.transitions.back().to, tdm::MissionState::Shutdown);
  EXPECT_EQ(r.landing_attempts, 0);
  // The planned flight stays within the planner's world-frame limits (5 %).
  EXPECT_LE(r.max_axis_speed, 1.05 * r.v_limit);
  EXPECT_LE(r.max_axis_acceleration, 1.05 * r.a_limit);
  EXPECT_GT(r.replans, 5);
}

// Motors off just before the timeout: the verdict waits for the drone to
// come to rest (it was "timeout in shutdown" for a landing 0.38 s early).
TEST(Mission, ALandingJustBeforeTheTimeoutIsALanding) {
  tdm::MissionOptions o = perfect(tdm::VehiclePath::Line);
  const tdm::MissionResult first = tdm::run_mission(o, 1);
  ASSERT_EQ(first.outcome, tdm::MissionOutcome::Landed) << first.message;
  ASSERT_EQ(first.transitions.back().to, tdm::MissionState::Shutdown);
  o.timeout = first.transitions.back().t + 0.05;
  const tdm::MissionResult late = tdm::run_mission(o, 1);
  EXPECT_EQ(late.outcome, tdm::MissionOutcome::Landed) << late.message;
  EXPECT_EQ(late.touchdown_error, first.touchdown_error);
  o.timeout = first.transitions.back().t - 0.05;  // before the cut: a timeout
  EXPECT_EQ(tdm::run_mission(o, 1).outcome, tdm::MissionOutcome::Timeout);
}

TEST(Mission, SameSeedSameBitsForAnyThreadCount) {
  tdm::MissionOptions o;  // the default (noisy) circle mission
  const auto one = tdm::run_missions(o, 4, 9, 1);
  const auto two = tdm::run_missions(o, 4, 9, 2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    SCOPED_TRACE(i);
    expect_same(one[i], two[i]);
    // Run i alone is run i of the batch.
    expect_same(one[i], tdm::run_mission(o, 9, i));
  }
  // Another seed: other missions.
  const auto other = tdm::run_missions(o, 1, 10, 1);
  EXPECT_NE(other[0].duration, one[0].duration);
}

// Issue 56, Done when: the wind estimate (drone.wind_observer_time, the
// force thrust and gravity leave unexplained, through the drag) converges
// to a constant wind within a stated time, hovering over a pad that stands
// still and chasing one at 2 and 4 m/s, in the closed loop with its IMU
// noise: from 1 s on and until the motors stop, every 1 s window's mean
// horizontal error is within 0.2 m/s and no sample's beyond 0.5 m/s (seed
// 5: 0.09 / 0.11 / 0.16 and 0.21 / 0.21 / 0.33 at 0 / 2 / 4 m/s; the
// IMU's noise through the 0.05 s observer is most of it).
TEST(Mission, TheWindEstimateConvergesInHoverAndInAChase) {
  for (const double speed : {1e-3, 2.0, 4.0}) {
    SCOPED_TRACE(speed);
    tdm::MissionOptions o;
    o.vehicle.speed = speed;
    o.vehicle.max_wheel_speed = 6;
    if (speed > 3) {
      o.guidance.planner.v_max = 6;
      o.guidance.planner.a_max = 5;
    }
    o.wind.mean = {3.0, -4.0, 0.0};
    const tdm::MissionResult r = tdm::run_mission(o, 5, 0, true);
    double window = 0, worst_window = 0, worst = 0;
    int n = 0, samples = 0;
    for (const auto& s : r.trace) {
      if (s.state == tdm::MissionState::Shutdown) break;
      if (s.t < 1.0) continue;
      const double e = (s.wind_estimate - s.wind).head<2>().norm();
      worst = std::max(worst, e);
      window += e;
      ++samples;
      if (++n == 50) {  // 1 s at 50 Hz
        worst_window = std::max(worst_window, window / n);
        window = 0;
        n = 0;
      }
    }
    EXPECT_GT(samples, 400);  // flew for more than 8 s
    EXPECT_LT(worst_window, 0.2);
    EXPECT_LT(worst, 0.5);
    EXPECT_TRUE(r.landed()) << r.message;
  }
}

namespace {

// The 4 m/s chase on the 8 m circle, held at the tracking point (never
// cleared to land) with the pad-frame integral off: the steady offset from
// the tracking point, pad frame, mean over 10 s.
Eigen::Vector3d steady_offset_in_a_turn(bool turn_feed_forward) {
  tdm::MissionOptions o;
  o.vehicle.speed = 4.0;
  o.vehicle.max_wheel_speed = 6;
  o.guidance.planner.v_max = 6;
  o.guidance.planner.a_max = 5;
  o.guidance.pad_integral_gain = 0;
  o.drone.drag_feed_forward = true;
  o.drone.turn_feed_forward = turn_feed_forward;
  o.machine.stable_time = 1000;
  o.machine.max_tracking_time = 1000;
  o.timeout = 25;
  const tdm::MissionResult r = tdm::run_mission(o, 1, 0, true);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& s : r.trace) {
    if (s.t < 15 || s.state != tdm::MissionState::Tracking) continue;
    sum += s.relative - o.guidance.tracking_point;
    ++n;
  }
  EXPECT_GT(n, 400);
  return sum / std::max(n, 1);
}

}  // namespace

TEST(Mission, TheTurnFeedForwardKeepsTheDroneOnTheTurningPad) {
  // The velocity loop's derivative acts on the measured acceleration (PX4):
  // in a steady turn it brakes the centripetal 2 m/s² the setpoint asks
  // for, kd ω²R / |C(iω) − ω²| ≈ 0.2 m outward at kd 0.2, ω 0.5 rad/s, R 8 m
  // (C the velocity PI times the position P at ω). Raising the feed-forward
  // by kd takes it out. The turn is to the left: outward is −y. Seed 1:
  // (0.01, −0.27) without, (0.09, −0.06) m with.
  const Eigen::Vector3d without = steady_offset_in_a_turn(false), with = steady_offset_in_a_turn(true);
  EXPECT_LT(without.y(), -0.15) << without.transpose();
  EXPECT_GT(without.y(), -0.4) << without.transpose();
  EXPECT_LT(with.head<2>().norm(), 0.15) << with.transpose();
}

TEST(Mission, TheFigureEightAt4msLandsThroughItsLobeSwitches) {
  // Two 8 m lobes at 4 m/s: the turn reverses every 12.6 s, shorter than a
  // landing. Every landing used to fail there (plan_infeasible, pose_lost):
  // 9 of 100.
  tdm::MissionOptions o;
  o.vehicle.path = tdm::VehiclePath::FigureEight;
  o.vehicle.speed = 4.0;
  o.vehicle.max_wheel_speed = 5.4;
  o.guidance.planner.v_max = 6;
  o.guidance.planner.a_max = 5;
  o.drone.drag_feed_forward = true;
  int landed = 0;
  for (int i = 0; i < 10; ++i) landed += tdm::run_mission(o, 3, i).landed() ? 1 : 0;
  EXPECT_GE(landed, 9);
}

TEST(Mission, RecordedTraceFollowsTheRun) {
  const tdm::MissionResult r = tdm::run_mission(tdm::MissionOptions{}, 3, 0, true);
  ASSERT_FALSE(r.trace.empty());
  EXPECT_NEAR(r.trace.back().t, r.duration, 0.03);
  // 50 Hz samples, pad at its height, the state sequence as the log says.
  EXPECT_NEAR(r.trace[1].t - r.trace[0].t, 0.02, 1e-9);
  EXPECT_NEAR(r.trace[10].pad.z(), tdm::MissionOptions{}.vehicle.pad_position.z(), 1e-9);
  EXPECT_EQ(r.trace.back().state, r.transitions.empty() ? tdm::MissionState::Searching : r.transitions.back().to);
}

TEST(Mission, OptionsTheDroneCannotFlyAreRefusedByKey) {
  const auto refused = [](tdm::MissionOptions o, const std::string& key) {
    std::string why;
    EXPECT_FALSE(o.validate(&why)) << key;
    EXPECT_EQ(why.rfind(key, 0), 0u) << why;
    EXPECT_THROW((void)tdm::run_mission(o, 1), touchdown::InvalidArgument);
  };
  tdm::MissionOptions o;
  o.vehicle.speed = 5.4;  // the wheels allow it; the drone's 3 m/s per axis do not
  o.vehicle.max_wheel_speed = 8;
  refused(o, "vehicle.speed");
  o = {};
  o.machine.rendezvous_point = {2.5, 0, 1.5};  // in front of the vehicle: behind the camera
  refused(o, "state_machine.rendezvous_point");
  o = {};
  o.guidance.tracking_point = {-1.2, 0, 5};  // above the field of view
  refused(o, "guidance.tracking_point");
  o = {};
  o.link.dropout = 1;
  refused(o, "link.dropout");
  std::string why;
  EXPECT_TRUE(tdm::MissionOptions{}.validate(&why)) << why;
}

namespace {

// A camera that never finds the drone.
class BlindPerception final : public tdm::Perception {
 public:
  tdm::PoseMeasurement capture(const tdm::PerceptionTruth& truth) override {
    tdm::PoseMeasurement m;
    m.t_capture = m.t_available = truth.t;
    return m;
  }
  [[nodiscard]] double rate_hz() const override { return 30; }
};

}  // namespace

TEST(PerceptionRegistry, AUserPerceptionIsNamedLikeTheBuiltIns) {
  EXPECT_EQ(tdm::perception_registry().names(), (std::vector<std::string>{"model", "render"}));
  tdm::perception_registry().add("test-blind", "never sees the drone", [](const tdm::MissionOptions&, std::uint64_t) {
    return std::make_unique<BlindPerception>();
  });
  // The registry is process-wide: take the entry out again however this
  // test ends, so the other tests of this binary see only the built-ins.
  struct Unregister {
    ~Unregister() { tdm::perception_registry().remove("test-blind"); }
  } unregister;
  tdm::MissionOptions o = perfect(tdm::VehiclePath::Line);
  const tdm::MissionResult seen = tdm::run_mission(o, 1);
  o.perception = "test-blind";
  std::string why;
  EXPECT_TRUE(o.validate(&why)) << why;
  const tdm::MissionResult blind = tdm::run_mission(o, 1);
  // The named factory is the one flown: with it, no frame has a pose, and
  // the perfect camera's landing does not happen.
  EXPECT_GT(seen.pose_ok, 0);
  EXPECT_EQ(seen.outcome, tdm::MissionOutcome::Landed);
  EXPECT_EQ(blind.pose_ok, 0);
  EXPECT_NE(blind.outcome, tdm::MissionOutcome::Landed);
  o.perception = "telepathy";
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("perception.mode: unknown 'telepathy' (known: model, render, test-blind)"), std::string::npos)
      << why;
  EXPECT_THROW((void)tdm::make_default_perception(o, 1), touchdown::InvalidArgument);
  EXPECT_TRUE(tdm::perception_registry().remove("test-blind"));
  EXPECT_FALSE(tdm::perception_registry().remove("test-blind"));
  EXPECT_EQ(tdm::perception_registry().names(), (std::vector<std::string>{"model", "render"}));
}

TEST(Guidance, PadFrameStatesAgreeWithRigidBodyMotion) {
  // A pad at 2 m/s turning at 0.25 rad/s: a point fixed in its frame moves
  // at v + ω × r and accelerates at a + ω × (ω × r) (here a = ω × v).
  tdm::PadState pad;
  pad.T_world_pad.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pad.T_world_pad.translation() = Eigen::Vector3d(3, -1, 0.4);
  const double w = 0.25;
  pad.velocity = pad.T_world_pad.linear() * Eigen::Vector3d(2, 0, 0);
  pad.acceleration = Eigen::Vector3d(0, 0, w).cross(pad.velocity);
  pad.yaw_rate = w;
  touchdown::plan::KinematicState fixed;
  fixed.p = Eigen::Vector3d(-1.2, 0.3, 1.0);
  const auto world = tdm::pad_to_world(pad, fixed);
  const Eigen::Vector3d r = pad.T_world_pad.linear() * fixed.p, omega(0, 0, w);
  EXPECT_TRUE(world.v.isApprox(pad.velocity + omega.cross(r), 1e-12));
  EXPECT_TRUE(world.a.isApprox(pad.acceleration + omega.cross(omega.cross(r)), 1e-12));
  // And back.
  touchdown::plan::KinematicState moving{fixed.p, {0.1, -0.2, 0.3}, {0.5, 0.1, -0.2}};
  const auto back = tdm::world_to_pad(pad, tdm::pad_to_world(pad, moving));
  EXPECT_TRUE(back.p.isApprox(moving.p, 1e-12));
  EXPECT_TRUE(back.v.isApprox(moving.v, 1e-12));
  EXPECT_TRUE(back.a.isApprox(moving.a, 1e-12));
}

TEST(Guidance, AChangingTurnSwingsAFixedPointAsFiniteDifferencesSay) {
  // A pad whose yaw rate changes (ψ(t) = ψ0 + ω0 t + ½ ω̇ t², origin moving
  // as c(t) = (t, 0.3 t², 0)): a point fixed in its frame is at c + R(ψ) p;
  // its world velocity and acceleration from pad_to_world must equal the
  // central differences of that position (h = 1e-4 s).
  const double psi0 = 0.4, w0 = 0.5, wdot = -1.6;
  const Eigen::Vector3d p(-1.2, 0.3, 1.0);
  const auto at = [&](double t) {
    tdm::PadState pad;
    pad.T_world_pad.linear() =
        Eigen::AngleAxisd(psi0 + w0 * t + 0.5 * wdot * t * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pad.T_world_pad.translation() = Eigen::Vector3d(t, 0.3 * t * t, 0.4);
    pad.velocity = Eigen::Vector3d(1, 0.6 * t, 0);
    pad.acceleration = Eigen::Vector3d(0, 0.6, 0);
    pad.yaw_rate = w0 + wdot * t;
    pad.yaw_acceleration = wdot;
    return pad;
  };
  const double t = 0.7, h = 1e-4;
  const auto x = [&](double s) { return Eigen::Vector3d(at(s).T_world_pad * p); };
  touchdown::plan::KinematicState fixed;
  fixed.p = p;
  const auto world = tdm::pad_to_world(at(t), fixed);
  EXPECT_LT((world.v - (x(t + h) - x(t - h)) / (2 * h)).norm(), 1e-6);
  EXPECT_LT((world.a - (x(t + h) - 2 * x(t) + x(t - h)) / (h * h)).norm(), 1e-4);
  // Without the yaw acceleration the swing ω̇ × p (1.9 m/s² here) is missing.
  tdm::PadState steady = at(t);
  steady.yaw_acceleration = 0;
  EXPECT_GT((tdm::pad_to_world(steady, fixed).a - world.a).norm(), 1.5);
  // And back.
  const touchdown::plan::KinematicState moving{p, {0.1, -0.2, 0.3}, {0.5, 0.1, -0.2}};
  const auto back = tdm::world_to_pad(at(t), tdm::pad_to_world(at(t), moving));
  EXPECT_TRUE(back.a.isApprox(moving.a, 1e-12));
}

TEST(Guidance, LandingPlanEndsAtTheTerminalPointGoingDown) {
  const tdm::GuidanceOptions o;
  tdm::Guidance g(o, 0.06);
  tdm::PadState pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  const tdm::StateMachineOptions machine;
  touchdown::plan::KinematicState at_tracking;
  at_tracking.p = o.tracking_point;
  // Tracking holds the tracking point, moving with the pad.
  const auto hold = g.update(0, tdm::MissionState::Tracking, true, pad, at_tracking, {}, machine);
  EXPECT_TRUE(hold.setpoint.position.isApprox(o.tracking_point, 1e-12));
  EXPECT_TRUE(hold.setpoint.velocity.isApprox(pad.velocity, 1e-12));
  // Landing: the first plan from there, ending at the terminal point.
  const auto out = g.update(0.02, tdm::MissionState::Landing, true, pad, at_tracking, {}, machine);
  ASSERT_EQ(out.replan, tdm::ReplanOutcome::Ok) << g.message();
  const auto& traj = g.trajectory();
  EXPECT_TRUE(traj.evaluate(0).isApprox(o.tracking_point, 1e-6));
  EXPECT_TRUE(traj.evaluate(traj.total_duration()).isApprox(g.terminal_point(), 1e-6));
  EXPECT_NEAR(traj.evaluate(traj.total_duration(), 1).z(), -o.terminal_speed, 1e-6);
  // A replan 0.11 s later at the remaining durations keeps the end time.
  const double end = g.plan_start() + traj.total_duration();
  touchdown::plan::KinematicState on_plan{traj.evaluate(0.11), traj.evaluate(0.11, 1), traj.evaluate(0.11, 2)};
  const auto again = g.update(0.13, tdm::MissionState::Landing, false, pad, on_plan, {}, machine);
  ASSERT_EQ(again.replan, tdm::ReplanOutcome::Ok);
  EXPECT_NEAR(g.plan_start() + g.trajectory().total_duration(), end, 1e-9);
}

// The wind in the prediction: a new corridor plans within the acceleration
// the estimated wind's drag leaves (floored at half of planner.a_max).
TEST(Guidance, ANewPlanKeepsWithinTheAccelerationTheWindLeaves) {
  tdm::GuidanceOptions options;
  options.planner.time.rho = 1e5;  // time dear: the plan uses what it may
  options.planner.a_max = 2.5;
  const auto peak = [&options](double capacity) {
    const tdm::GuidanceOptions& o = options;
    tdm::Guidance g(o, 0.06);
    g.set_acceleration_capacity(capacity);
    tdm::PadState pad;
    pad.velocity = Eigen::Vector3d(2, 0, 0);
    touchdown::plan::KinematicState at_tracking;
    at_tracking.p = o.tracking_point;
    at_tracking.v = Eigen::Vector3d(0.8, -0.5, 0.3);  // overshooting: it must turn back hard
    const auto out = g.update(0, tdm::MissionState::Landing, true, pad, at_tracking, {}, {});
    EXPECT_EQ(out.replan, tdm::ReplanOutcome::Ok) << capacity << ": " << g.message();
    double a = 0;
    const auto& traj = g.trajectory();
    for (int i = 0; i <= 400; ++i) {
      a = std::max(a, traj.evaluate(traj.total_duration() * i / 400, 2).cwiseAbs().maxCoeff());
    }
    return a;
  };
  const double a_max = options.planner.a_max;
  const double free = peak(std::numeric_limits<double>::infinity());
  ASSERT_GT(free, 0.6 * a_max) << free;  // the limit below binds
  EXPECT_LE(free, a_max * (1 + 1e-6));
  EXPECT_LE(peak(0.6 * a_max), 0.6 * a_max * (1 + 1e-6));
  EXPECT_LE(peak(0.1 * a_max), 0.5 * a_max * (1 + 1e-6));  // the floor
}

TEST(PerceptionModel, NoiseGrowsWithRangeAsModelled) {
  tdm::MissionOptions mo;
  tdm::PerceptionModelOptions o = mo.perception_options();
  o.bias_sigma = 0;
  o.dropout = 0.1;
  o.dropout_b = 0;
  tdm::PerceptionModel m(o, 5);
  EXPECT_TRUE(m.visible(mo.machine.rendezvous_point));
  EXPECT_FALSE(m.visible({2.0, 0, 1}));   // ahead of the camera, which looks back
  EXPECT_FALSE(m.visible({-9.0, 0, 2}));  // beyond max_range
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(-0.3, 0, 0.3), Eigen::Vector3d(-2.5, 0, 1.5)}) {
    tdm::PerceptionTruth truth;
    truth.p_pad_com = p;
    const double r = (p - o.camera.T_pad_camera.translation()).norm();
    const double sigma = o.sigma_a + o.sigma_b * r * r;
    double sum2 = 0;
    int ok = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
      truth.t = i / 30.0;
      const auto meas = m.capture(truth);
      if (!meas.ok) continue;
      ++ok;
      EXPECT_DOUBLE_EQ(meas.sigma, sigma);
      sum2 += (meas.p_pad - p).squaredNorm();
    }
    EXPECT_NEAR(static_cast<double>(ok) / n, 1 - o.dropout, 0.01);
    EXPECT_NEAR(std::sqrt(sum2 / (3.0 * ok)), sigma, 0.02 * sigma);
  }
}

// Issue 58 item 8: why a mission did not land, in words a summary counts.
TEST(FailureReason, NamesTheCrashTheLastAbortOrWhereItTimedOut) {
  using S = tdm::MissionState;
  using R = tdm::TransitionReason;
  tdm::MissionResult landed;
  landed.outcome = tdm::MissionOutcome::Landed;
  EXPECT_EQ(tdm::failure_reason(landed), "");
  tdm::MissionResult crash;
  crash.outcome = tdm::MissionOutcome::Crashed;
  crash.message = "touched the ground";
  EXPECT_EQ(tdm::failure_reason(crash), "crashed: touched the ground");
  tdm::MissionResult gave_up;
  gave_up.outcome = tdm::MissionOutcome::Aborted;
  gave_up.transitions = {{1, S::Searching, S::Rendezvous, R::ArrivedAtRendezvous},
                         {5, S::Landing, S::Tracking, R::PoseLost},
                         {9, S::Landing, S::Tracking, R::LowOffCentre},
                         {12, S::Tracking, S::Landing, R::TrackingStable}};
  EXPECT_EQ(tdm::failure_reason(gave_up), "gave up: low_off_centre");  // the last abort, not the last transition
  tdm::MissionResult stuck;
  stuck.outcome = tdm::MissionOutcome::Timeout;
  EXPECT_EQ(tdm::failure_reason(stuck), "timeout in searching");
  stuck.transitions = {{1, S::Searching, S::Rendezvous, R::ArrivedAtRendezvous},
                       {30, S::Rendezvous, S::Rendezvous, R::RendezvousTimeout}};
  EXPECT_EQ(tdm::failure_reason(stuck), "timeout in rendezvous after rendezvous_timeout");
  stuck.transitions.push_back({31, S::Rendezvous, S::Tracking, R::TrackerLocked});
  EXPECT_EQ(tdm::failure_reason(stuck), "timeout in tracking");
  // Counted most frequent first, landings left out; merged across cells.
  const auto counts = tdm::count_failure_reasons({landed, crash, stuck, gave_up, stuck});
  EXPECT_EQ(counts,
            (tdm::FailureCounts{
                {"timeout in tracking", 2}, {"crashed: touched the ground", 1}, {"gave up: low_off_centre", 1}}));
  EXPECT_EQ(tdm::merge_failure_reasons(counts, {{"gave up: low_off_centre", 3}}),
            (tdm::FailureCounts{
                {"gave up: low_off_centre", 4}, {"timeout in tracking", 2}, {"crashed: touched the ground", 1}}));
}

// Half the camera frames without a pose: the tracker still locks (Ok frames
// without a gap, not in a row) and the missions land (15 of 100 when the
// lock wanted ten Ok frames in a row).
TEST(Mission, HalfTheFramesDroppedStillLocksAndLands) {
  tdm::MissionOptions o;
  o.perception_model.dropout = 0.5;
  const auto results = tdm::run_missions(o, 20, 1, 2);
  int landed = 0;
  for (const auto& r : results) landed += r.landed() ? 1 : 0;
  EXPECT_GE(landed, 19);
}
