// The violation types as the source defines them (issue 52), on hand-built
// runs of a scripted system: a descent committed on a look-alike is Type I;
// a true detection followed by drift, or a landing with no detection, is an
// off-marker landing; and every run records what its class rests on.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

#include "scenario/clear_scenario.hpp"
#include "touchdown/scenario/run.hpp"

namespace touchdown::scenario {
namespace {

/// Flies to above `point` at 8 m, reports a detection of it in each frame
/// once there (the corners of a 0.5 m square around it, projected), commits
/// to a descent on it after 1 s, then lands with horizontal velocity `drift`.
/// With report = false it reports nothing and lands all the same. With
/// re_aim(p), while landing it reports a detection of p in each frame
/// instead (a false one when p is a distractor) and steers towards p, or by
/// `drift` while drift is not zero (a detection it does not follow).
class Scripted final : public LandingSystem {
 public:
  Scripted(Eigen::Vector2d point, Eigen::Vector2d drift, bool report) : point_(point), drift_(drift), report_(report) {}
  void re_aim(Eigen::Vector2d p) { re_aim_ = p, has_re_aim_ = true; }
  std::string_view name() const override { return "scripted"; }
  void reset(const SystemSetup& setup) override {
    setup_ = setup;
    over_since_ = -1;
    descending_ = false;
  }
  SystemOutput update(const SystemInput& in) override {
    SystemOutput out;
    const DroneState& s = in.state;
    const Eigen::Vector2d to = point_ - s.position.head<2>();
    if (descending_) {
      out.command.land = true;
      out.command.velocity_world << drift_, 0;
      out.phase = "land";
      if (has_re_aim_) {
        if (in.frame) out.detections.push_back(detection_of(re_aim_, s));
        Eigen::Vector2d v = re_aim_ - s.position.head<2>();
        if (v.norm() > 1.0) v /= v.norm();
        if (drift_.isZero()) out.command.velocity_world << v, 0;
      }
      return out;
    }
    out.phase = "approach";
    Eigen::Vector2d v = to;
    if (v.norm() > 2.0) v *= 2.0 / v.norm();
    out.command.velocity_world << v, 8.0 - s.position.z();
    if (to.norm() < 0.3 && std::abs(s.position.z() - 8.0) < 0.3) {
      if (over_since_ < 0) over_since_ = s.t;
      if (in.frame && report_) out.detections.push_back(detection_of(point_, s));
      if (s.t - over_since_ >= 1.0) {
        descending_ = true;
        out.descent_started = true;
        out.target = point_;
      }
    }
    return out;
  }

 private:
  Detection detection_of(const Eigen::Vector2d& p, const DroneState& s) const {
    const CameraOptions& cam = setup_.camera;
    const Eigen::Isometry3d T_camera_world = (s.T_world_body() * cam.T_body_camera()).inverse();
    Detection d;
    d.id = setup_.marker_id;
    d.accepted = true;
    d.ground = p;
    const std::array<Eigen::Vector2d, 4> offsets{{{-0.25, 0.25}, {0.25, 0.25}, {0.25, -0.25}, {-0.25, -0.25}}};
    for (std::size_t i = 0; i < 4; ++i) {
      const Eigen::Vector3d pc = T_camera_world * Eigen::Vector3d(p.x() + offsets[i].x(), p.y() + offsets[i].y(), 0);
      d.corners[i] = Eigen::Vector2d(cam.fx() * pc.x() / pc.z() + 0.5 * (cam.width - 1),
                                     cam.fx() * pc.y() / pc.z() + 0.5 * (cam.height - 1));
    }
    d.quality = (d.corners[1] - d.corners[0]).norm();
    return d;
  }

  Eigen::Vector2d point_, drift_;
  bool report_;
  Eigen::Vector2d re_aim_ = Eigen::Vector2d::Zero();
  bool has_re_aim_ = false;
  SystemSetup setup_;
  double over_since_ = -1;
  bool descending_ = false;
};

Scenario with_lookalike(Eigen::Vector2d at = {6, 0}) {
  Scenario s = test::clear_scenario(60);
  Distractor fake;
  fake.kind = DistractorKind::Lookalike;
  fake.flipped_bits = 2;
  fake.position = at;
  s.distractors = {fake};
  return s;
}

TEST(ViolationTypes, ADescentCommittedOnALookalikeIsTypeI) {
  const Scenario s = with_lookalike();
  Scripted sut(s.distractors[0].position, {0, 0}, true);
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_TRUE(r.landed) << r.message;
  EXPECT_NEAR(r.dtl, 6.0, 0.5);
  EXPECT_EQ(r.status, Violation::TypeI) << r.message;
  ASSERT_TRUE(r.has_trigger);
  EXPECT_EQ(r.trigger.label, Label::Distractor);
  EXPECT_EQ(r.trigger.object, "distractors[0] (lookalike)");
  EXPECT_NEAR((r.trigger.ground - s.distractors[0].position).norm(), 0.0, 0.3);
  EXPECT_TRUE(r.false_detection);
  EXPECT_NE(r.message.find("lookalike"), std::string::npos) << r.message;
}

TEST(ViolationTypes, ATrueDetectionThenDriftIsAnOffMarkerLanding) {
  const Scenario s = with_lookalike();
  Scripted sut(s.marker.position, {0.6, 0.4}, true);
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_TRUE(r.landed) << r.message;
  EXPECT_GT(r.dtl, 1.5) << "the drift must carry it off";
  EXPECT_EQ(r.status, Violation::OffMarker) << r.message;
  ASSERT_TRUE(r.has_trigger);
  EXPECT_TRUE(r.trigger.on_target());
  EXPECT_EQ(r.trigger.object, "marker");
  EXPECT_FALSE(r.false_detection);
  EXPECT_NEAR((r.descent_target - s.marker.position).norm(), 0.0, 1e-12);
  EXPECT_NE(r.message.find("after a true detection"), std::string::npos) << r.message;
  EXPECT_EQ(to_string(r.status), "off-marker");
}

TEST(ViolationTypes, ADescentReAimedByALookalikeIsTypeI) {
  // Committed on the marker, then (landing) it follows a look-alike 3 m off.
  const Scenario s = with_lookalike({3, 0});
  Scripted sut(s.marker.position, {0, 0}, true);
  sut.re_aim(s.distractors[0].position);
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_TRUE(r.landed) << r.message;
  EXPECT_NEAR((r.final_position.head<2>() - s.distractors[0].position).norm(), 0.0, 0.5) << r.message;
  EXPECT_EQ(r.status, Violation::TypeI) << r.message;
  ASSERT_TRUE(r.has_trigger);
  EXPECT_TRUE(r.trigger.on_target());
  EXPECT_NEAR((r.descent_target - s.marker.position).norm(), 0.0, 1e-12);
  ASSERT_TRUE(r.has_last_accepted);
  EXPECT_EQ(r.last_accepted.object, "distractors[0] (lookalike)");
  EXPECT_GT(r.last_accepted.t, r.descent_time);
  EXPECT_NE(r.message.find("committed on the marker"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("re-aimed by a detection of distractors[0] (lookalike)"), std::string::npos) << r.message;
}

TEST(ViolationTypes, AFalseDetectionNotFollowedLeavesADriftOffMarker) {
  // The same false detection while landing, but the drone drifts the other
  // way: it landed nearer the marker than the look-alike, not led by it.
  const Scenario s = with_lookalike({3, 0});
  Scripted sut(s.marker.position, {-0.6, 0.2}, true);
  sut.re_aim(s.distractors[0].position);
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_TRUE(r.landed) << r.message;
  EXPECT_GT(r.dtl, 1.5) << r.message;
  ASSERT_TRUE(r.has_last_accepted);
  EXPECT_FALSE(r.last_accepted.on_target());
  EXPECT_EQ(r.status, Violation::OffMarker) << r.message;
  EXPECT_NE(r.message.find("drifted"), std::string::npos) << r.message;
}

TEST(ViolationTypes, ALandingWithoutAnyDetectionIsBlindNotTypeI) {
  const Scenario s = with_lookalike();
  Scripted sut(Eigen::Vector2d(-4, 3), {0, 0}, false);
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_TRUE(r.landed) << r.message;
  EXPECT_EQ(r.status, Violation::OffMarker) << r.message;
  EXPECT_FALSE(r.has_trigger);
  EXPECT_FALSE(r.has_last_accepted);
  EXPECT_NE(r.message.find("blind"), std::string::npos) << r.message;
}

TEST(ViolationTypes, TheRecordsNameTheOccluderAndTheCollidedObject) {
  // The pole-on-marker collision of run_test.cpp: the object and the phase.
  const Scenario s = test::pole_on_marker_scenario();
  auto sut = make_landing_system("opencv-mls");
  const ScenarioResult r = run_scenario(s, *sut);
  ASSERT_EQ(r.status, Violation::TypeIII) << r.message;
  EXPECT_EQ(r.collision.what, "static_objects[0] (pole)");
  EXPECT_FALSE(r.collision_phase.empty());
  EXPECT_NE(r.message.find(r.collision_phase), std::string::npos) << r.message;
  // The pole stood in front of the marker in some frames: it is its occluder.
  ASSERT_FALSE(r.occluders.empty());
  EXPECT_EQ(r.occluders.front().object, "static_objects[0] (pole)");
  EXPECT_GT(r.occluders.front().frames, 0);
  EXPECT_LE(r.occluders.front().first_t, r.occluders.front().last_t);
  // The nearest approach is the collision itself.
  ASSERT_TRUE(r.has_nearest);
  EXPECT_EQ(r.nearest.what, r.collision.what);
  EXPECT_EQ(r.nearest.distance, 0.0);
  EXPECT_EQ(r.nearest_phase, r.collision_phase);
  EXPECT_NEAR(r.nearest_t, r.collision.t, 1e-9);
}

TEST(ViolationTypes, TheNearestApproachIsRecordedWithoutACollision) {
  // The look-alike scene has no objects: nothing to be near.
  const ScenarioResult none = run_scenario(with_lookalike(), *make_landing_system("opencv-mls"));
  EXPECT_FALSE(none.has_nearest);
  // A pole 1.5 m beside the marker: a clean landing passes it at about
  // 1.5 − 0.1 (its radius) − the drone's half span, never touching it.
  Scenario s = test::clear_scenario();
  StaticObject pole;
  pole.kind = StaticKind::Pole;
  pole.size = {0.2, 0.2, 3};
  pole.position = s.marker.position + Eigen::Vector2d(1.5, 0);
  s.static_objects = {pole};
  const ScenarioResult r = run_scenario(s, *make_landing_system("opencv-mls"));
  ASSERT_TRUE(r.landed) << r.message;
  ASSERT_TRUE(r.has_nearest);
  EXPECT_EQ(r.nearest.what, "static_objects[0] (pole)");
  // On the ground the drone's centre is within dtl of the marker's; its
  // reach toward the pole is between the X frame's narrowest (a rotor
  // disk's centre at 45°, m = r/√2) and its half span; the approach may
  // have wandered a little nearer (0.2 m).
  const FlightOptions f;
  const double half_span = f.airframe.motor_radius + f.airframe.prop_radius;
  const double narrowest = f.airframe.motor_radius / std::sqrt(2.0) + f.airframe.prop_radius;
  EXPECT_GT(r.nearest.distance, 1.5 - 0.1 - half_span - r.dtl - 0.2) << r.message;
  EXPECT_LT(r.nearest.distance, 1.5 - 0.1 - narrowest + r.dtl + 0.02) << r.message;
}

TEST(ViolationTypes, TheFactsReplayBitForBit) {
  const Scenario s = with_lookalike();
  Scripted a(s.distractors[0].position, {0, 0}, true), b(s.distractors[0].position, {0, 0}, true);
  const ScenarioResult ra = run_scenario(s, a), rb = run_scenario(s, b);
  EXPECT_EQ(ra.message, rb.message);
  EXPECT_EQ(ra.trigger.object, rb.trigger.object);
  EXPECT_EQ(ra.trigger.t, rb.trigger.t);
  EXPECT_EQ(ra.observability.longest_s, rb.observability.longest_s);
  EXPECT_EQ(ra.observability.probe_longest_s, rb.observability.probe_longest_s);
  ASSERT_EQ(ra.probe.size(), rb.probe.size());
  for (std::size_t i = 0; i < ra.probe.size(); ++i) EXPECT_EQ(ra.probe[i].view.contrast, rb.probe[i].view.contrast);
}

}  // namespace
}  // namespace touchdown::scenario
