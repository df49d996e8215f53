// The plan module's enum names (core/enum_names.hpp), as landing_plan's JSON
// and summaries write them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/plan/corridor.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/qp.hpp"

namespace td = touchdown;
namespace tp = touchdown::plan;

using PlanEnums = ::testing::Types<tp::QpStatus, tp::ConstraintGroup, tp::PlanStatus, tp::CorridorStatus>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Plan, EnumNamesSuite, PlanEnums);
}  // namespace touchdown::test
