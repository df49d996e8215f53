// The twin module's enum names (core/enum_names.hpp): statuses as the JSON
// and CSV outputs write them, options as landing_sweep reads them.
#include <gtest/gtest.h>

#include "test_util.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/sweep.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

TEST(TwinEnumNames, EveryEnumeratorRoundTripsThroughItsName) {
  td::test::expect_names_round_trip<tw::RunStatus>();
  td::test::expect_names_round_trip<tw::SafetyMetric>();
  td::test::expect_names_round_trip<tw::UnsafeReason>();
  td::test::expect_names_round_trip<tw::SweepStatus>();
  td::test::expect_names_round_trip<tw::SearchPreference>();
  // A safe heading has no reason: the empty name.
  EXPECT_EQ(tw::to_string(tw::UnsafeReason::None), "");
  EXPECT_EQ(tw::to_string(tw::UnsafeReason::AboveThreshold), "S above the threshold");
}

TEST(TwinEnumNames, ABadNameListsTheAcceptedNames) {
  td::test::expect_bad_name<tw::SafetyMetric>("best", "expected one of full, seed; got 'best'");
  td::test::expect_bad_name<tw::SearchPreference>("lowest_score",
                                                  "expected one of lowest, nearest; got 'lowest_score'");
}
