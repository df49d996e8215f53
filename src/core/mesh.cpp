#include "touchdown/core/mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <numeric>
#include <tuple>

namespace touchdown {

TriangleMesh weld_vertices(const TriangleMesh& mesh) {
  const std::size_t n = mesh.vertices.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](std::uint32_t i) {
    const auto& v = mesh.vertices[i];
    return std::make_tuple(v.x(), v.y(), v.z());
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::vector<std::uint32_t> remap(n);
  TriangleMesh out;
  for (std::size_t k = 0; k < n; ++k) {
    if (k == 0 || key(order[k]) != key(order[k - 1])) out.vertices.push_back(mesh.vertices[order[k]]);
    remap[order[k]] = static_cast<std::uint32_t>(out.vertices.size() - 1);
  }
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
  return out;
}

MeshClosedness check_closedness(const TriangleMesh& input) {
  const TriangleMesh mesh = weld_vertices(input);
  MeshClosedness c;
  // (undirected key, +1 if traversed low→high else -1)
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++c.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[static_cast<std::size_t>(k)], b = t[static_cast<std::size_t>((k + 1) % 3)];
      const std::uint64_t lo = std::min(a, b), hi = std::max(a, b);
      edges.emplace_back((lo << 32) | hi, a < b ? 1 : -1);
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    int balance = 0;
    while (j < edges.size() && edges[j].first == edges[i].first) balance += edges[j++].second;
    const std::size_t uses = j - i;
    ++c.edges;
    if (uses == 1)
      ++c.boundary_edges;
    else if (uses > 2)
      ++c.nonmanifold_edges;
    else if (balance != 0)
      ++c.misoriented_edges;
    i = j;
  }
  return c;
}

double signed_volume(const TriangleMesh& mesh) {
  double six_v = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    six_v += a.dot(b.cross(c));
  }
  return six_v / 6.0;
}

Bounds3 bounds_of(const TriangleMesh& mesh) {
  Bounds3 b;
  for (const auto& v : mesh.vertices) b.extend(v.cast<double>());
  return b;
}

}  // namespace touchdown
