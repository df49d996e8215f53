// The mission file: the bundled one reads back to the library's defaults
// (its documented setup), and each kind of bad input is one error naming
// the file, the line and the key.
#include "touchdown/mission/mission_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace tdm = touchdown::mission;
namespace td = touchdown;

namespace {

std::filesystem::path bundled() { return std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/missions/circle.yaml"; }
std::filesystem::path missions_dir() { return bundled().parent_path(); }

}  // namespace

// Issue 58 item 7: a bundled mission copied elsewhere still finds the
// airframe it names (../airframes/quad180.yaml) in touchdown's data tree.
TEST(MissionFile, ACopiedBundledMissionFindsItsAirframe) {
  td::test::TempDir dir;
  std::filesystem::create_directories(dir / "m");
  const auto copy = dir / "m/circle.yaml";
  std::filesystem::copy_file(bundled(), copy);
  const tdm::MissionFile f = tdm::load_mission(copy);
  EXPECT_EQ(f.options.drone.airframe.name, tdm::load_mission(bundled()).options.drone.airframe.name);
  EXPECT_EQ(f.airframe.filename(), "quad180.yaml");
  EXPECT_TRUE(std::filesystem::exists(f.airframe)) << f.airframe;
}

TEST(MissionFile, BundledCircleIsTheLibraryDefault) {
  const tdm::MissionFile f = tdm::load_mission(bundled());
  const tdm::MissionOptions d;
  const tdm::MissionOptions& o = f.options;
  EXPECT_TRUE(f.warnings.empty());
  EXPECT_EQ(o.vehicle.path, d.vehicle.path);
  EXPECT_EQ(o.vehicle.speed, d.vehicle.speed);
  EXPECT_EQ(o.vehicle.radius, d.vehicle.radius);
  EXPECT_EQ(o.vehicle.pad_position, d.vehicle.pad_position);
  EXPECT_EQ(o.pad.size, d.pad.size);
  EXPECT_EQ(o.drone.airframe.name, d.drone.airframe.name);
  EXPECT_DOUBLE_EQ(o.drone.airframe.total_mass(), d.drone.airframe.total_mass());
  EXPECT_EQ(o.drone_start, d.drone_start);
  EXPECT_EQ(o.machine.rendezvous_point, d.machine.rendezvous_point);
  EXPECT_NEAR(o.machine.max_vehicle_yaw_rate, d.machine.max_vehicle_yaw_rate, 0.03);
  EXPECT_EQ(o.guidance.tracking_point, d.guidance.tracking_point);
  EXPECT_EQ(o.guidance.planner.v_max, d.guidance.planner.v_max);
  EXPECT_EQ(o.guidance.planner.time.max_evaluations, d.guidance.planner.time.max_evaluations);
  ASSERT_TRUE(o.guidance.planner.corridor && o.guidance.planner.corridor->camera);
  // The camera's rpy_deg [-70, 0, 90] is the default's "back and 20° up".
  const auto& cam = o.guidance.planner.corridor->camera->T_pad_camera;
  const auto& def = d.guidance.planner.corridor->camera->T_pad_camera;
  EXPECT_TRUE(cam.linear().isApprox(def.linear(), 1e-12));
  EXPECT_TRUE(cam.translation().isApprox(def.translation(), 1e-12));
  EXPECT_EQ(o.perception_model.sigma_b, d.perception_model.sigma_b);
  EXPECT_EQ(o.link.latency, d.link.latency);
  EXPECT_EQ(o.fix.sigma, d.fix.sigma);
  EXPECT_EQ(o.timeout, d.timeout);
  EXPECT_EQ(f.airframe.filename(), "quad180.yaml");
}

class MissionFileBadInput : public ::testing::TestWithParam<td::test::BadInput> {};

TEST_P(MissionFileBadInput, OneErrorNamingTheKey) {
  const auto& input = GetParam();
  try {
    (void)tdm::parse_mission(input.text, "m.yaml", missions_dir());
    FAIL() << "accepted";
  } catch (const td::Error& e) {
    td::test::expect_one_line_naming(e.what(), input);
  }
}

namespace {

std::string text() { return td::test::read_text(bundled()); }
std::string edit(const std::string& from, const std::string& to) { return td::test::replace(text(), from, to); }

}  // namespace

INSTANTIATE_TEST_SUITE_P(
    Cases, MissionFileBadInput,
    ::testing::Values(
        td::test::BadInput{
            "unknown_key", edit("  radius: 8.0 ", "  radios: 8.0 "), {"m.yaml:15:", "vehicle.radios", "unknown key"}},
        td::test::BadInput{"nan", edit("  speed: 2.0 ", "  speed: .nan "), {"m.yaml:14:", "vehicle.speed", "number"}},
        td::test::BadInput{
            "negative_radius", edit("  radius: 8.0 ", "  radius: -8.0 "), {"m.yaml:15:", "vehicle.radius", "positive"}},
        td::test::BadInput{"too_fast_to_follow",
                           edit("  speed: 2.0 ", "  speed: 4.5 ") + "",
                           {"m.yaml:14:", "vehicle.speed", "follow"}},
        td::test::BadInput{"rendezvous_not_seen",
                           edit("rendezvous_point: [-2.5, 0.0, 1.5]", "rendezvous_point: [2.5, 0.0, 1.5]"),
                           {"m.yaml:", "state_machine.rendezvous_point", "field of view"}},
        td::test::BadInput{"bad_path_name",
                           edit("  path: circle ", "  path: oval "),
                           {"m.yaml:13:", "vehicle.path", "circle, line, figure_eight, random"}},
        td::test::BadInput{"planner_key",
                           edit("limits: {v_max: 3.0, a_max: 4.0}", "limits: {v_max: -3.0, a_max: 4.0}"),
                           {"m.yaml:", "guidance.planner.limits.v_max", "> 0"}},
        td::test::BadInput{"planner_unknown_key",
                           edit("    order: 7", "    ordre: 7"),
                           {"m.yaml:", "guidance.planner.ordre", "unknown key"}},
        td::test::BadInput{"missing_airframe",
                           edit("airframe: ../airframes/quad180.yaml", "airframe: nowhere.yaml"),
                           {"m.yaml:", "drone.airframe", "nowhere.yaml"}},
        td::test::BadInput{"duplicate_key", text() + "timeout: 30\n", {"m.yaml:", "timeout", "duplicate key"}},
        td::test::BadInput{"dropout_one", edit("dropout: 0.02", "dropout: 1.0"), {"m.yaml:", "link.dropout"}},
        td::test::BadInput{"not_a_mapping", "- 1\n- 2\n", {"m.yaml", "expected a mapping"}},
        td::test::BadInput{"unknown_perception",
                           edit("  mode: model ", "  mode: telepathy "),
                           {"m.yaml:76:", "perception.mode", "unknown 'telepathy' (known: model, render)"}},
        td::test::BadInput{"bad_turbulence",
                           edit("gust_time: 2.0}", "gust_time: 2.0, turbulence: strong}"),
                           {"m.yaml:89:", "wind.turbulence", "none, light, moderate, severe"}},
        td::test::BadInput{"fast_turning_wind",
                           edit("gust_time: 2.0}", "gust_time: 2.0, turn_rate_deg: 90}"),
                           {"m.yaml:", "wind.turn_rate_deg", "[-30, 30]"}},
        td::test::BadInput{"negative_log_smoothing",
                           edit("  counter_clockwise: true", "  log_smoothing: -1\n  counter_clockwise: true"),
                           {"m.yaml:16:", "vehicle.log_smoothing", "[0, 10]"}},
        td::test::BadInput{"bad_flag",
                           edit("counter_clockwise: true", "counter_clockwise: yes please"),
                           {"m.yaml:16:", "vehicle.counter_clockwise", "true or false"}}),
    td::test::bad_input_name);
