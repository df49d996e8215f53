#include "touchdown/terrain/height_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "column_grid.hpp"
#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"

namespace touchdown::terrain {
namespace {

// Calls f(cells) for each 4-connected region of empty cells that does not
// touch the grid border, in scan order of its first cell.
template <class F>
void for_each_enclosed_empty_region(const HeightMap& map, F&& f) {
  const int nx = map.nx(), ny = map.ny();
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(nx) * ny, 0);
  std::vector<std::pair<int, int>> stack;
  std::vector<std::size_t> region;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      if (map.valid(i, j) || seen[map.index(i, j)]) continue;
      bool border = false;
      region.clear();
      stack.assign(1, {i, j});
      seen[map.index(i, j)] = 1;
      while (!stack.empty()) {
        const auto [ci, cj] = stack.back();
        stack.pop_back();
        region.push_back(map.index(ci, cj));
        if (ci == 0 || cj == 0 || ci == nx - 1 || cj == ny - 1) border = true;
        const std::array<std::array<int, 2>, 4> nb{{{ci - 1, cj}, {ci + 1, cj}, {ci, cj - 1}, {ci, cj + 1}}};
        for (const auto& [ni, nj] : nb) {
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
          const std::size_t k = map.index(ni, nj);
          if (seen[k] || map.valid(ni, nj)) continue;
          seen[k] = 1;
          stack.push_back({ni, nj});
        }
      }
      if (!border) f(region);
    }
  }
}

}  // namespace

HeightMap::HeightMap(double x0, double y0, double cell, int nx, int ny)
    : x0_(x0),
      y0_(y0),
      cell_(cell),
      nx_(nx),
      ny_(ny),
      z_(static_cast<std::size_t>(nx) * ny, std::numeric_limits<float>::quiet_NaN()),
      state_(static_cast<std::size_t>(nx) * ny, CellState::Empty) {}

std::size_t HeightMap::count(CellState s) const {
  return static_cast<std::size_t>(std::count(state_.begin(), state_.end(), s));
}

std::optional<double> HeightMap::height_at(double x, double y) const {
  const double u = (x - x0_) / cell_ - 0.5, v = (y - y0_) / cell_ - 0.5;
  const int i = static_cast<int>(std::floor(u)), j = static_cast<int>(std::floor(v));
  const double fu = u - i, fv = v - j;
  double sum = 0, wsum = 0;
  double nearest = std::numeric_limits<double>::quiet_NaN(), nearest_d = 1e300;
  for (int dj = 0; dj <= 1; ++dj) {
    for (int di = 0; di <= 1; ++di) {
      const int ci = i + di, cj = j + dj;
      if (ci < 0 || cj < 0 || ci >= nx_ || cj >= ny_ || !valid(ci, cj)) continue;
      const double w = (di ? fu : 1 - fu) * (dj ? fv : 1 - fv);
      sum += w * height(ci, cj);
      wsum += w;
      const double d = std::hypot(di - fu, dj - fv);
      if (d < nearest_d) {
        nearest_d = d;
        nearest = height(ci, cj);
      }
    }
  }
  if (nearest_d > 1e299) return std::nullopt;
  if (wsum > 1e-9) return sum / wsum;
  return nearest;
}

bool HeightMapOptions::validate(std::string* why) const {
  if (!(cell > 0) || !std::isfinite(cell)) return invalid(why, "cell: must be a positive number of metres");
  if (!(max_hole >= 0) || !std::isfinite(max_hole)) return invalid(why, "max_hole: must be >= 0 m");
  if (!(max_fill_slope > 0)) return invalid(why, "max_fill_slope: must be positive");
  if (max_cells == 0) return invalid(why, "max_cells: must be positive");
  if (!(pit_depth > 0) || !std::isfinite(pit_depth))
    return invalid(why, "pit_depth: must be a positive number of metres");
  return true;
}

namespace {

// A cloud wider than this [m] is taken for millimetres in the message of a
// height map too large to build.
constexpr double kMillimetreSpan = 1000;

}  // namespace

HeightMap build_height_map(const PointCloud& cloud, const HeightMapOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("height map options: " + why);
  if (cloud.empty()) throw InvalidArgument("height map of an empty cloud");
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const auto& p : cloud.points) {
    lo = lo.cwiseMin(p.head<2>().cast<double>());
    hi = hi.cwiseMax(p.head<2>().cast<double>());
  }
  // Cells aligned to multiples of the cell size, so maps of overlapping
  // clouds line up.
  const double x0 = std::floor(lo.x() / o.cell) * o.cell, y0 = std::floor(lo.y() / o.cell) * o.cell;
  const double fx = std::floor((hi.x() - x0) / o.cell) + 1, fy = std::floor((hi.y() - y0) / o.cell) + 1;
  if (fx * fy > static_cast<double>(o.max_cells)) {
    const double span = std::max(hi.x() - lo.x(), hi.y() - lo.y());
    // A landing-site scan spans metres to a few hundred; a thousand times
    // that is a cloud in millimetres (issue 58).
    const std::string units =
        span > kMillimetreSpan ? "; a scan this large is likely in millimetres: scale it by 0.001 to metres" : "";
    throw InvalidArgument("height map would need " + std::to_string(static_cast<long long>(fx)) + " x " +
                          std::to_string(static_cast<long long>(fy)) + " cells (cloud spans " +
                          touchdown::detail::format_general(hi.x() - lo.x(), 4) + " x " +
                          touchdown::detail::format_general(hi.y() - lo.y(), 4) +
                          " m); crop the cloud or use a larger cell" + units);
  }
  HeightMap map(x0, y0, o.cell, static_cast<int>(fx), static_cast<int>(fy));
  detail::ColumnGrid grid;
  grid.build(cloud.points, x0, y0, o.cell, map.nx(), map.ny());
  std::vector<float> zs;
  for (int j = 0; j < map.ny(); ++j) {
    for (int i = 0; i < map.nx(); ++i) {
      zs.clear();
      grid.for_each_in(i, j, [&](std::uint32_t k) { zs.push_back(cloud.points[k].z()); });
      if (zs.empty()) continue;
      float z;
      if (o.aggregate == CellAggregate::Max) {
        z = *std::max_element(zs.begin(), zs.end());
      } else {
        z = median_in_place(std::span(zs));
      }
      map.set(i, j, z, CellState::Measured);
    }
  }
  return map;
}

HoleReport fill_holes(HeightMap& map, double max_gap, double max_fill_slope) {
  HoleReport report;
  const int nx = map.nx(), ny = map.ny();
  const double cell = map.cell();
  // Directions: row, column, both diagonals; step length in metres.
  constexpr std::array<std::array<int, 2>, 4> dirs{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  std::vector<std::pair<std::size_t, float>> fills;
  if (max_gap > 0) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        if (map.valid(i, j)) continue;
        double sum = 0, wsum = 0;
        for (const auto& d : dirs) {
          const double step = cell * std::hypot(d[0], d[1]);
          // The gap between two measured cells d1 + d2 steps apart is
          // (d1 + d2 - 1) empty steps wide.
          const int reach = static_cast<int>(std::floor(max_gap / step + 1e-9)) + 1;
          auto probe = [&](int sign, int& dist) -> float {
            for (int s = 1; s < reach; ++s) {
              const int ci = i + sign * s * d[0], cj = j + sign * s * d[1];
              if (ci < 0 || cj < 0 || ci >= nx || cj >= ny) return std::numeric_limits<float>::quiet_NaN();
              if (map.state(ci, cj) == CellState::Measured) {
                dist = s;
                return map.height(ci, cj);
              }
            }
            return std::numeric_limits<float>::quiet_NaN();
          };
          int d1 = 0, d2 = 0;
          const float z1 = probe(-1, d1);
          if (std::isnan(z1)) continue;
          const float z2 = probe(+1, d2);
          if (std::isnan(z2)) continue;
          if ((d1 + d2 - 1) * step > max_gap + 1e-9) continue;
          const double span = (d1 + d2) * step;
          // A gap across which the height jumps steeply is an occlusion
          // shadow behind an edge: the hidden ground continues at the lower
          // side's height, so a ramp between the two would be made up.
          const double z =
              std::abs(static_cast<double>(z1) - z2) > max_fill_slope * span
                  ? std::min(z1, z2)
                  : (static_cast<double>(z1) * d2 + static_cast<double>(z2) * d1) / static_cast<double>(d1 + d2);
          const double w = 1.0 / span;  // shorter spans weigh more
          sum += w * z;
          wsum += w;
        }
        if (wsum > 0) fills.emplace_back(map.index(i, j), static_cast<float>(sum / wsum));
      }
    }
  }
  for (const auto& [idx, z] : fills) {
    map.set(static_cast<int>(idx % nx), static_cast<int>(idx / nx), z, CellState::Filled);
  }
  report.filled_cells = fills.size();

  for_each_enclosed_empty_region(map, [&](const std::vector<std::size_t>& region) {
    ++report.large_holes;
    report.large_hole_cells += region.size();
  });
  return report;
}

UnknownReport fill_unknown(HeightMap& map, UnknownFill fill, double pit_depth) {
  UnknownReport report;
  const int nx = map.nx(), ny = map.ny();
  std::vector<std::size_t> regions;  // cell indices, region by region
  std::vector<std::pair<std::size_t, float>> heights;
  for_each_enclosed_empty_region(map, [&](const std::vector<std::size_t>& region) {
    ++report.regions;
    report.cells += region.size();
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    for (const std::size_t k : region) {
      const int i = static_cast<int>(k % nx), j = static_cast<int>(k / nx);
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int ni = i + di, nj = j + dj;
          if (ni < 0 || nj < 0 || ni >= nx || nj >= ny || !map.valid(ni, nj)) continue;
          lo = std::min(lo, map.height(ni, nj));
          hi = std::max(hi, map.height(ni, nj));
        }
      }
    }
    // Enclosed: the rim has at least one valid cell.
    const float z = fill == UnknownFill::Block ? hi : lo - static_cast<float>(pit_depth);
    for (const std::size_t k : region) heights.emplace_back(k, z);
  });
  // Set after the search so that one region's fill is not another's rim.
  for (const auto& [k, z] : heights) map.set(static_cast<int>(k % nx), static_cast<int>(k / nx), z, CellState::Unknown);
  return report;
}

TriangleMesh triangulate_solid(const HeightMap& map, double base_thickness) {
  const int nx = map.nx(), ny = map.ny();
  TriangleMesh mesh;
  if (nx < 2 || ny < 2) return mesh;
  // Quad (i, j) spans the centres of cells (i..i+1, j..j+1).
  const int qx = nx - 1, qy = ny - 1;
  auto qidx = [&](int i, int j) { return static_cast<std::size_t>(j) * qx + i; };
  std::vector<std::uint8_t> quad(static_cast<std::size_t>(qx) * qy, 0);
  for (int j = 0; j < qy; ++j)
    for (int i = 0; i < qx; ++i)
      quad[qidx(i, j)] = map.valid(i, j) && map.valid(i + 1, j) && map.valid(i, j + 1) && map.valid(i + 1, j + 1);
  auto has = [&](int i, int j) { return i >= 0 && j >= 0 && i < qx && j < qy && quad[qidx(i, j)]; };

  // A vertex touched only by two diagonally opposite quads would make the
  // walls meet along one edge four times: drop the upper-right quad of each
  // such pinch until none is left.
  for (bool changed = true; changed;) {
    changed = false;
    for (int j = 1; j < ny - 1; ++j) {
      for (int i = 1; i < nx - 1; ++i) {
        const bool ll = has(i - 1, j - 1), lr = has(i, j - 1), ul = has(i - 1, j), ur = has(i, j);
        if (ll && ur && !lr && !ul) {
          quad[qidx(i, j)] = 0;
          changed = true;
        } else if (lr && ul && !ll && !ur) {
          quad[qidx(i - 1, j)] = 0;
          changed = true;
        }
      }
    }
  }

  // Vertices: a top and a bottom vertex for every cell used by a quad.
  std::vector<std::int32_t> top(static_cast<std::size_t>(nx) * ny, -1);
  float zmin = std::numeric_limits<float>::max();
  for (int j = 0; j < qy; ++j) {
    for (int i = 0; i < qx; ++i) {
      if (!quad[qidx(i, j)]) continue;
      for (int dj = 0; dj <= 1; ++dj) {
        for (int di = 0; di <= 1; ++di) {
          auto& t = top[map.index(i + di, j + dj)];
          if (t >= 0) continue;
          t = static_cast<std::int32_t>(mesh.vertices.size());
          const float z = map.height(i + di, j + dj);
          zmin = std::min(zmin, z);
          mesh.vertices.emplace_back(static_cast<float>(map.centre_x(i + di)), static_cast<float>(map.centre_y(j + dj)),
                                     z);
        }
      }
    }
  }
  if (mesh.vertices.empty()) return mesh;
  const std::size_t ntop = mesh.vertices.size();
  const float zbase = zmin - static_cast<float>(base_thickness);
  for (std::size_t v = 0; v < ntop; ++v) {
    mesh.vertices.emplace_back(mesh.vertices[v].x(), mesh.vertices[v].y(), zbase);
  }
  auto T = [&](int i, int j) { return static_cast<std::uint32_t>(top[map.index(i, j)]); };
  auto B = [&](int i, int j) {
    return static_cast<std::uint32_t>(top[map.index(i, j)] + static_cast<std::int32_t>(ntop));
  };

  for (int j = 0; j < qy; ++j) {
    for (int i = 0; i < qx; ++i) {
      if (!quad[qidx(i, j)]) continue;
      const std::uint32_t a = T(i, j), b = T(i + 1, j), c = T(i + 1, j + 1), d = T(i, j + 1);
      // Split along the diagonal with the smaller height difference, which
      // keeps ridges and step edges sharp.
      const float dac = std::abs(map.height(i, j) - map.height(i + 1, j + 1));
      const float dbd = std::abs(map.height(i + 1, j) - map.height(i, j + 1));
      if (dac <= dbd) {
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      } else {
        mesh.triangles.push_back({a, b, d});
        mesh.triangles.push_back({b, c, d});
      }
      const std::uint32_t A = B(i, j), Bq = B(i + 1, j), C = B(i + 1, j + 1), D = B(i, j + 1);
      mesh.triangles.push_back({A, C, Bq});  // bottom faces down
      mesh.triangles.push_back({A, D, C});
      // Walls along quad edges with no quad on the other side. Top edges
      // run counter-clockwise (seen from above) around the quad: p → q.
      auto wall = [&](std::uint32_t p, std::uint32_t q, std::uint32_t pb, std::uint32_t qb) {
        mesh.triangles.push_back({q, p, pb});
        mesh.triangles.push_back({q, pb, qb});
      };
      if (!has(i, j - 1)) wall(a, b, A, Bq);
      if (!has(i + 1, j)) wall(b, c, Bq, C);
      if (!has(i, j + 1)) wall(c, d, C, D);
      if (!has(i - 1, j)) wall(d, a, D, A);
    }
  }
  return mesh;
}

}  // namespace touchdown::terrain
