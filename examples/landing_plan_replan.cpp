// Replan a landing at 10 Hz against a vehicle driving a circle, through the
// library API — what a companion-computer integrator copies. Every 0.1 s
// the planner gets the drone's state relative to the pad and the pad's
// current velocity and yaw rate, builds the corridor, allocates the segment
// durations and solves the QP; the drone then flies 0.1 s of the new plan
// with a small random gust on its velocity (the disturbance replanning is
// for). A replan that fails keeps the previous plan. Within 10 cm of the
// touchdown point at under 0.3 m/s relative, the drone touches down.
//
//   example_landing_plan_replan data/plans/landing.yaml
#include <chrono>
#include <cstdio>
#include <random>

#include "touchdown/core/error.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"

int main(int argc, char** argv) {
  namespace tp = touchdown::plan;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s PROBLEM.yaml\n", argv[0]);
    return 2;
  }
  tp::PlanProblem problem;
  try {
    problem = tp::load_plan_problem(argv[1]);
  } catch (const touchdown::Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  // The vehicle drives a circle of 10 m radius at 2 m/s.
  tp::PadMotion pad;
  pad.velocity = Eigen::Vector3d(2, 0, 0);
  pad.yaw_rate = 0.2;
  const double period = 0.1;  // 10 Hz
  tp::KinematicState drone = problem.start;
  std::mt19937 rng(1);
  std::normal_distribution<double> gust(0, 0.05);
  const Eigen::Vector3d touchdown = problem.goal ? problem.goal->p : tp::default_goal(problem.options).p;
  double t = 0, worst_ms = 0, age = 0;
  int replans = 0, kept = 0;
  tp::PlanResult plan;
  for (; replans < 200; ++replans) {
    // Within 10 cm of the touchdown point and slower than 0.3 m/s relative to the pad: touch down.
    if ((drone.p - touchdown).norm() < 0.1 && drone.v.norm() < 0.3) {
      std::printf(
          "landed after %.1f s and %d replans (%d kept the previous plan): %.3f m from the touchdown point, "
          "%.2f m/s relative, world speed %.2f m/s; slowest replan %.1f ms\n",
          t, replans, kept, (drone.p - touchdown).norm(), drone.v.norm(), pad.to_world(0, drone).v.norm(), worst_ms);
      return 0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    tp::PlanResult next = tp::plan(drone, problem.goal, pad, problem.options);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    worst_ms = std::max(worst_ms, ms);
    if (next.ok()) {
      plan = std::move(next);
      age = 0;
    } else if (plan.ok()) {  // keep flying the last good plan
      ++kept;
    } else {
      std::printf("t %.1f s: no plan (%s: %s)\n", t, std::string(tp::to_string(next.status)).c_str(),
                  next.message.c_str());
      return 1;
    }
    std::printf("t %4.1f s  drone (%6.2f %5.2f %5.2f) m from the pad  plan %.2f s  cost %7.3f  %5.1f ms%s\n", t,
                drone.p.x(), drone.p.y(), drone.p.z(), plan.trajectory.total_duration() - age, plan.cost, ms,
                age > 0 ? "  (previous plan)" : "");
    // Fly one period of the plan (the pad moves as predicted, so the
    // relative state is the plan's), then a gust.
    age = std::min(age + period, plan.trajectory.total_duration());
    drone = {plan.trajectory.evaluate(age), plan.trajectory.evaluate(age, 1), plan.trajectory.evaluate(age, 2)};
    const double gz = gust(rng), gy = gust(rng);  // one draw per statement (argument order is unspecified)
    drone.v += Eigen::Vector3d(gust(rng), gy, gz);
    // The pad turns: its velocity in the world rotates with it.
    pad.velocity = pad.world_velocity(period);
    pad.yaw = pad.heading(period);
    t += period;
  }
  std::printf("no landing after %d replans\n", replans);
  return 1;
}
