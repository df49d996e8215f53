#include "touchdown/core/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace td = touchdown;
using td::test::TempDir;

namespace {

// A closed tetrahedron with non-trivial coordinates.
td::TriangleMesh tetra() {
  td::TriangleMesh m;
  m.vertices = {{0.125f, -0.5f, 0.f}, {1.5f, 0.25f, 0.f}, {0.f, 1.f, 0.f}, {0.5f, 0.375f, 0.875f}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  return m;
}

std::vector<Eigen::Vector3f> sorted_vertices(const td::TriangleMesh& m) {
  auto v = td::weld_vertices(m).vertices;
  std::sort(v.begin(), v.end(),
            [](const auto& a, const auto& b) { return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z()); });
  return v;
}

}  // namespace

TEST(MeshIo, RoundTripEveryFormat) {
  TempDir dir;
  const auto m = tetra();
  ASSERT_GT(td::signed_volume(m), 0);
  const std::vector<std::pair<std::string, td::MeshFormat>> cases = {{"a.stl", td::MeshFormat::StlBinary},
                                                                     {"b.stl", td::MeshFormat::StlAscii},
                                                                     {"c.ply", td::MeshFormat::PlyBinary},
                                                                     {"d.ply", td::MeshFormat::PlyAscii},
                                                                     {"e.obj", td::MeshFormat::Obj}};
  for (const auto& [name, fmt] : cases) {
    SCOPED_TRACE(name);
    td::write_mesh(m, dir / name, fmt);
    const auto back = td::read_mesh(dir / name);
    EXPECT_EQ(back.triangles.size(), 4u);
    EXPECT_EQ(sorted_vertices(back), sorted_vertices(m));
    EXPECT_TRUE(td::check_closedness(back).consistently_oriented());
    EXPECT_NEAR(td::signed_volume(back), td::signed_volume(m), 1e-6);
  }
  EXPECT_EQ(dir.files().size(), cases.size());  // no .mtl, no temporaries
}

TEST(MeshIo, DefaultStlIsBinary) {
  TempDir dir;
  td::write_mesh(tetra(), dir / "t.stl");
  // Binary STL: 80-byte header + count + 50 bytes a triangle.
  EXPECT_EQ(std::filesystem::file_size(dir / "t.stl"), 84u + 4u * 50u);
}

TEST(MeshIoBadInput, Errors) {
  TempDir dir;
  td::test::write_text(dir / "junk.stl", "solid x\n facet normal 0 0 1\n outer loop\n vertex 1 2\n");
  EXPECT_THROW(td::read_mesh(dir / "junk.stl"), td::ParseError);
  EXPECT_THROW(td::read_mesh(dir / "missing.stl"), td::IoError);
  EXPECT_THROW(td::write_mesh(tetra(), dir / "x.dae"), td::InvalidArgument);
  try {
    td::write_mesh(tetra(), dir / "no" / "x.stl");
    FAIL() << "expected IoError";
  } catch (const td::IoError& e) {
    EXPECT_NE(std::string(e.what()).find("output directory"), std::string::npos);
  }
  EXPECT_EQ(dir.files().size(), 1u);  // only junk.stl
}
