// The plan module's enum names (core/enum_names.hpp), as landing_plan's JSON
// and summaries write them.
#include <gtest/gtest.h>

#include "test_util.hpp"
#include "touchdown/plan/corridor.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/qp.hpp"

namespace td = touchdown;
namespace tp = touchdown::plan;

TEST(PlanEnumNames, EveryEnumeratorRoundTripsThroughItsName) {
  td::test::expect_names_round_trip<tp::QpStatus>();
  td::test::expect_names_round_trip<tp::ConstraintGroup>();
  td::test::expect_names_round_trip<tp::PlanStatus>();
  td::test::expect_names_round_trip<tp::CorridorStatus>();
  td::test::expect_bad_name<tp::ConstraintGroup>(
      "jerk", "expected one of boundary, corridor, velocity, acceleration; got 'jerk'");
}
