// The twin module's enum names (core/enum_names.hpp): statuses as the JSON
// and CSV outputs write them, options as landing_sweep reads them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/sweep.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

using TwinEnums = ::testing::Types<tw::RunStatus, tw::SafetyMetric, tw::UnsafeReason, tw::SweepStatus,
                                   tw::SearchPreference, tw::HeadingFlown, tw::TerrainContact>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Twin, EnumNamesSuite, TwinEnums);
}  // namespace touchdown::test

TEST(TwinEnumNames, ABadNameListsTheAcceptedNames) {
  td::test::expect_bad_name<tw::SafetyMetric>("best", "expected one of full, seed; got 'best'");
  td::test::expect_bad_name<tw::SearchPreference>("lowest_score",
                                                  "expected one of lowest, nearest; got 'lowest_score'");
}
