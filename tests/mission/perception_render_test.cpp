// The render perception: the built-in camera and constellation are the
// bundled files' numbers; it keeps the perception contract on an approach
// to the pad (as does the model); a short render-mode mission lands.
#include "touchdown/mission/perception_render.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "perception_contract.hpp"
#include "touchdown/mission/mission.hpp"

namespace tdm = touchdown::mission;

namespace {

std::filesystem::path data(const std::string& rel) {
  return std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data" / rel;
}

// An approach from the tracking point down to the pad at 30 Hz, level, in
// the pad frame: what the vehicle's camera watches while landing.
std::vector<tdm::PerceptionTruth> approach() {
  const tdm::MissionOptions o;
  const Eigen::Vector3d com = o.drone.airframe.centre_of_mass();
  std::vector<tdm::PerceptionTruth> path;
  const int n = 90;
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1);
    tdm::PerceptionTruth t;
    t.t = i / 30.0;
    t.T_pad_body.translation() = (1 - s) * o.guidance.tracking_point + s * Eigen::Vector3d(0, 0, 0.15) - com;
    t.p_pad_com = t.T_pad_body * com;
    path.push_back(t);
  }
  return path;
}

}  // namespace

TEST(RenderPerception, BuiltInCameraAndConstellationAreTheBundledFiles) {
  const auto file = touchdown::pose::load_constellation(data("constellations/quad180_leds.yaml"));
  const auto built_in = tdm::quad180_constellation();
  ASSERT_EQ(file.leds.size(), built_in.leds.size());
  for (std::size_t i = 0; i < file.leds.size(); ++i) {
    EXPECT_EQ(file.leds[i].p_body, built_in.leds[i].p_body);
    EXPECT_EQ(file.leds[i].color, built_in.leds[i].color);
    EXPECT_TRUE(file.leds[i].normal.isApprox(built_in.leds[i].normal, 1e-12));
    EXPECT_EQ(file.leds[i].half_angle_deg, built_in.leds[i].half_angle_deg);
  }
  const auto camera = touchdown::pose::load_camera(data("cameras/d455_1280x720.yaml"));
  const auto d455 = tdm::d455_camera();
  EXPECT_EQ(camera.width, d455.width);
  EXPECT_EQ(camera.height, d455.height);
  EXPECT_EQ(camera.fx, d455.fx);
  EXPECT_EQ(camera.cx, d455.cx);
  // 87° horizontally, as the mission's corridor assumes.
  EXPECT_NEAR(2 * std::atan(0.5 * d455.width / d455.fx), 87 * M_PI / 180, 1e-3);
}

TEST(RenderPerception, KeepsThePerceptionContract) {
  const tdm::MissionOptions o;
  const auto m = o.perception_options();
  tdm::test::expect_perception_contract(
      [&](std::uint64_t seed) {
        return std::make_unique<tdm::RenderPerception>(o.render, m.camera.T_pad_camera,
                                                       o.drone.airframe.centre_of_mass(), m.rate_hz, m.latency, seed);
      },
      approach(), 0.8);
}

TEST(PerceptionModel, KeepsThePerceptionContract) {
  const tdm::MissionOptions o;
  tdm::test::expect_perception_contract(
      [&](std::uint64_t seed) { return std::make_unique<tdm::PerceptionModel>(o.perception_options(), seed); },
      approach(), 0.9);
}

TEST(RenderPerception, ShortMissionWithTheTrackerInTheLoopLands) {
  tdm::MissionOptions o;
  o.perception = "render";
  o.vehicle.path = tdm::VehiclePath::Line;
  o.drone_start = Eigen::Vector3d(-2.0, 0.0, 1.9);  // near the rendezvous point
  o.timeout = 25;
  const tdm::MissionResult r = tdm::run_mission(o, 2);
  ASSERT_EQ(r.outcome, tdm::MissionOutcome::Landed) << r.message;
  EXPECT_LT(r.touchdown_error, 0.05);
  EXPECT_GT(r.pose_ok, 0.9 * r.pose_frames);
  EXPECT_LT(r.pose_error_max, 0.05);
}

// A real camera's errors: an extrinsic calibration error moves every
// measurement by about that error (the renderer sees the true camera, the
// conversion uses the calibration), the clock offset shifts every capture
// stamp by one per-mission draw, dropped frames return no pose; all off, the
// measurements are the ideal camera's, bit for bit.
TEST(RenderPerception, CameraErrorsBiasTheMeasurementsAsCalibrated) {
  const tdm::MissionOptions o;
  const auto m = o.perception_options();
  const auto run = [&](const tdm::CameraErrors& e) {
    tdm::RenderPerceptionOptions r = o.render;
    r.errors = e;
    tdm::RenderPerception p(r, m.camera.T_pad_camera, o.drone.airframe.centre_of_mass(), m.rate_hz, m.latency, 5);
    std::vector<tdm::PoseMeasurement> out;
    for (const auto& t : approach()) out.push_back(p.capture(t));
    return out;
  };
  const auto ideal = run({});
  const auto same = run({});
  tdm::CameraErrors shifted;
  shifted.extrinsic_position_sigma = 0.02;
  shifted.clock_offset_sigma = 0.01;
  const auto biased = run(shifted);
  tdm::CameraErrors dropping;
  dropping.frame_drop = 0.5;
  const auto dropped = run(dropping);
  int ok = 0, dropped_ok = 0;
  double offset = 0;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  const auto path = approach();
  for (std::size_t i = 0; i < path.size(); ++i) {
    EXPECT_EQ(ideal[i].ok, same[i].ok);
    if (ideal[i].ok) {
      EXPECT_EQ(ideal[i].p_pad, same[i].p_pad);
    }
    EXPECT_DOUBLE_EQ(ideal[i].t_capture, path[i].t);
    dropped_ok += dropped[i].ok ? 1 : 0;
    if (!ideal[i].ok || !biased[i].ok) continue;
    ++ok;
    bias += biased[i].p_pad - ideal[i].p_pad;
    if (i == 0) offset = biased[i].t_capture - path[i].t;
    EXPECT_NEAR(biased[i].t_capture - path[i].t, offset, 1e-12);  // one offset per mission
  }
  ASSERT_GT(ok, 40);
  bias /= ok;
  // A 2 cm per-axis position error of the camera: the measurements move by
  // centimetres, consistently (the mean shift is of that size, not zero).
  EXPECT_GT(bias.norm(), 0.005);
  EXPECT_LT(bias.norm(), 0.2);
  EXPECT_GT(std::abs(offset), 1e-5);
  EXPECT_LT(std::abs(offset), 0.05);
  EXPECT_LT(dropped_ok, 0.75 * ok);  // about half of the frames never arrive
  EXPECT_GT(dropped_ok, 0.25 * ok);
}
