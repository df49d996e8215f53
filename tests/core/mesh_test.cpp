#include "touchdown/core/mesh.hpp"

#include <gtest/gtest.h>

namespace td = touchdown;

namespace {

// Unit cube [0,1]^3, 12 outward-facing triangles.
td::TriangleMesh cube() {
  td::TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                 {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return m;
}

}  // namespace

TEST(Mesh, CubeIsClosedAndOutward) {
  const auto c = td::check_closedness(cube());
  EXPECT_EQ(c.edges, 18u);
  EXPECT_TRUE(c.watertight());
  EXPECT_TRUE(c.consistently_oriented());
  EXPECT_NEAR(td::signed_volume(cube()), 1.0, 1e-12);
}

TEST(Mesh, FlippedTriangleIsMisoriented) {
  auto m = cube();
  std::swap(m.triangles[3][0], m.triangles[3][1]);
  const auto c = td::check_closedness(m);
  EXPECT_TRUE(c.watertight());
  EXPECT_FALSE(c.consistently_oriented());
  EXPECT_EQ(c.misoriented_edges, 3u);
}

TEST(Mesh, MissingTriangleLeavesBoundary) {
  auto m = cube();
  m.triangles.pop_back();
  const auto c = td::check_closedness(m);
  EXPECT_FALSE(c.watertight());
  EXPECT_EQ(c.boundary_edges, 3u);
}

TEST(Mesh, DuplicatedTriangleIsNonManifold) {
  auto m = cube();
  m.triangles.push_back(m.triangles[0]);
  const auto c = td::check_closedness(m);
  EXPECT_FALSE(c.watertight());
  EXPECT_EQ(c.nonmanifold_edges, 3u);
}

TEST(Mesh, TriangleSoupIsWeldedByPosition) {
  // Unindexed soup, as an STL file stores it.
  const auto m = cube();
  td::TriangleMesh soup;
  for (const auto& t : m.triangles) {
    const auto base = static_cast<std::uint32_t>(soup.vertices.size());
    for (int k = 0; k < 3; ++k) soup.vertices.push_back(m.vertices[t[static_cast<std::size_t>(k)]]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  EXPECT_EQ(td::weld_vertices(soup).vertices.size(), 8u);
  EXPECT_TRUE(td::check_closedness(soup).consistently_oriented());
  const auto b = td::bounds_of(soup);
  EXPECT_EQ(b.min, Eigen::Vector3d(0, 0, 0));
  EXPECT_EQ(b.max, Eigen::Vector3d(1, 1, 1));
}
