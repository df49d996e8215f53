// The mission state machine on scripted inputs: every transition and every
// guard, each abort included.
#include "touchdown/mission/state_machine.hpp"

#include <gtest/gtest.h>

#include "touchdown/core/error.hpp"

namespace tdm = touchdown::mission;
using tdm::MissionState;
using tdm::TransitionReason;

namespace {

// A scripted ground station: holds the inputs and steps the machine at 100 Hz,
// with pose frames at 30 Hz while `frames_ok`.
struct Script {
  explicit Script(tdm::StateMachineOptions o = {}) : machine(o), options(o) {}
  tdm::StateMachine machine;
  tdm::StateMachineOptions options;
  tdm::StateMachineInputs in;
  bool frames = false, frames_ok = true;
  double next_frame = 0;
  std::vector<tdm::Transition> log;

  tdm::StateMachineOutput step(double dt = 0.01) {
    in.t += dt;
    in.new_pose = frames && in.t >= next_frame;
    if (in.new_pose) next_frame = in.t + 1.0 / 30;
    in.pose_ok = frames_ok;
    const tdm::StateMachineOutput out = machine.step(in);
    if (out.transitioned) log.push_back(out.transition);
    in.replan = tdm::ReplanOutcome::None;
    return out;
  }
  // Steps until the state changes or `seconds` pass; the reason of the change.
  std::optional<TransitionReason> run(double seconds) {
    const double end = in.t + seconds;
    while (in.t < end) {
      const auto out = step();
      if (out.transitioned) return out.transition.reason;
    }
    return std::nullopt;
  }
  // Drives a fresh machine into `state` along the nominal path.
  void reach(MissionState state) {
    in.p_fix = options.rendezvous_point;
    if (state == MissionState::Searching) return;
    ASSERT_EQ(run(1), TransitionReason::ArrivedAtRendezvous);
    if (state == MissionState::Rendezvous) return;
    frames = true;
    ASSERT_EQ(run(2), TransitionReason::TrackerLocked);
    if (state == MissionState::Tracking) return;
    in.tracking_point = {-1, 0, 1};
    in.p_estimate = in.tracking_point;
    in.height = 1;
    in.have_plan = true;
    ASSERT_EQ(run(options.stable_time + 0.5), TransitionReason::TrackingStable);
  }
};

}  // namespace

TEST(StateMachine, NominalPathThroughAllFiveStates) {
  Script s;
  EXPECT_EQ(s.machine.state(), MissionState::Searching);
  // Far from the rendezvous point: keeps searching.
  s.in.p_fix = {-10, 3, 5};
  EXPECT_FALSE(s.run(2).has_value());
  s.reach(MissionState::Landing);
  EXPECT_EQ(s.machine.state(), MissionState::Landing);
  // Descends onto the pad centre: shutdown, motors off.
  s.in.p_estimate = {0.03, -0.02, 0.2};
  s.in.height = s.options.shutdown_height;
  const auto out = s.step();
  ASSERT_TRUE(out.transitioned);
  EXPECT_EQ(out.transition.reason, TransitionReason::TouchdownZone);
  EXPECT_TRUE(out.motors_off);
  EXPECT_EQ(s.machine.state(), MissionState::Shutdown);
  ASSERT_EQ(s.log.size(), 4u);
  EXPECT_EQ(s.log[0].to, MissionState::Rendezvous);
  EXPECT_EQ(s.log[1].to, MissionState::Tracking);
  EXPECT_EQ(s.log[2].to, MissionState::Landing);
  EXPECT_EQ(s.log[3].to, MissionState::Shutdown);
  // Shutdown is final.
  s.frames = false;
  EXPECT_FALSE(s.run(5).has_value());
}

TEST(StateMachine, LockNeedsOkFramesWithoutAGap) {
  tdm::StateMachineOptions o;
  o.lock_frames = 10;
  Script s(o);
  s.reach(MissionState::Rendezvous);
  // Frames that are not Ok never lock.
  s.frames = true;
  s.frames_ok = false;
  EXPECT_FALSE(s.run(1).has_value());
  // Nine Ok frames, then one without an Ok pose (dropped): it does not
  // count and does not reset; the tenth Ok frame locks.
  s.frames_ok = true;
  for (int k = 0; k < 9;) k += s.step().state == MissionState::Rendezvous && s.in.new_pose ? 1 : 0;
  s.frames_ok = false;
  while (!s.in.new_pose) s.step();
  s.frames_ok = true;
  int frames = 0;
  while (s.machine.state() == MissionState::Rendezvous) {
    s.step();
    frames += s.in.new_pose ? 1 : 0;
  }
  EXPECT_EQ(frames, 1);
  EXPECT_EQ(s.log.back().reason, TransitionReason::TrackerLocked);
  // A gap longer than lock_max_gap restarts the count.
  Script g(o);
  g.reach(MissionState::Rendezvous);
  g.frames = true;
  for (int k = 0; k < 9;) k += g.step().state == MissionState::Rendezvous && g.in.new_pose ? 1 : 0;
  g.frames = false;
  g.run(o.lock_max_gap + 0.05);
  g.frames = true;
  frames = 0;
  while (g.machine.state() == MissionState::Rendezvous) {
    g.step();
    frames += g.in.new_pose ? 1 : 0;
  }
  EXPECT_EQ(frames, o.lock_frames);
}

TEST(StateMachine, RendezvousTimesOutBackToSearching) {
  tdm::StateMachineOptions o;
  o.rendezvous_timeout = 3;
  Script s(o);
  s.reach(MissionState::Rendezvous);
  EXPECT_FALSE(s.run(2.9).has_value());
  EXPECT_EQ(s.run(0.2), TransitionReason::RendezvousTimeout);
  EXPECT_EQ(s.machine.state(), MissionState::Searching);
}

TEST(StateMachine, TrackingWaitsForStableErrorAndSpeed) {
  Script s;
  s.reach(MissionState::Tracking);
  s.in.tracking_point = {-1, 0, 1};
  s.in.p_estimate = {-1, 0, 1};
  s.in.height = 1;
  // Moving too fast relative to the pad: not stable.
  s.in.v_estimate = {0.6, 0, 0};
  EXPECT_FALSE(s.run(3).has_value());
  // Slow but far from the tracking point: not stable.
  s.in.v_estimate = {0.1, 0, 0};
  s.in.p_estimate = {-1.3, 0, 1};
  EXPECT_FALSE(s.run(3).has_value());
  // Stable, then disturbed halfway: the stable time restarts.
  s.in.p_estimate = {-1, 0, 1};
  EXPECT_FALSE(s.run(1.0).has_value());
  s.in.tracking_error = 0.5;
  s.step();
  s.in.tracking_error = 0;
  EXPECT_FALSE(s.run(1.0).has_value());
  // A wind that would blow the landed drone off the pad: no landing.
  s.in.slide_ratio = s.options.max_slide_ratio * 1.1;
  EXPECT_FALSE(s.run(3).has_value());
  s.in.slide_ratio = 0;
  EXPECT_FALSE(s.run(1.0).has_value());
  EXPECT_EQ(s.run(1.0), TransitionReason::TrackingStable);
}

// A drone that never holds the tracking point (a vehicle too fast for its
// limits, a wind too strong) gives up after max_tracking_time, not at the
// mission's timeout; being stable for a moment restarts nothing.
TEST(StateMachine, TrackingNeverStableGivesUp) {
  Script s;
  s.options.max_tracking_time = 10;
  s.machine = tdm::StateMachine(s.options);
  s.reach(MissionState::Tracking);
  s.in.tracking_point = {-1, 0, 1};
  s.in.p_estimate = {-1.5, 0, 1};  // 0.5 m off: never stable
  s.in.height = 1;
  EXPECT_FALSE(s.run(9.9).has_value());
  const tdm::StateMachineOutput before = s.step();
  EXPECT_FALSE(before.gave_up);
  EXPECT_EQ(s.run(0.2), TransitionReason::NotStable);
  EXPECT_EQ(s.machine.state(), MissionState::Rendezvous);
  EXPECT_TRUE(s.step().gave_up);
  // Held there: nothing follows.
  s.in.p_estimate = s.in.tracking_point;
  EXPECT_FALSE(s.run(5).has_value());
  // Holding its point well but never cleared by the wind (the upset guard)
  // or a turning vehicle: the give-up names what held it most often.
  for (const auto& [why, blocker] :
       {std::pair{TransitionReason::WindTooStrong, 0}, std::pair{TransitionReason::VehicleTurning, 1}}) {
    Script w;
    w.options.max_tracking_time = 10;
    w.machine = tdm::StateMachine(w.options);
    w.reach(MissionState::Tracking);
    w.in.tracking_point = w.in.p_estimate = {-1, 0, 1};
    w.in.height = 1;
    w.in.slide_ratio = blocker == 0 ? 2 * w.options.max_slide_ratio : 0;
    w.in.vehicle_yaw_rate = blocker == 1 ? 2 * w.options.max_vehicle_yaw_rate : 0;
    EXPECT_EQ(w.run(10.2), why);
  }
  // Stable in time: it lands as before.
  Script t;
  t.options.max_tracking_time = 10;
  t.machine = tdm::StateMachine(t.options);
  t.reach(MissionState::Tracking);
  t.in.tracking_point = {-1, 0, 1};
  t.in.p_estimate = {-1.5, 0, 1};
  t.in.height = 1;
  EXPECT_FALSE(t.run(8).has_value());
  t.in.p_estimate = t.in.tracking_point;
  EXPECT_EQ(t.run(t.options.stable_time + 0.5), TransitionReason::TrackingStable);
}

TEST(StateMachine, TrackingLosesThePoseBackToRendezvous) {
  Script s;
  s.reach(MissionState::Tracking);
  s.frames = false;
  EXPECT_FALSE(s.run(0.45).has_value());
  EXPECT_EQ(s.run(0.2), TransitionReason::PoseLost);
  EXPECT_EQ(s.machine.state(), MissionState::Rendezvous);
  EXPECT_EQ(s.machine.landing_attempts(), 0);  // not a landing abort
}

TEST(StateMachine, EachLandingAbortNamesItsGuard) {
  struct Case {
    TransitionReason reason;
    MissionState to;
  };
  for (const Case c : {Case{TransitionReason::PoseLost, MissionState::Rendezvous},
                       Case{TransitionReason::PlanInfeasible, MissionState::Tracking},
                       Case{TransitionReason::VehicleAccelerating, MissionState::Tracking},
                       Case{TransitionReason::VehicleTurning, MissionState::Tracking},
                       Case{TransitionReason::WindTooStrong, MissionState::Tracking},
                       Case{TransitionReason::LowWithoutPlan, MissionState::Tracking},
                       Case{TransitionReason::LowOffCentre, MissionState::Tracking}}) {
    SCOPED_TRACE(std::string(tdm::to_string(c.reason)));
    Script s;
    s.reach(MissionState::Landing);
    ASSERT_EQ(s.machine.state(), MissionState::Landing);
    // Nothing wrong: stays in landing.
    EXPECT_FALSE(s.run(1).has_value());
    switch (c.reason) {
      case TransitionReason::PoseLost:
        s.frames = false;
        break;
      case TransitionReason::PlanInfeasible:
        // Four failures, then a success resets the count; then five in a row.
        for (int k = 0; k < 4; ++k) {
          s.in.replan = tdm::ReplanOutcome::Failed;
          EXPECT_FALSE(s.step().transitioned);
        }
        s.in.replan = tdm::ReplanOutcome::Ok;
        s.step();
        for (int k = 0; k < 4; ++k) {
          s.in.replan = tdm::ReplanOutcome::Failed;
          EXPECT_FALSE(s.step().transitioned);
        }
        s.in.replan = tdm::ReplanOutcome::Failed;
        break;
      case TransitionReason::VehicleAccelerating:
        s.in.vehicle_acceleration = s.options.max_vehicle_acceleration * 1.1;
        break;
      case TransitionReason::VehicleTurning:
        s.in.vehicle_yaw_rate = -s.options.max_vehicle_yaw_rate * 1.1;
        break;
      case TransitionReason::WindTooStrong:
        s.in.slide_ratio = s.options.max_slide_ratio * 1.1;
        break;
      case TransitionReason::LowWithoutPlan:
        // Low with a plan is fine; low without one aborts.
        s.in.height = 0.3;
        EXPECT_FALSE(s.run(0.5).has_value());
        s.in.have_plan = false;
        break;
      case TransitionReason::LowOffCentre:
        s.in.p_estimate = {0.0, s.options.shutdown_radius * 1.5, 0.1};
        s.in.v_estimate = {0, 0, -0.3};
        s.in.height = s.options.shutdown_height;
        break;
      default:
        FAIL();
    }
    EXPECT_EQ(s.run(1), c.reason);
    EXPECT_EQ(s.machine.state(), c.to);
    EXPECT_EQ(s.machine.landing_attempts(), 1);
  }
}

TEST(StateMachine, ShutdownNeedsBothTheRadiusAndTheHeight) {
  Script s;
  s.reach(MissionState::Landing);
  s.in.p_estimate = {0.0, 0, 0.3};
  s.in.height = 0.2;  // above the centre but high
  EXPECT_FALSE(s.run(0.5).has_value());
  s.in.height = s.options.shutdown_height;
  EXPECT_EQ(s.run(0.1), TransitionReason::TouchdownZone);
}

TEST(StateMachine, ContactFeltShutsDownAboveABiasedHeight) {
  Script s;
  s.reach(MissionState::Landing);
  // The estimate says 4 cm above the pad (a bias), descending: no shutdown.
  s.in.p_estimate = {0.02, 0, 0.3};
  s.in.height = 0.04;
  s.in.v_estimate = {0, 0, -0.3};
  EXPECT_FALSE(s.run(0.5).has_value());
  // The descent stops there (the feet are down): after contact_time, shutdown.
  s.in.v_estimate = {0, 0, -0.02};
  EXPECT_FALSE(s.run(s.options.contact_time - 0.02).has_value());
  EXPECT_EQ(s.run(0.05), TransitionReason::TouchdownZone);
}

// A stop that the guidance commands (the terminal rule holding its height
// off the touchdown point, or only starting down again) is not contact:
// taking it for one cut the motors 6 cm up (touchdown at 0.65-0.77 m/s in
// 1-3 of 100 missions on the circles before this guard).
TEST(StateMachine, AHeldHeightIsNotContact) {
  Script s;
  s.reach(MissionState::Landing);
  s.in.p_estimate = {0.02, 0, 0.3};
  s.in.height = 0.04;
  s.in.v_estimate = {0, 0, -0.02};
  s.in.commanded_descent = 0;  // holding
  EXPECT_FALSE(s.run(1.0).has_value());
  s.in.commanded_descent = 0.5 * s.options.contact_speed;  // starting down
  EXPECT_FALSE(s.run(1.0).has_value());
  s.in.commanded_descent = 0.35;  // commanded down and not moving: the feet are on the pad
  EXPECT_FALSE(s.run(s.options.contact_time - 0.02).has_value());
  EXPECT_EQ(s.run(0.05), TransitionReason::TouchdownZone);
}

// A descent that stalls higher than contact_height is not contact: the
// racing quadrotor at full lean in a 6 m/s crosswind at 14 m/s stalled with
// its lowest foot 7.6 cm up, and a contact window of 8 cm cut its motors
// there (touchdown at 0.86 m/s; road crosswind 95th percentile 0.57 → 0.28
// m/s with 5 cm).
TEST(StateMachine, AStallAboveTheContactHeightIsNotContact) {
  Script s;
  s.reach(MissionState::Landing);
  s.in.p_estimate = {0.02, 0, 0.3};
  s.in.v_estimate = {0, 0, -0.02};
  s.in.commanded_descent = 0.35;
  s.in.height = s.options.contact_height + 0.01;
  EXPECT_FALSE(s.run(1.0).has_value());
  s.in.height = s.options.contact_height - 0.01;
  EXPECT_FALSE(s.run(s.options.contact_time - 0.02).has_value());
  EXPECT_EQ(s.run(0.05), TransitionReason::TouchdownZone);
}

TEST(StateMachine, GivesUpAfterMaxLandingAttempts) {
  tdm::StateMachineOptions o;
  o.max_landing_attempts = 2;
  Script s(o);
  s.reach(MissionState::Landing);
  s.in.vehicle_yaw_rate = 5;
  EXPECT_EQ(s.run(0.1), TransitionReason::VehicleTurning);
  s.in.vehicle_yaw_rate = 0;
  EXPECT_EQ(s.run(o.stable_time + 0.5), TransitionReason::TrackingStable);
  s.in.vehicle_yaw_rate = 5;
  const auto out = s.step();
  ASSERT_TRUE(out.transitioned);
  EXPECT_EQ(out.transition.reason, TransitionReason::VehicleTurning);  // the guard that aborted the last landing
  EXPECT_EQ(out.transition.from, MissionState::Landing);
  EXPECT_TRUE(out.gave_up);
  EXPECT_EQ(s.machine.state(), MissionState::Rendezvous);
  // It holds there: no lock, no timeout, whatever comes.
  s.in.vehicle_yaw_rate = 0;
  EXPECT_FALSE(s.run(o.rendezvous_timeout + 5).has_value());
  EXPECT_TRUE(s.step().gave_up);
}

TEST(StateMachine, InvalidOptionsAreRefusedByName) {
  const auto refused = [](auto edit, const std::string& key) {
    tdm::StateMachineOptions o;
    edit(o);
    std::string why;
    EXPECT_FALSE(o.validate(&why)) << key;
    EXPECT_NE(why.find(key), std::string::npos) << why;
    EXPECT_THROW(tdm::StateMachine{o}, touchdown::InvalidArgument);
  };
  refused([](auto& o) { o.lock_frames = 0; }, "lock_frames");
  refused([](auto& o) { o.pose_timeout = std::nan(""); }, "pose_timeout");
  refused([](auto& o) { o.rendezvous_point.z() = -1; }, "rendezvous_point");
  refused([](auto& o) { o.shutdown_height = 1; }, "shutdown_height");
  refused([](auto& o) { o.max_plan_failures = 0; }, "max_plan_failures");
  refused([](auto& o) { o.max_landing_attempts = 0; }, "max_landing_attempts");
  std::string why;
  EXPECT_TRUE(tdm::StateMachineOptions{}.validate(&why)) << why;
}

TEST(StateMachine, NamesRoundTrip) {
  for (int i = 0; i < 5; ++i) {
    const auto s = static_cast<MissionState>(i);
    EXPECT_EQ(touchdown::from_string<MissionState>(tdm::to_string(s)), s);
  }
  for (int i = 0; i < 12; ++i) {
    const auto r = static_cast<TransitionReason>(i);
    EXPECT_EQ(touchdown::from_string<TransitionReason>(tdm::to_string(r)), r);
  }
}
