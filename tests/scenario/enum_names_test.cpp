// The scenario module's enum names (core/enum_names.hpp): kinds as scenario
// files and the command line spell them, violation types as the run's JSON
// and the campaign CSV print them, the reference systems' phases as the run
// log writes them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "scenario/opencv_mls.hpp"
#include "test_util.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/dataset.hpp"
#include "touchdown/scenario/geometry.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/world.hpp"

namespace td = touchdown;
namespace ts = touchdown::scenario;

using ScenarioEnums =
    ::testing::Types<ts::MapKind, ts::DistractorKind, ts::StaticKind, ts::DynamicKind, ts::MotionKind, ts::Violation,
                     ts::ObjectAction, ts::Solid::Shape, ts::Label, ts::Sight, ts::detail::MlsPhase, ts::DatasetSplit>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Scenario, EnumNamesSuite, ScenarioEnums);
}  // namespace touchdown::test

TEST(ScenarioEnumNames, NamesAreTheFilesAndOutputsSpellings) {
  EXPECT_EQ(ts::to_string(ts::MapKind::Ground), "ground");
  EXPECT_EQ(ts::to_string(ts::DistractorKind::WrongId), "wrong_id");
  EXPECT_EQ(ts::to_string(ts::MotionKind::External), "external");
  // The paper's roman numerals, as the JSON "type" and the campaign CSV print them.
  EXPECT_EQ(ts::to_string(ts::Violation::None), "none");
  EXPECT_EQ(ts::to_string(ts::Violation::TypeIII), "III");
  EXPECT_EQ(ts::to_string(ts::Violation::OffMarker), "off-marker");
  EXPECT_EQ(ts::to_string(ts::Sight::LowContrast), "low-contrast");
  EXPECT_EQ(ts::detail::to_string(ts::detail::MlsPhase::Approach), "approach");
}

TEST(ScenarioEnumNames, MaskValuesAreTheLabelsNumbers) {
  EXPECT_EQ(ts::mask_value(ts::Label::Ground), 0);
  EXPECT_EQ(ts::mask_value(ts::Label::Marker), 1);
  EXPECT_EQ(ts::mask_value(ts::Label::Distractor), 2);
  EXPECT_EQ(ts::mask_value(ts::Label::StaticObject), 3);
  EXPECT_EQ(ts::mask_value(ts::Label::DynamicObject), 4);
  EXPECT_EQ(ts::mask_value(ts::Label::Sky), 5);
}

TEST(ScenarioEnumNames, ABadNameListsTheAcceptedNames) {
  td::test::expect_bad_name<ts::MapKind>("moon", "expected one of ground, lawn; got 'moon'");
  td::test::expect_bad_name<ts::StaticKind>("lamp", "expected one of box, chair, pole, tree; got 'lamp'");
  td::test::expect_bad_name<ts::Violation>("type_i",
                                           "expected one of none, I, II, III, off-marker, system-failed; got 'type_i'");
}
