// The observability oracle (issue 52) on hand-built scenes: a clear view,
// thick and light fog, a box over the marker, ground snow over it, cells
// painted over, the marker out of view and too far; its stretches; and the
// runs it judges (a Type II in thick fog is unfair; a system that hovers
// away from the marker in clear weather fails a fair test).
#include "touchdown/scenario/oracle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scenario/clear_scenario.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/run.hpp"

namespace touchdown::scenario {
namespace {

/// The frame a nadir camera sees from (x, y, altitude), with the oracle's view of it.
struct Shot {
  CameraFrame frame;
  TargetView view;
};

Shot shoot(const Scenario& s, const Eigen::Vector3d& at, const CameraOptions& camera = {}) {
  Renderer renderer(s, camera);
  SceneState state;
  state.T_world_body.translation() = at;
  for (std::size_t i = 0; i < s.dynamic_objects.size(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << s.dynamic_objects[i].position, 0;
    state.T_world_dynamic.push_back(T);
  }
  Shot shot;
  renderer.render(state, shot.frame);
  const TargetOracle oracle(s, OracleOptions{});
  shot.view = oracle.observe(shot.frame, state.T_world_body * camera.T_body_camera(), camera);
  return shot;
}

TEST(TargetOracle, AClearMarkerBelowIsObservable) {
  const Shot shot = shoot(test::clear_scenario(), {0, 0, 10});
  const TargetView& v = shot.view;
  EXPECT_EQ(v.sight, Sight::Observable) << to_string(v.sight);
  // 1 m at 10 m with fx = 320 px: 32 px a side.
  EXPECT_NEAR(v.side_px, 32.0, 1.0);
  EXPECT_NEAR(v.view_angle_deg, 0.0, 1.0);
  EXPECT_NEAR(v.visible_fraction, 1.0, 1e-9);
  EXPECT_GT(v.contrast, 120) << "paper white against ink black";
  EXPECT_EQ(v.misread_border, 0);
  EXPECT_EQ(v.misread_code, 0);
}

TEST(TargetOracle, ThickFogLeavesNoContrastLightFogLeavesEnough) {
  Scenario s = test::clear_scenario();
  s.weather.fog = 0.34;  // the grey frame: t = exp(-0.34 · 10) = 0.033 at 10 m
  const Shot thick = shoot(s, {0, 0, 10});
  EXPECT_EQ(thick.view.sight, Sight::LowContrast) << to_string(thick.view.sight);
  EXPECT_LT(thick.view.contrast, 14);
  s.weather.fog = 0.05;  // t = 0.61
  const Shot light = shoot(s, {0, 0, 10});
  EXPECT_EQ(light.view.sight, Sight::Observable) << to_string(light.view.sight);
  // Koschmieder: the contrast falls with the transmission (within 25 %).
  const Shot clear = shoot(test::clear_scenario(), {0, 0, 10});
  EXPECT_NEAR(light.view.contrast / clear.view.contrast, std::exp(-0.05 * 10), 0.25 * std::exp(-0.05 * 10));
}

TEST(TargetOracle, ABoxOverTheMarkerHidesIt) {
  Scenario s = test::clear_scenario();
  StaticObject box;
  box.kind = StaticKind::Box;
  box.position = {0.2, 0};
  box.size = {1.2, 1.2, 0.4};
  s.static_objects = {box};
  const Shot shot = shoot(s, {0, 0, 10});
  EXPECT_EQ(shot.view.sight, Sight::Hidden) << to_string(shot.view.sight);
  EXPECT_LT(shot.view.visible_fraction, 0.5);
}

TEST(TargetOracle, GroundSnowOverTheMarkerMakesItUnreadable) {
  Scenario s = test::clear_scenario();
  s.weather.ground_snow = 1.0;
  const Shot shot = shoot(s, {0, 0, 10});
  EXPECT_FALSE(shot.view.observable()) << "contrast " << shot.view.contrast;
  EXPECT_TRUE(shot.view.sight == Sight::Covered || shot.view.sight == Sight::LowContrast) << to_string(shot.view.sight);
}

TEST(TargetOracle, ABorderCellPaintedWhiteIsCovered) {
  // The clear frame with the pixels of one black border cell (top-left,
  // 1/6 of the side from the corner) painted paper white: ArUco's contour
  // breaks there, so the oracle must not call it readable.
  const Scenario s = test::clear_scenario();
  Shot shot = shoot(s, {0, 0, 10});
  ASSERT_EQ(shot.view.sight, Sight::Observable);
  const CameraOptions camera;
  const double f = camera.fx(), cx = 0.5 * (camera.width - 1), cy = 0.5 * (camera.height - 1);
  // The camera looks down with image up = body +x: world (x, y) → pixel
  // (cx - f·y/h, cy - f·x/h) at height h = 10.05.
  const double h = 10.05, cell = 1.0 / 6;
  int painted = 0;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const double x = (cy - v) * h / f, y = (cx - u) * h / f;
      // Marker yaw 0: image top = +y, left = -x; the top-left cell.
      if (x > -0.5 && x < -0.5 + cell && y < 0.5 && y > 0.5 - cell) {
        std::uint8_t* p = shot.frame.image.pixels.data() + 3 * (static_cast<std::size_t>(v) * camera.width + u);
        p[0] = p[1] = p[2] = 230;
        ++painted;
      }
    }
  }
  ASSERT_GT(painted, 10);
  const TargetOracle oracle(s, OracleOptions{});
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 0, 0, 10;
  const TargetView v = oracle.observe(shot.frame, T * camera.T_body_camera(), camera);
  EXPECT_EQ(v.sight, Sight::Covered) << to_string(v.sight);
  EXPECT_EQ(v.misread_border, 1);
  EXPECT_EQ(v.misread_code, 0);

  // A cell of the white margin (left of that one) painted leaf-dark: the
  // border's contour is open there, covered too.
  Shot margin = shoot(s, {0, 0, 10});
  painted = 0;
  for (int v2 = 0; v2 < camera.height; ++v2) {
    for (int u = 0; u < camera.width; ++u) {
      const double x = (cy - v2) * h / f, y = (cx - u) * h / f;
      if (x > -0.5 && x < -0.5 + cell && y > 0.5 && y < 0.5 + cell) {
        std::uint8_t* p = margin.frame.image.pixels.data() + 3 * (static_cast<std::size_t>(v2) * camera.width + u);
        p[0] = p[1] = p[2] = 40;
        ++painted;
      }
    }
  }
  ASSERT_GT(painted, 10);
  const TargetView w = oracle.observe(margin.frame, T * camera.T_body_camera(), camera);
  EXPECT_EQ(w.sight, Sight::Covered) << to_string(w.sight);
  EXPECT_EQ(w.misread_border, 1);
}

TEST(TargetOracle, OutOfViewAndTooFar) {
  const Scenario s = test::clear_scenario();
  EXPECT_EQ(shoot(s, {20, 0, 10}).view.sight, Sight::OutOfView);
  // Half in view: a corner outside the image is out of view too.
  EXPECT_EQ(shoot(s, {0, 7.8, 6}).view.sight, Sight::OutOfView);
  // 1 m at 60 m: 5.3 px a side, under 2 px a cell.
  const Shot far = shoot(s, {0, 0, 60});
  EXPECT_EQ(far.view.sight, Sight::TooSmall) << to_string(far.view.sight);
  EXPECT_NEAR(far.view.side_px, 320.0 / 60.05, 0.3);
}

TEST(TargetOracle, RefusesBadOptions) {
  OracleOptions o;
  o.min_contrast = -1;
  EXPECT_THROW(TargetOracle(test::clear_scenario(), o), InvalidArgument);
  o = {};
  o.probe_size_px = 4;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("probe_size_px"), std::string::npos) << why;
}

TEST(LongestStretch, JoinsGapsUpToMaxGap) {
  // Samples every 0.1 s; observable 0.0–0.4, 0.7–1.2 (gap 0.2 after 0.4 ≤ 0.3), 2.0.
  std::vector<double> t;
  std::vector<char> ok;
  for (int i = 0; i <= 20; ++i) {
    t.push_back(0.1 * i);
    ok.push_back((i <= 4 || (i >= 7 && i <= 12) || i == 20) ? 1 : 0);
  }
  EXPECT_NEAR(longest_stretch(t, ok, 0.1, 0.3), 1.3, 1e-9);  // 0.0 .. 1.2 joined, + one period
  EXPECT_NEAR(longest_stretch(t, ok, 0.1, 0.0), 0.6, 1e-9);  // 0.7 .. 1.2
  EXPECT_EQ(longest_stretch(t, std::vector<char>(t.size(), 0), 0.1, 0.3), 0.0);
  EXPECT_EQ(longest_stretch({}, {}, 0.1, 0.3), 0.0);
}

/// A system that holds its start position and never looks for the marker:
/// the planted "no search" weakness of the outside system.
class Hover final : public LandingSystem {
 public:
  std::string_view name() const override { return "hover"; }
  void reset(const SystemSetup&) override {}
  SystemOutput update(const SystemInput&) override { return {}; }
};

TEST(RunOracle, ThickFogMakesANoLandingUnfair) {
  Scenario s = test::clear_scenario(20);
  s.weather.fog = 0.34;
  auto sut = make_landing_system("opencv-mls");
  const ScenarioResult r = run_scenario(s, *sut);
  ASSERT_EQ(r.status, Violation::TypeII) << r.message;
  const Observability& o = r.observability;
  EXPECT_TRUE(o.measured);
  EXPECT_EQ(o.probe_longest_s, 0.0);
  EXPECT_EQ(o.probe_failure, Sight::LowContrast);
  EXPECT_FALSE(o.observable_long_enough());
  EXPECT_NE(r.message.find("unfair"), std::string::npos) << r.message;
  // The probe ran at 2 Hz over the 20 s.
  EXPECT_NEAR(static_cast<double>(r.probe.size()), 40, 1);
}

TEST(RunOracle, HoveringAwayInClearWeatherIsAFairNoLanding) {
  Scenario s = test::clear_scenario(20);
  s.drone.position = {-20, 0, 6};  // 90° field of view at 6 m: it sees 6 m around
  Hover sut;
  const ScenarioResult r = run_scenario(s, sut);
  ASSERT_EQ(r.status, Violation::TypeII) << r.message;
  const Observability& o = r.observability;
  // Its own camera, 20 m west at 6 m, never had the marker; the probe above
  // the marker had it the whole run.
  EXPECT_EQ(o.longest_s, 0.0);
  EXPECT_NEAR(o.probe_longest_s, 20.0, 0.5 + 1e-9);
  EXPECT_TRUE(o.observable_long_enough());
  EXPECT_EQ(r.message.find("unfair"), std::string::npos) << r.message;
}

TEST(RunOracle, ALandingSeesTheTargetLongEnoughAndCostsLittle) {
  auto sut = make_landing_system("opencv-mls");
  const ScenarioResult r = run_scenario(test::clear_scenario(), *sut);
  ASSERT_EQ(r.status, Violation::None) << r.message;
  EXPECT_GE(r.observability.longest_s, 5.0);
  // Every frame in which the system accepted the target, the oracle could read it.
  int accepted = 0, readable = 0;
  for (const FrameRecord& f : r.frames) {
    if (f.accepted > 0 && f.false_accepted == 0) {
      ++accepted;
      readable += f.view.observable() || f.view.sight == Sight::TooSmall || f.view.sight == Sight::OutOfView;
    }
  }
  EXPECT_GT(accepted, 40);
  EXPECT_GE(readable, accepted * 9 / 10);
  EXPECT_TRUE(r.has_trigger);
  EXPECT_TRUE(r.trigger.on_target()) << r.trigger.object;
  EXPECT_EQ(r.trigger.object, "marker");
}

TEST(RunOracle, OffByOptionMeasuresNothing) {
  RunOptions o;
  o.oracle.enabled = false;
  auto sut = make_landing_system("opencv-mls");
  Scenario s = test::clear_scenario(10);
  s.weather.fog = 0.34;
  const ScenarioResult r = run_scenario(s, *sut, o);
  EXPECT_FALSE(r.observability.measured);
  EXPECT_TRUE(r.probe.empty());
  EXPECT_TRUE(r.observability.observable_long_enough()) << "nothing known against the system";
}

}  // namespace
}  // namespace touchdown::scenario
