// The landing mission's state machine (state_machine.hpp).
#include "touchdown/mission/state_machine.hpp"

#include <cmath>

#include "core/checks.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::positive;

}  // namespace

bool StateMachineOptions::validate(std::string* why) const {
  if (!rendezvous_point.allFinite()) return invalid(why, "rendezvous_point: must be finite");
  if (!(rendezvous_point.z() > 0)) return invalid(why, "rendezvous_point: must be above the pad (z > 0)");
  if (!positive(rendezvous_radius)) return invalid(why, "rendezvous_radius: must be positive [m]");
  if (lock_frames < 1) return invalid(why, "lock_frames: must be >= 1");
  if (!positive(lock_max_gap)) return invalid(why, "lock_max_gap: must be positive [s]");
  if (!positive(rendezvous_timeout)) return invalid(why, "rendezvous_timeout: must be positive [s]");
  if (!positive(stable_error)) return invalid(why, "stable_error: must be positive [m]");
  if (!positive(stable_speed)) return invalid(why, "stable_speed: must be positive [m/s]");
  if (!(stable_time >= 0) || !std::isfinite(stable_time)) return invalid(why, "stable_time: must be >= 0 [s]");
  if (!positive(pose_timeout)) return invalid(why, "pose_timeout: must be positive [s]");
  if (max_plan_failures < 1) return invalid(why, "max_plan_failures: must be >= 1");
  if (!positive(max_vehicle_acceleration)) return invalid(why, "max_vehicle_acceleration: must be positive [m/s^2]");
  if (!(max_slide_ratio > 0 && max_slide_ratio <= 1)) return invalid(why, "max_slide_ratio: must be in (0, 1]");
  if (!positive(max_tracking_time)) return invalid(why, "max_tracking_time: must be positive [s]");
  if (!positive(max_vehicle_yaw_rate)) return invalid(why, "max_vehicle_yaw_rate: must be positive [rad/s]");
  if (!(min_height_without_plan >= 0) || !std::isfinite(min_height_without_plan)) {
    return invalid(why, "min_height_without_plan: must be >= 0 [m]");
  }
  if (!positive(shutdown_radius)) return invalid(why, "shutdown_radius: must be positive [m]");
  if (!positive(shutdown_height)) return invalid(why, "shutdown_height: must be positive [m]");
  if (!(contact_height >= shutdown_height) || !std::isfinite(contact_height)) {
    return invalid(why, "contact_height: must be finite and >= shutdown_height [m]");
  }
  if (!positive(contact_speed)) return invalid(why, "contact_speed: must be positive [m/s]");
  if (!(contact_time >= 0) || !std::isfinite(contact_time)) return invalid(why, "contact_time: must be >= 0 [s]");
  if (!(shutdown_height < min_height_without_plan)) {
    return invalid(why, "shutdown_height: must be below min_height_without_plan");
  }
  if (max_landing_attempts < 1) return invalid(why, "max_landing_attempts: must be >= 1");
  return true;
}

StateMachine::StateMachine(StateMachineOptions options) : options_(std::move(options)) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument("state machine: " + why);
}

StateMachineOutput StateMachine::go(MissionState to, TransitionReason why, double t) {
  StateMachineOutput out;
  out.transitioned = true;
  out.transition = {t, state_, to, why};
  state_ = to;
  entered_ = t;
  stable_since_ = -1;
  blocked_.fill(0);
  stalled_since_ = -1;
  plan_failures_ = 0;
  if (to == MissionState::Rendezvous) ok_run_ = 0;  // the tracker initialises here
  out.state = to;
  out.motors_off = to == MissionState::Shutdown;
  out.gave_up = gave_up_;
  return out;
}

StateMachineOutput StateMachine::step(const StateMachineInputs& in) {
  const StateMachineOptions& o = options_;
  if (!started_) {
    entered_ = in.t;
    started_ = true;
  }
  // The lock counter: Ok frames no further apart than lock_max_gap. A
  // frame without an Ok pose (dropped, or the tracker not sure) does not
  // count, and does not reset the count: only a gap does (with half the
  // frames dropped, ten Ok frames in a row came in 15 % of the missions).
  if (in.new_pose && in.pose_ok) {
    ok_run_ = in.t - last_ok_ <= o.lock_max_gap ? ok_run_ + 1 : 1;
    last_ok_ = in.t;
  }
  const bool pose_lost = in.t - last_ok_ > o.pose_timeout;
  if (in.replan == ReplanOutcome::Failed) ++plan_failures_;
  if (in.replan == ReplanOutcome::Ok) plan_failures_ = 0;

  // A landing aborted: climb back to tracking (or to the rendezvous point
  // when the pose is lost); the attempt counts.
  auto abort_landing = [&](MissionState to, TransitionReason why) {
    ++attempts_;
    if (attempts_ >= o.max_landing_attempts) {
      // The last landing's guard names the give-up (gave_up says it ends).
      gave_up_ = true;
      return go(MissionState::Rendezvous, why, in.t);
    }
    return go(to, why, in.t);
  };

  switch (state_) {
    case MissionState::Searching:
      if (!gave_up_ && (in.p_fix - o.rendezvous_point).norm() <= o.rendezvous_radius) {
        return go(MissionState::Rendezvous, TransitionReason::ArrivedAtRendezvous, in.t);
      }
      break;
    case MissionState::Rendezvous:
      if (gave_up_) break;  // holds at the rendezvous point
      if (ok_run_ >= o.lock_frames && !pose_lost) {
        return go(MissionState::Tracking, TransitionReason::TrackerLocked, in.t);
      }
      if (in.t - entered_ > o.rendezvous_timeout) {
        return go(MissionState::Searching, TransitionReason::RendezvousTimeout, in.t);
      }
      break;
    case MissionState::Tracking: {
      if (pose_lost) return go(MissionState::Rendezvous, TransitionReason::PoseLost, in.t);
      const std::array<bool, 4> clear{
          in.tracking_error <= o.stable_error && (in.p_estimate - in.tracking_point).norm() <= o.stable_error &&
              in.v_estimate.norm() <= o.stable_speed,
          in.vehicle_acceleration <= o.max_vehicle_acceleration,
          std::abs(in.vehicle_yaw_rate) <= o.max_vehicle_yaw_rate, in.slide_ratio <= o.max_slide_ratio};
      const bool stable = clear[0] && clear[1] && clear[2] && clear[3];
      for (std::size_t i = 0; i < clear.size(); ++i) blocked_[i] += clear[i] ? 0 : 1;
      if (!stable) {
        stable_since_ = -1;
      } else if (stable_since_ < 0) {
        stable_since_ = in.t;
      }
      if (stable_since_ >= 0 && in.t - stable_since_ >= o.stable_time) {
        return go(MissionState::Landing, TransitionReason::TrackingStable, in.t);
      }
      if (stable_since_ < 0 && in.t - entered_ > o.max_tracking_time) {
        gave_up_ = true;  // it will not be: hold at the rendezvous point
        // Named by what held it most often (ties: the drone's own first).
        static constexpr std::array<TransitionReason, 4> kWhy{
            TransitionReason::NotStable, TransitionReason::VehicleAccelerating, TransitionReason::VehicleTurning,
            TransitionReason::WindTooStrong};
        const auto most = std::max_element(blocked_.begin(), blocked_.end()) - blocked_.begin();
        return go(MissionState::Rendezvous, kWhy[static_cast<std::size_t>(most)], in.t);
      }
      break;
    }
    case MissionState::Landing:
      if (pose_lost) return abort_landing(MissionState::Rendezvous, TransitionReason::PoseLost);
      if (plan_failures_ >= o.max_plan_failures) {
        return abort_landing(MissionState::Tracking, TransitionReason::PlanInfeasible);
      }
      if (in.vehicle_acceleration > o.max_vehicle_acceleration) {
        return abort_landing(MissionState::Tracking, TransitionReason::VehicleAccelerating);
      }
      if (std::abs(in.vehicle_yaw_rate) > o.max_vehicle_yaw_rate) {
        return abort_landing(MissionState::Tracking, TransitionReason::VehicleTurning);
      }
      if (in.slide_ratio > o.max_slide_ratio) {
        return abort_landing(MissionState::Tracking, TransitionReason::WindTooStrong);
      }
      if (in.commanded_descent < o.contact_speed || in.height > o.contact_height ||
          std::abs(in.v_estimate.z()) >= o.contact_speed) {
        stalled_since_ = -1;
      } else if (stalled_since_ < 0) {
        stalled_since_ = in.t;
      }
      if (in.height <= o.shutdown_height || (stalled_since_ >= 0 && in.t - stalled_since_ >= o.contact_time)) {
        if ((in.p_estimate.head<2>() - in.touchdown_point).norm() <= o.shutdown_radius) {
          return go(MissionState::Shutdown, TransitionReason::TouchdownZone, in.t);
        }
        return abort_landing(MissionState::Tracking, TransitionReason::LowOffCentre);
      }
      if (!in.have_plan && in.height < o.min_height_without_plan) {
        return abort_landing(MissionState::Tracking, TransitionReason::LowWithoutPlan);
      }
      break;
    case MissionState::Shutdown:
      break;
  }
  StateMachineOutput out;
  out.state = state_;
  out.motors_off = state_ == MissionState::Shutdown;
  out.gave_up = gave_up_;
  return out;
}

}  // namespace touchdown::mission
