// The search module's enum names (core/enum_names.hpp): methods as
// landing_fuzz and campaign.json spell them, gene groups and shrink
// statuses as the shrink report writes them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/search/chromosome.hpp"
#include "touchdown/search/search.hpp"
#include "touchdown/search/shrink.hpp"

namespace td = touchdown;
namespace tsr = touchdown::search;

using SearchEnums = ::testing::Types<tsr::Method, tsr::GeneGroup, tsr::ShrinkStatus, tsr::SeedPool>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Search, EnumNamesSuite, SearchEnums);
}  // namespace touchdown::test

TEST(SearchEnumNames, NamesAreTheCommandLinesAndFilesSpellings) {
  EXPECT_EQ(tsr::to_string(tsr::Method::Rlaga), "rlaga");
  EXPECT_EQ(tsr::to_string(tsr::Method::ManyObjectiveGa), "many-objective-ga");
  EXPECT_EQ(tsr::to_string(tsr::GeneGroup::DynamicObject), "dynamic_object");
  EXPECT_EQ(tsr::to_string(tsr::ShrinkStatus::NotViolating), "not_violating");
  EXPECT_EQ(td::enum_name(tsr::SeedPool::Cover), "cover");  // campaign.json's diversity.pool
  td::test::expect_bad_name<tsr::Method>("nsga2",
                                         "expected one of rlaga, diverse-ga, many-objective-ga, random; got 'nsga2'");
}
