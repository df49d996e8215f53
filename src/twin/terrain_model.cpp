#include "touchdown/twin/terrain_model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>

#include "touchdown/core/cloud_io.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/mesh_io.hpp"

namespace touchdown::twin {

UnknownCells UnknownCells::of(const terrain::HeightMap& map) {
  UnknownCells u;
  if (map.count(terrain::CellState::Unknown) == 0) return u;
  u.x0 = map.x0();
  u.y0 = map.y0();
  u.cell = map.cell();
  u.nx = map.nx();
  u.ny = map.ny();
  u.unknown.resize(static_cast<std::size_t>(u.nx) * u.ny);
  for (int j = 0; j < u.ny; ++j)
    for (int i = 0; i < u.nx; ++i) u.unknown[map.index(i, j)] = map.state(i, j) == terrain::CellState::Unknown;
  return u;
}

TerrainModel::TerrainModel(TriangleMesh mesh, UnknownCells unknown)
    : mesh_(std::move(mesh)), unknown_(std::move(unknown)) {
  if (mesh_.triangles.empty()) throw InvalidArgument("terrain mesh has no triangles");
  if (!unknown_.empty() && (unknown_.nx <= 0 || unknown_.ny <= 0 || !(unknown_.cell > 0) ||
                            unknown_.unknown.size() != static_cast<std::size_t>(unknown_.nx) * unknown_.ny)) {
    throw InvalidArgument("terrain unknown-cell grid: size does not match nx x ny");
  }
  bounds_ = bounds_of(mesh_);
  const std::size_t n = mesh_.triangles.size();
  geometry_.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    TriangleGeometry& g = geometry_[t];
    for (std::size_t k = 0; k < 3; ++k) g.v[k] = mesh_.vertices[mesh_.triangles[t][k]].cast<double>();
    const Eigen::Vector3d normal = (g.v[1] - g.v[0]).cross(g.v[2] - g.v[0]);
    const double len = normal.norm();
    g.n = len > 0 ? Eigen::Vector3d(normal / len) : Eigen::Vector3d::UnitZ();
  }
  {
    std::vector<Eigen::Vector3d> normals(n);
    for (std::size_t t = 0; t < n; ++t) normals[t] = geometry_[t].n;
    height_field_ = HeightField::detect(mesh_, normals);
  }
  std::vector<Eigen::AlignedBox3f> tri_box(n);  // construction only: the buckets keep their own copies
  double edge_sum = 0;
  for (std::size_t t = 0; t < n; ++t) {
    Eigen::AlignedBox3f b;
    for (int k = 0; k < 3; ++k) b.extend(mesh_.vertices[mesh_.triangles[t][static_cast<std::size_t>(k)]]);
    tri_box[t] = b;
    edge_sum += std::max(b.sizes().x(), b.sizes().y());
  }
  // Buckets about twice the typical triangle extent, and not too many.
  const double span_x = bounds_.max.x() - bounds_.min.x(), span_y = bounds_.max.y() - bounds_.min.y();
  cell_ = std::max({2.0 * edge_sum / static_cast<double>(n), 1e-3, std::sqrt(span_x * span_y / 4e6)});
  x0_ = bounds_.min.x();
  y0_ = bounds_.min.y();
  nx_ = static_cast<int>(span_x / cell_) + 1;
  ny_ = static_cast<int>(span_y / cell_) + 1;
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;
  std::vector<std::uint32_t> count(cells + 1, 0);
  auto range = [&](const Eigen::AlignedBox3f& b, int& i0, int& i1, int& j0, int& j1) {
    i0 = std::clamp(static_cast<int>((b.min().x() - x0_) / cell_), 0, nx_ - 1);
    i1 = std::clamp(static_cast<int>((b.max().x() - x0_) / cell_), 0, nx_ - 1);
    j0 = std::clamp(static_cast<int>((b.min().y() - y0_) / cell_), 0, ny_ - 1);
    j1 = std::clamp(static_cast<int>((b.max().y() - y0_) / cell_), 0, ny_ - 1);
  };
  tri_cell_.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    int i0, i1, j0, j1;
    range(tri_box[t], i0, i1, j0, j1);
    tri_cell_[t] = {i0, j0};
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) ++count[static_cast<std::size_t>(j) * nx_ + i + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
  start_ = count;
  items_.resize(count.back());
  cell_max_z_.assign(cells, -std::numeric_limits<float>::infinity());
  for (std::size_t t = 0; t < n; ++t) {
    int i0, i1, j0, j1;
    range(tri_box[t], i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const std::size_t c = static_cast<std::size_t>(j) * nx_ + i;
        items_[count[c]++] = {tri_box[t], static_cast<std::uint32_t>(t)};
        cell_max_z_[c] = std::max(cell_max_z_[c], tri_box[t].max().z());
      }
  }
  bx_ = (nx_ + kBlock - 1) / kBlock;
  by_ = (ny_ + kBlock - 1) / kBlock;
  block_max_z_.assign(static_cast<std::size_t>(bx_) * by_, -std::numeric_limits<float>::infinity());
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      float& b = block_max_z_[static_cast<std::size_t>(j / kBlock) * bx_ + i / kBlock];
      b = std::max(b, cell_max_z_[static_cast<std::size_t>(j) * nx_ + i]);
    }
  }
  // Highest triangles first in each bucket: a query stops at the first one
  // entirely below it (the terrain solid's bottom is never visited).
  for (std::size_t c = 0; c < cells; ++c) {
    std::sort(items_.begin() + start_[c], items_.begin() + start_[c + 1], [](const Item& a, const Item& b) {
      const float za = a.box.max().z(), zb = b.box.max().z();
      return za > zb || (za == zb && a.triangle < b.triangle);
    });
  }
}

double TerrainModel::max_z_near(const Eigen::AlignedBox3d& box) const {
  if (box.max().x() < bounds_.min.x() || box.min().x() > bounds_.max.x() || box.max().y() < bounds_.min.y() ||
      box.min().y() > bounds_.max.y()) {
    return -std::numeric_limits<double>::infinity();
  }
  const int i0 = std::clamp(static_cast<int>((box.min().x() - x0_) / cell_), 0, nx_ - 1);
  const int i1 = std::clamp(static_cast<int>((box.max().x() - x0_) / cell_), 0, nx_ - 1);
  const int j0 = std::clamp(static_cast<int>((box.min().y() - y0_) / cell_), 0, ny_ - 1);
  const int j1 = std::clamp(static_cast<int>((box.max().y() - y0_) / cell_), 0, ny_ - 1);
  // Whole blocks inside the range from the block maxima, the buckets of
  // the blocks it only partly covers one by one: the same maximum as a
  // walk over every bucket.
  float z = -std::numeric_limits<float>::infinity();
  for (int bj = j0 / kBlock; bj <= j1 / kBlock; ++bj) {
    const int cj0 = std::max(j0, bj * kBlock), cj1 = std::min(j1, bj * kBlock + kBlock - 1);
    for (int bi = i0 / kBlock; bi <= i1 / kBlock; ++bi) {
      const int ci0 = std::max(i0, bi * kBlock), ci1 = std::min(i1, bi * kBlock + kBlock - 1);
      const float block = block_max_z_[static_cast<std::size_t>(bj) * bx_ + bi];
      if (block <= z) continue;
      const bool whole =
          cj1 - cj0 + 1 == std::min(kBlock, ny_ - bj * kBlock) && ci1 - ci0 + 1 == std::min(kBlock, nx_ - bi * kBlock);
      if (whole) {
        z = block;
        continue;
      }
      for (int j = cj0; j <= cj1; ++j)
        for (int i = ci0; i <= ci1; ++i) z = std::max(z, cell_max_z_[static_cast<std::size_t>(j) * nx_ + i]);
    }
  }
  return z;
}

void TerrainModel::triangles_overlapping(const Eigen::AlignedBox3d& box, std::vector<std::uint32_t>& out) const {
  if (box.max().x() < bounds_.min.x() || box.min().x() > bounds_.max.x() || box.max().y() < bounds_.min.y() ||
      box.min().y() > bounds_.max.y() || box.min().z() > bounds_.max.z() || box.max().z() < bounds_.min.z()) {
    return;
  }
  const int i0 = std::clamp(static_cast<int>((box.min().x() - x0_) / cell_), 0, nx_ - 1);
  const int i1 = std::clamp(static_cast<int>((box.max().x() - x0_) / cell_), 0, nx_ - 1);
  const int j0 = std::clamp(static_cast<int>((box.min().y() - y0_) / cell_), 0, ny_ - 1);
  const int j1 = std::clamp(static_cast<int>((box.max().y() - y0_) / cell_), 0, ny_ - 1);
  const Eigen::AlignedBox3f fb = box.cast<float>();
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const std::size_t c = static_cast<std::size_t>(j) * nx_ + i;
      if (cell_max_z_[c] < fb.min().z()) continue;
      for (std::uint32_t s = start_[c]; s < start_[c + 1]; ++s) {
        const Item& item = items_[s];
        if (item.box.max().z() < fb.min().z()) break;  // sorted: the rest are lower
        if (!item.box.intersects(fb)) continue;
        const std::uint32_t t = item.triangle;
        // A triangle listed in several buckets is reported once: from the
        // first bucket of the query that it occupies.
        const auto& cell0 = tri_cell_[t];
        if (std::max(i0, cell0[0]) == i && std::max(j0, cell0[1]) == j) out.push_back(t);
      }
    }
  }
}

std::optional<double> TerrainModel::top_z(double x, double y) const {
  std::vector<std::uint32_t> tris;
  const Eigen::AlignedBox3d column(Eigen::Vector3d(x, y, bounds_.min.z() - 1),
                                   Eigen::Vector3d(x, y, bounds_.max.z() + 1));
  triangles_overlapping(column, tris);
  std::optional<double> best;
  for (std::uint32_t t : tris) {
    const Eigen::Vector3d a = vertex(t, 0), b = vertex(t, 1), c = vertex(t, 2);
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (std::abs(det) < 1e-15) continue;  // vertical
    const double l1 = ((x - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
    const double l2 = ((b.x() - a.x()) * (y - a.y()) - (x - a.x()) * (b.y() - a.y())) / det;
    const double l0 = 1 - l1 - l2;
    constexpr double eps = -1e-9;
    if (l0 < eps || l1 < eps || l2 < eps) continue;
    const double z = l0 * a.z() + l1 * b.z() + l2 * c.z();
    if (!best || z > *best) best = z;
  }
  return best;
}

std::optional<double> TerrainModel::max_top_z(const Eigen::Vector2d& centre, double radius, double step) const {
  std::optional<double> best;
  const int n = std::max(1, static_cast<int>(std::ceil(radius / step)));
  for (int j = -n; j <= n; ++j) {
    for (int i = -n; i <= n; ++i) {
      const Eigen::Vector2d p = centre + Eigen::Vector2d(i, j) * (radius / n);
      if ((p - centre).norm() > radius + 1e-12) continue;
      const auto z = top_z(p.x(), p.y());
      if (!z) return std::nullopt;
      if (!best || *z > *best) best = z;
    }
  }
  // Peaks between the samples: any vertex inside the disk that lies on the top surface.
  std::vector<std::uint32_t> tris;
  triangles_overlapping(Eigen::AlignedBox3d(Eigen::Vector3d(centre.x() - radius, centre.y() - radius, bounds_.min.z()),
                                            Eigen::Vector3d(centre.x() + radius, centre.y() + radius, bounds_.max.z())),
                        tris);
  for (std::uint32_t t : tris) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = vertex(t, k);
      if ((v.head<2>() - centre).norm() <= radius && v.z() > *best) {
        const auto z = top_z(v.x(), v.y());
        if (z && *z > *best) best = z;
      }
    }
  }
  return best;
}

namespace {

// Calls hit(centre) for the centre of every unknown cell whose square
// overlaps the axis-aligned box [lo, hi]; stops early when hit returns true.
template <class F>
bool any_unknown_cell(const UnknownCells& u, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, F&& hit) {
  if (u.empty()) return false;
  const int i0 = std::max(0, static_cast<int>(std::floor((lo.x() - u.x0) / u.cell)));
  const int j0 = std::max(0, static_cast<int>(std::floor((lo.y() - u.y0) / u.cell)));
  const int i1 = std::min(u.nx - 1, static_cast<int>(std::floor((hi.x() - u.x0) / u.cell)));
  const int j1 = std::min(u.ny - 1, static_cast<int>(std::floor((hi.y() - u.y0) / u.cell)));
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      if (!u.unknown[static_cast<std::size_t>(j) * u.nx + i]) continue;
      if (hit(Eigen::Vector2d(u.x0 + (i + 0.5) * u.cell, u.y0 + (j + 0.5) * u.cell))) return true;
    }
  }
  return false;
}

}  // namespace

// Both tests below are conservative: a cell counts when its centre is
// within the shape's reach plus the cell's half diagonal, so a cell whose
// corner only nearly touches the shape (by < 0.41 cell) is also counted.
// For terrain nobody has seen, erring towards "unknown" is the safe side.
bool TerrainModel::unknown_near(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius) const {
  const double reach = radius + 0.5 * unknown_.cell * std::numbers::sqrt2;
  const Eigen::Vector2d lo = a.cwiseMin(b).array() - reach, hi = a.cwiseMax(b).array() + reach;
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  return any_unknown_cell(unknown_, lo, hi, [&](const Eigen::Vector2d& c) {
    const double t = len2 > 0 ? std::clamp((c - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (a + t * ab - c).norm() <= reach;
  });
}

bool TerrainModel::unknown_in_box(const Eigen::Vector2d& centre, const Eigen::Vector2d& half, double yaw,
                                  double pad) const {
  const double reach = pad + 0.5 * unknown_.cell * std::numbers::sqrt2;
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  const double ex = std::abs(cy) * half.x() + std::abs(sy) * half.y() + reach;
  const double ey = std::abs(sy) * half.x() + std::abs(cy) * half.y() + reach;
  return any_unknown_cell(unknown_, centre - Eigen::Vector2d(ex, ey), centre + Eigen::Vector2d(ex, ey),
                          [&](const Eigen::Vector2d& c) {
                            const Eigen::Vector2d d = c - centre;
                            const Eigen::Vector2d local(cy * d.x() + sy * d.y(), -sy * d.x() + cy * d.y());
                            const Eigen::Vector2d out = (local.cwiseAbs() - half).cwiseMax(0.0);
                            return out.norm() <= reach;
                          });
}

TerrainFile read_terrain_file(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  TerrainFile file;
  file.path = path;
  if (ext == ".stl" || ext == ".obj") {
    file.mesh = read_mesh(path);
    return file;
  }
  if (ext == ".ply") {
    try {
      file.mesh = read_mesh(path);
      return file;
    } catch (const ParseError&) {
      // A PLY without faces is a point cloud.
    }
  }
  file.cloud = read_cloud(path);
  if (file.cloud.empty()) throw ParseError(path.string() + ": the point cloud is empty");
  return file;
}

std::shared_ptr<const TerrainModel> make_terrain_model(TerrainFile file, const terrain::TerrainOptions& cloud_options) {
  if (file.mesh) return std::make_shared<const TerrainModel>(std::move(*file.mesh));
  auto result = terrain::mesh_terrain(std::move(file.cloud), cloud_options);
  if (!result.ok()) throw InvalidArgument(file.path.string() + ": " + result.message);
  return std::make_shared<const TerrainModel>(std::move(result.mesh), UnknownCells::of(result.height_map));
}

std::shared_ptr<const TerrainModel> load_terrain_model(const std::filesystem::path& path,
                                                       const terrain::TerrainOptions& cloud_options) {
  return make_terrain_model(read_terrain_file(path), cloud_options);
}

}  // namespace touchdown::twin
