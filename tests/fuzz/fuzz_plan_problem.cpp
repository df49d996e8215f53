// libFuzzer target for the landing problem YAML parser (problem_io.hpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/plan/problem_io.hpp"

namespace {

using touchdown::plan::KinematicState;
using touchdown::plan::PlanProblem;

bool same_state(const KinematicState& a, const KinematicState& b) { return a.p == b.p && a.v == b.v && a.a == b.a; }

// Every value the same double, except the camera rotation, which passes
// through roll-pitch-yaw degrees (docs/formats.md).
bool same_problem(const PlanProblem& a, const PlanProblem& b) {
  if (!same_state(a.start, b.start) || a.goal.has_value() != b.goal.has_value()) return false;
  if (a.goal && !same_state(*a.goal, *b.goal)) return false;
  if (a.pad.velocity != b.pad.velocity || a.pad.yaw_rate != b.pad.yaw_rate || a.pad.yaw != b.pad.yaw) return false;
  const auto &o = a.options, &p = b.options;
  if (o.order != p.order || o.segments != p.segments || o.v_max != p.v_max || o.a_max != p.a_max ||
      o.durations != p.durations || o.time.min != p.time.min || o.time.max != p.time.max || o.time.rho != p.time.rho ||
      o.time.max_evaluations != p.time.max_evaluations || o.corridor.has_value() != p.corridor.has_value() ||
      o.obstacles.size() != p.obstacles.size()) {
    return false;
  }
  for (std::size_t i = 0; i < o.obstacles.size(); ++i) {
    if (o.obstacles[i].min != p.obstacles[i].min || o.obstacles[i].max != p.obstacles[i].max) return false;
  }
  if (!o.corridor) return true;
  const auto &c = *o.corridor, &d = *p.corridor;
  if (c.h_touchdown != d.h_touchdown || c.deflate != d.deflate || c.dilate != d.dilate ||
      c.max_dilations != d.max_dilations || c.radius != d.radius || c.margin != d.margin ||
      c.camera.has_value() != d.camera.has_value()) {
    return false;
  }
  if (!c.camera) return true;
  const auto &x = *c.camera, &y = *d.camera;
  return x.T_pad_camera.translation() == y.T_pad_camera.translation() &&
         (x.T_pad_camera.linear() - y.T_pad_camera.linear()).cwiseAbs().maxCoeff() < 1e-12 &&
         x.horizontal_fov_rad == y.horizontal_fov_rad && x.vertical_fov_rad == y.vertical_fov_rad &&
         x.near_m == y.near_m && x.far_m == y.far_m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  PlanProblem problem;
  try {
    problem =
        touchdown::plan::parse_plan_problem(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
  } catch (const touchdown::Error&) {
    return 0;
  }
  // A parsed problem is always valid ...
  std::string why;
  if (!problem.options.validate(&why)) __builtin_trap();
  // ... and writes back to YAML that parses (no exception may escape here)
  // to the same values.
  PlanProblem again;
  try {
    again = touchdown::plan::parse_plan_problem(touchdown::plan::plan_problem_to_yaml(problem), "again");
  } catch (const touchdown::Error&) {
    __builtin_trap();
  }
  if (!same_problem(problem, again)) __builtin_trap();
  return 0;
}
