#include "touchdown/terrain/height_map.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;

namespace {

// Points on the plane z = 0.1 x - 0.05 y + 0.3 at every 5 mm over [0, 1)^2.
td::PointCloud plane_cloud() {
  td::PointCloud c;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      const double x = 0.0025 + i * 0.005, y = 0.0025 + j * 0.005;
      c.points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(0.1 * x - 0.05 * y + 0.3));
    }
  c.mark_unorganized();
  return c;
}

double plane(double x, double y) { return 0.1 * x - 0.05 * y + 0.3; }

}  // namespace

TEST(HeightMap, MedianOfAPlaneIsThePlaneAtCellCentres) {
  tt::HeightMapOptions o;
  o.cell = 0.02;
  const auto m = tt::build_height_map(plane_cloud(), o);
  EXPECT_EQ(m.nx(), 50);
  EXPECT_EQ(m.ny(), 50);
  EXPECT_EQ(m.count(tt::CellState::Measured), 2500u);
  for (int j = 0; j < m.ny(); j += 7)
    for (int i = 0; i < m.nx(); i += 7) EXPECT_NEAR(m.height(i, j), plane(m.centre_x(i), m.centre_y(j)), 1e-6);
  EXPECT_NEAR(*m.height_at(0.511, 0.333), plane(0.511, 0.333), 1e-6);
  EXPECT_FALSE(m.height_at(-1, 0).has_value());
}

TEST(HeightMap, MaxAndMedianAggregates) {
  td::PointCloud c;
  c.points = {{0.005f, 0.005f, 1}, {0.006f, 0.004f, 5}, {0.004f, 0.006f, 2}, {0.003f, 0.003f, 4}, {0.031f, 0.031f, 7}};
  c.mark_unorganized();
  tt::HeightMapOptions o;
  o.cell = 0.02;
  o.aggregate = tt::CellAggregate::Max;
  EXPECT_EQ(tt::build_height_map(c, o).height(0, 0), 5.f);
  o.aggregate = tt::CellAggregate::Median;
  const auto m = tt::build_height_map(c, o);
  EXPECT_EQ(m.height(0, 0), 3.f);  // median of {1, 2, 4, 5}
  EXPECT_EQ(m.height(1, 1), 7.f);
  EXPECT_FALSE(m.valid(1, 0));
}

TEST(HeightMap, TooLargeGridIsRefused) {
  td::PointCloud c;
  c.points = {{0, 0, 0}, {1000, 1000, 0}};
  c.mark_unorganized();
  EXPECT_THROW(tt::build_height_map(c, tt::HeightMapOptions{}), td::InvalidArgument);
}

TEST(HeightMap, SmallGapsAreFilledExactlyOnAPlaneAndLargeOnesReported) {
  tt::HeightMapOptions o;
  o.cell = 0.02;
  auto m = tt::build_height_map(plane_cloud(), o);
  // Punch a 3x3-cell hole (6 cm) and a 10x10-cell hole (20 cm).
  const float nan = NAN;
  for (int j = 10; j < 13; ++j)
    for (int i = 10; i < 13; ++i) m.set(i, j, nan, tt::CellState::Empty);
  for (int j = 30; j < 40; ++j)
    for (int i = 30; i < 40; ++i) m.set(i, j, nan, tt::CellState::Empty);
  // And clear the border column: outside the footprint, never filled.
  for (int j = 0; j < m.ny(); ++j) m.set(0, j, nan, tt::CellState::Empty);
  const auto r = tt::fill_holes(m, 0.10);
  for (int j = 10; j < 13; ++j)
    for (int i = 10; i < 13; ++i) {
      ASSERT_EQ(m.state(i, j), tt::CellState::Filled);
      EXPECT_NEAR(m.height(i, j), plane(m.centre_x(i), m.centre_y(j)), 1e-5);
    }
  EXPECT_EQ(m.state(35, 35), tt::CellState::Empty);
  EXPECT_FALSE(m.valid(0, 25));
  EXPECT_EQ(r.large_holes, 1u);
  EXPECT_GT(r.large_hole_cells, 0u);
  EXPECT_LT(r.large_hole_cells, 100u);  // its rim was partly filled
  EXPECT_EQ(r.filled_cells, 9u + (100u - r.large_hole_cells));
}

TEST(HeightMap, NoFillingWithZeroGap) {
  auto m = tt::build_height_map(plane_cloud(), tt::HeightMapOptions{});
  m.set(5, 5, NAN, tt::CellState::Empty);
  const auto r = tt::fill_holes(m, 0.0);
  EXPECT_EQ(r.filled_cells, 0u);
  EXPECT_EQ(r.large_holes, 1u);
}

TEST(TriangulateSolid, FlatMapIsAClosedSlab) {
  tt::HeightMap m(0, 0, 0.1, 5, 4);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 5; ++i) m.set(i, j, 1.0f, tt::CellState::Measured);
  const auto mesh = tt::triangulate_solid(m, 0.5);
  const auto c = td::check_closedness(mesh);
  EXPECT_TRUE(c.watertight());
  EXPECT_TRUE(c.consistently_oriented());
  // Surface over the cell centres: 0.4 x 0.3 m, 0.5 m thick.
  EXPECT_NEAR(td::signed_volume(mesh), 0.4 * 0.3 * 0.5, 1e-6);
  EXPECT_EQ(mesh.triangles.size(), 2u * 12 + 2u * 12 + 2u * 14);
}

TEST(TriangulateSolid, RandomMasksAlwaysGiveClosedOrientedSolids) {
  // Property test: holes, islands and diagonal pinches in random masks.
  for (std::uint64_t seed = 0; seed < 60; ++seed) {
    td::Rng rng(seed);
    const int nx = 3 + static_cast<int>(rng.uniform() * 12), ny = 3 + static_cast<int>(rng.uniform() * 12);
    const double keep = rng.uniform(0.3, 0.95);
    tt::HeightMap m(-0.3, 0.2, 0.05, nx, ny);
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if (rng.uniform() < keep) m.set(i, j, static_cast<float>(rng.uniform(0, 0.2)), tt::CellState::Measured);
    const auto mesh = tt::triangulate_solid(m, 0.1);
    if (mesh.empty()) continue;
    const auto c = td::check_closedness(mesh);
    ASSERT_TRUE(c.watertight()) << "seed " << seed << ": " << c.boundary_edges << " boundary, " << c.nonmanifold_edges
                                << " non-manifold";
    ASSERT_TRUE(c.consistently_oriented()) << "seed " << seed;
    ASSERT_EQ(c.degenerate_triangles, 0u);
    EXPECT_GT(td::signed_volume(mesh), 0) << "seed " << seed;
  }
}

TEST(TriangulateSolid, TopSurfaceInterpolatesTheCells) {
  tt::HeightMap m(0, 0, 0.02, 6, 6);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 6; ++i)
      m.set(i, j, static_cast<float>(0.3 * m.centre_x(i) + 0.1 * m.centre_y(j)), tt::CellState::Measured);
  const auto mesh = tt::triangulate_solid(m, 0.05);
  for (double x : {0.015, 0.033, 0.07, 0.1}) {
    for (double y : {0.011, 0.05, 0.099}) {
      EXPECT_NEAR(td::test::mesh_top_z(mesh, x, y), 0.3 * x + 0.1 * y, 1e-6);
    }
  }
  EXPECT_TRUE(std::isnan(td::test::mesh_top_z(mesh, 0.005, 0.05)));  // outside the centres
}

TEST(HeightMapOptions, ValidateNamesTheField) {
  using O = tt::HeightMapOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"cell:", [](O& o) { o.cell = 0; }},
      {"cell:", [](O& o) { o.cell = std::numeric_limits<double>::infinity(); }},
      {"max_hole:", [](O& o) { o.max_hole = -1; }},
      {"max_fill_slope:", [](O& o) { o.max_fill_slope = 0; }},
      {"max_cells:", [](O& o) { o.max_cells = 0; }},
  });
}

// Issue 58 item 4: a cloud in millimetres was refused with only the cell
// count; now the message says what the span suggests.
TEST(HeightMap, ACloudInMillimetresIsNamedAsSuch) {
  td::PointCloud mm = plane_cloud();
  for (auto& p : mm.points) {  // a 2.4 m x 1.35 m scene written in mm
    p.x() *= 2400.0F;
    p.y() *= 1350.0F;
    p.z() *= 1000.0F;
  }
  tt::HeightMapOptions o;
  o.cell = 0.02;
  std::string why;
  try {
    (void)tt::build_height_map(mm, o);
  } catch (const td::InvalidArgument& e) {
    why = e.what();
  }
  EXPECT_NE(why.find("height map would need "), std::string::npos) << why;
  EXPECT_NE(why.find(" cells (cloud spans 2388 x 1343 m)"), std::string::npos) << why;
  EXPECT_NE(why.find("likely in millimetres: scale it by 0.001"), std::string::npos) << why;
  // A large cloud in metres that fits is built, and a merely too fine cell
  // over a metre-sized scan does not speak of millimetres.
  o.cell = 0.00002;
  why.clear();
  try {
    (void)tt::build_height_map(plane_cloud(), o);
  } catch (const td::InvalidArgument& e) {
    why = e.what();
  }
  EXPECT_NE(why.find("crop the cloud or use a larger cell"), std::string::npos) << why;
  EXPECT_EQ(why.find("millimetres"), std::string::npos) << why;
}
