// The mission module's enum names (core/enum_names.hpp): the vehicle's
// path as mission files and landing_mission spell it, outcomes, states and
// transition reasons as the mission's JSON and trace write them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/state_machine.hpp"
#include "touchdown/mission/vehicle.hpp"
#include "touchdown/mission/wind.hpp"

namespace td = touchdown;
namespace tmi = touchdown::mission;

using MissionEnums = ::testing::Types<tmi::VehiclePath, tmi::MissionOutcome, tmi::MissionState, tmi::TransitionReason,
                                      tmi::TurbulenceLevel, tmi::VehicleModel>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Mission, EnumNamesSuite, MissionEnums);
}  // namespace touchdown::test

TEST(MissionEnumNames, NamesAreTheFilesAndOutputsSpellings) {
  EXPECT_EQ(tmi::to_string(tmi::VehiclePath::FigureEight), "figure_eight");
  EXPECT_EQ(tmi::to_string(tmi::MissionOutcome::Timeout), "timeout");
  EXPECT_EQ(tmi::to_string(tmi::MissionState::Rendezvous), "rendezvous");
  EXPECT_EQ(tmi::to_string(tmi::TransitionReason::TrackerLocked), "tracker_locked");
  td::test::expect_bad_name<tmi::VehiclePath>(
      "figure-eight", "expected one of circle, line, figure_eight, random, log, road; got 'figure-eight'");
}
