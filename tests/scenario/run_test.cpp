// Closed-loop runs: each violation type produced by a hand-built scenario
// and classified, a clean landing, and bit-identical replays.
#include "touchdown/scenario/run.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <string>

#include "scenario/clear_scenario.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

ScenarioResult run_with(const Scenario& s, std::string_view system = "opencv-mls") {
  auto sut = make_landing_system(system);
  return run_scenario(s, *sut);
}

TEST(RunScenario, ClearWeatherLandsOnTheMarker) {
  const ScenarioResult r = run_with(test::clear_scenario());
  EXPECT_FALSE(r.violation()) << r.message;
  EXPECT_EQ(r.status, Violation::None);
  EXPECT_TRUE(r.landed);
  EXPECT_LT(r.dtl, 0.5) << r.message;
  EXPECT_TRUE(r.descent_started);
  // The 5 s sighting gate: the descent starts ≥ 5 s after the first sighting.
  double first_seen = -1;
  for (const auto& f : r.frames) {
    if (f.accepted > 0) {
      first_seen = f.t;
      break;
    }
  }
  ASSERT_GE(first_seen, 0);
  EXPECT_GE(r.descent_time - first_seen, 5.0 - 1e-9);
  EXPECT_FALSE(r.false_detection);
  EXPECT_LT(r.ttl, 45);
}

TEST(RunScenario, LookalikeMarkerLeadsToATypeILanding) {
  // A look-alike one cell off the target's code (5X5_50 corrects one cell
  // at OpenCV's default error-correction rate; 4X4_50 none) under the
  // drone's approach, 12 m short of the marker: at 12 m altitude the
  // camera sees ±9 m along its flight, so the real marker stays out of view
  // while the system locks on to the look-alike.
  Scenario s = test::clear_scenario();
  s.marker.dictionary = "5X5_50";
  Distractor fake;
  fake.kind = DistractorKind::Lookalike;
  fake.flipped_bits = 1;
  fake.position = {-12, 0};
  s.distractors = {fake};
  s.drone.position = {-16, 0, 12};
  const ScenarioResult r = run_with(s);
  EXPECT_TRUE(r.violation());
  EXPECT_EQ(r.status, Violation::TypeI) << r.message;
  EXPECT_TRUE(r.landed);
  EXPECT_NEAR(r.dtl, 12.0, 1.0);
  EXPECT_TRUE(r.false_detection);
  EXPECT_NEAR((r.descent_target - fake.position).norm(), 0.0, 0.5);
}

TEST(RunScenario, DenseFogIsATypeIIViolation) {
  Scenario s = test::clear_scenario();
  s.weather.fog = 0.4;
  s.time_limit = 20;
  const ScenarioResult r = run_with(s);
  EXPECT_TRUE(r.violation());
  EXPECT_EQ(r.status, Violation::TypeII) << r.message;
  EXPECT_FALSE(r.landed);
  EXPECT_FALSE(r.descent_started);
  EXPECT_DOUBLE_EQ(r.ttl, 20);
  for (const auto& f : r.frames) EXPECT_EQ(f.accepted, 0);
}

TEST(RunScenario, PoleOnTheDescentPathIsATypeIIICollision) {
  // A thin pole (5 cm) standing on the marker, 0.28 m from its centre: the
  // marker is read from above and the descent meets the pole.
  const Scenario s = test::pole_on_marker_scenario();
  const ScenarioResult r = run_with(s);
  EXPECT_TRUE(r.violation());
  EXPECT_EQ(r.status, Violation::TypeIII) << r.message;
  EXPECT_TRUE(r.collided);
  EXPECT_EQ(r.collision.what, "static_objects[0] (pole)");
  // It hit the pole on the way down, below the pole's top.
  EXPECT_LT(r.collision.point.z(), 4.0 + 0.05);
  EXPECT_TRUE(r.descent_started);
}

TEST(RunScenario, ReplayIsBitIdentical) {
  Scenario s = test::clear_scenario();
  DynamicObject dog;
  dog.kind = DynamicKind::Dog;
  dog.size = {0.8, 0.3, 0.6};
  dog.motion = MotionKind::Wander;
  dog.position = {3, 3};
  dog.speed = 1.5;
  s.dynamic_objects = {dog};
  s.weather.rain = 0.5;
  s.weather.ambient = 0.4;
  const Scenario replay = parse_scenario(to_json(s), "replay.json");
  const ScenarioResult a = run_with(s), b = run_with(replay);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.message, b.message);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  for (std::size_t i = 0; i < a.trajectory.size(); ++i) {
    ASSERT_EQ(std::memcmp(a.trajectory[i].position.data(), b.trajectory[i].position.data(), 3 * sizeof(double)), 0)
        << "step " << i;
    ASSERT_EQ(a.trajectory[i].phase, b.trajectory[i].phase);
  }
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    EXPECT_EQ(a.frames[i].marker_area_visible_px, b.frames[i].marker_area_visible_px);
    EXPECT_EQ(a.frames[i].detections, b.frames[i].detections);
  }
}

TEST(ScenarioRun, SteppedByHandIsRunScenario) {
  const Scenario s = test::clear_scenario();
  const ScenarioResult whole = run_with(s);
  auto sut = make_landing_system("opencv-mls");
  ScenarioRun run(s, *sut);
  std::size_t steps = 0, frames = 0;
  while (run.step()) {
    ++steps;
    frames += run.last_input().frame != nullptr ? 1 : 0;
    // Each step's input is the state the step before left.
    const double t_before = steps == 1 ? 0.0 : whole.trajectory[steps - 2].t;
    ASSERT_EQ(run.last_input().state.t, t_before) << "step " << steps;
  }
  EXPECT_TRUE(run.over());
  EXPECT_FALSE(run.step()) << "a run that is over takes no more steps";
  const ScenarioResult r = run.finish();
  EXPECT_EQ(steps, whole.trajectory.size());
  EXPECT_EQ(frames, whole.frames.size());
  EXPECT_EQ(r.status, whole.status);
  EXPECT_EQ(r.message, whole.message);
  ASSERT_EQ(r.trajectory.size(), whole.trajectory.size());
  for (std::size_t i = 0; i < r.trajectory.size(); ++i)
    ASSERT_EQ(std::memcmp(r.trajectory[i].position.data(), whole.trajectory[i].position.data(), 3 * sizeof(double)), 0)
        << "step " << i;
  // The outcome's summaries are derived from the records.
  EXPECT_EQ(r.flight_s, r.trajectory.back().t);
  EXPECT_EQ(r.frame_count, static_cast<int>(r.frames.size()));
  EXPECT_EQ(r.ok(), !r.violation());
}

TEST(ScenarioRun, MaxTimeEndsTheRunAsATypeII) {
  const Scenario s = test::clear_scenario();
  ASSERT_GT(s.time_limit, 3.0);
  auto sut = make_landing_system("opencv-mls");
  ScenarioRun run(s, *sut, {}, 3.0);
  EXPECT_EQ(run.time_limit(), 3.0);
  while (run.step()) {
  }
  const ScenarioResult r = run.finish();
  EXPECT_FALSE(r.landed);
  EXPECT_EQ(r.status, Violation::TypeII);
  EXPECT_TRUE(r.violation());
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.ttl, 3.0);
  EXPECT_NEAR(r.flight_s, 3.0, 1e-9);
  EXPECT_NE(r.message.find("no landing within 3 s"), std::string::npos) << r.message;
}

TEST(RunScenario, RejectsInvalidOptionsAndUnknownSystems) {
  RunOptions o;
  o.violation_radius = -1;
  auto sut = make_landing_system("opencv-mls");
  const Scenario clear = test::clear_scenario();
  EXPECT_THROW(run_scenario(clear, *sut, o), InvalidArgument);
  EXPECT_THROW(ScenarioRun(clear, *sut, o), InvalidArgument);
  EXPECT_THROW(make_landing_system("px4-precland"), InvalidArgument);
  MlsOptions m;
  m.seen_time = -1;
  EXPECT_THROW(make_landing_system("mm-mls", m), InvalidArgument);
  MlsOptions g;
  g.track_gate = std::numeric_limits<double>::quiet_NaN();
  try {
    (void)make_landing_system("mm-mls", g);
    ADD_FAILURE() << "a NaN track_gate was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("track_gate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace touchdown::scenario
