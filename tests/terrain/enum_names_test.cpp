// The terrain module's enum names (core/enum_names.hpp): one table per enum,
// spelled as the CLI (--agg, --unknown-fill, terrain_synth KIND) reads them.
#include <gtest/gtest.h>

#include "enum_names_suite.hpp"
#include "test_util.hpp"
#include "touchdown/terrain/frame_check.hpp"
#include "touchdown/terrain/height_map.hpp"
#include "touchdown/terrain/synthetic.hpp"
#include "touchdown/terrain/terrain_mesher.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;

using TerrainEnums = ::testing::Types<tt::CellAggregate, tt::UnknownFill, tt::CellState, tt::TerrainStatus,
                                      tt::FrameRule, tt::synthetic::ShapeKind>;
namespace touchdown::test {
INSTANTIATE_TYPED_TEST_SUITE_P(Terrain, EnumNamesSuite, TerrainEnums);
}  // namespace touchdown::test

TEST(TerrainEnumNames, ABadNameListsTheAcceptedNames) {
  td::test::expect_bad_name<tt::CellAggregate>("mean", "expected one of max, median; got 'mean'");
  td::test::expect_bad_name<tt::UnknownFill>("hole", "expected one of block, pit; got 'hole'");
  td::test::expect_bad_name<tt::synthetic::ShapeKind>(
      "crater", "expected one of flat, incline, step, plateau, rubble, post; got 'crater'");
}
