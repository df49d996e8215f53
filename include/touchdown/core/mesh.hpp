#pragma once
/// \file
/// Indexed triangle mesh and closedness checks.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace touchdown {

/// An indexed triangle mesh (metres). Triangles are counter-clockwise seen
/// from outside, so normals point out of a closed solid.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  [[nodiscard]] bool empty() const { return triangles.empty(); }
};

/// Edge statistics of a mesh whose vertices are first welded by exact
/// position (so an STL triangle soup is checked as the solid it describes).
struct MeshClosedness {
  std::size_t edges = 0;              ///< undirected edges
  std::size_t boundary_edges = 0;     ///< used by one triangle
  std::size_t nonmanifold_edges = 0;  ///< used by three or more triangles
  std::size_t misoriented_edges = 0;  ///< used twice in the same direction
  std::size_t degenerate_triangles = 0;

  /// Each edge shared by exactly two triangles.
  [[nodiscard]] bool watertight() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
  /// Each shared edge traversed in opposite directions by its two triangles.
  [[nodiscard]] bool consistently_oriented() const { return watertight() && misoriented_edges == 0; }
};

MeshClosedness check_closedness(const TriangleMesh& mesh);

/// Merges vertices with identical coordinates and drops the unused ones.
TriangleMesh weld_vertices(const TriangleMesh& mesh);

/// Signed volume (positive for a closed, outward-oriented solid).
double signed_volume(const TriangleMesh& mesh);

/// Axis-aligned bounds of the vertices; `min > max` for an empty mesh.
struct Bounds3 {
  Eigen::Vector3d min{Eigen::Vector3d::Constant(1e300)};
  Eigen::Vector3d max{Eigen::Vector3d::Constant(-1e300)};
  [[nodiscard]] bool empty() const { return (min.array() > max.array()).any(); }
  void extend(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};
Bounds3 bounds_of(const TriangleMesh& mesh);

}  // namespace touchdown
