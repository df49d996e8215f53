#include "touchdown/terrain/filters.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

#include "column_grid.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::terrain {
namespace {

template <typename Keep>
std::size_t erase_unless(PointCloud& cloud, Keep&& keep) {
  const std::size_t before = cloud.size();
  auto& pts = cloud.points;
  pts.erase(std::remove_if(pts.begin(), pts.end(), [&](const Eigen::Vector3f& p) { return !keep(p); }), pts.end());
  const std::size_t removed = before - pts.size();
  if (removed > 0) cloud.mark_unorganized();
  return removed;
}

// LSD radix sort of (key, index) pairs on the low `bits` bits of the key.
void radix_sort(std::vector<std::uint64_t>& keys, std::vector<std::uint32_t>& idx, int bits) {
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  std::vector<std::uint64_t> k2(keys.size());
  std::vector<std::uint32_t> i2(idx.size());
  std::vector<std::size_t> count(kBuckets);
  for (int shift = 0; shift < bits; shift += kDigit) {
    std::fill(count.begin(), count.end(), 0);
    for (auto k : keys) ++count[(k >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t t = c;
      c = sum;
      sum += t;
    }
    for (std::size_t i = 0; i < keys.size(); ++i) {
      const std::size_t pos = count[(keys[i] >> shift) & (kBuckets - 1)]++;
      k2[pos] = keys[i];
      i2[pos] = idx[i];
    }
    keys.swap(k2);
    idx.swap(i2);
  }
}

int bit_width(std::uint64_t v) {
  int b = 0;
  while (v) {
    ++b;
    v >>= 1;
  }
  return b;
}

}  // namespace

std::size_t remove_non_finite(PointCloud& cloud) {
  return erase_unless(cloud, [](const Eigen::Vector3f& p) { return p.allFinite(); });
}

std::size_t remove_flying_pixels(PointCloud& cloud, double threshold_at_1m) {
  if (!cloud.is_organized() || !(threshold_at_1m > 0)) return 0;
  const std::size_t w = cloud.width, h = cloud.height;
  const auto& pts = cloud.points;
  std::vector<std::uint8_t> flying(pts.size(), 0);
  auto depth = [&](std::size_t u, std::size_t v) { return pts[v * w + u].z(); };
  // True when both neighbours exist and each differs by more than `limit`.
  auto jumps = [](float d, float a, float b, float limit) {
    return std::isfinite(a) && std::isfinite(b) && std::abs(d - a) > limit && std::abs(d - b) > limit;
  };
  std::size_t count = 0;
  for (std::size_t v = 0; v < h; ++v) {
    for (std::size_t u = 0; u < w; ++u) {
      const float d = depth(u, v);
      if (!std::isfinite(d) || !pts[v * w + u].allFinite()) continue;
      const float limit = static_cast<float>(threshold_at_1m) * d * d;
      const bool row = u > 0 && u + 1 < w && jumps(d, depth(u - 1, v), depth(u + 1, v), limit);
      const bool col = v > 0 && v + 1 < h && jumps(d, depth(u, v - 1), depth(u, v + 1), limit);
      if (row || col) {
        flying[v * w + u] = 1;
        ++count;
      }
    }
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (flying[i]) cloud.points[i] = Eigen::Vector3f::Constant(nan);
  }
  return count;
}

void transform_cloud(PointCloud& cloud, const Eigen::Isometry3d& T) {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  for (auto& p : cloud.points) p = R * p + t;
  cloud.viewpoint = PointCloud{}.viewpoint;  // the points are now in a frame of our making
}

bool CropOptions::validate(std::string* why) const {
  if (!(radius >= 0) || !std::isfinite(radius)) return invalid(why, "radius: must be >= 0 m (0 = off)");
  if (box_body && ((box_body->min().array() > box_body->max().array()).any() || !box_body->min().allFinite() ||
                   !box_body->max().allFinite())) {
    return invalid(why, "box_body: min must not exceed max (finite, metres)");
  }
  return true;
}

bool OutlierOptions::validate(std::string* why) const {
  if (k < 0) return invalid(why, "k: must be >= 0 (0 = off)");
  if (!(std_ratio > 0) || !std::isfinite(std_ratio)) return invalid(why, "std_ratio: must be positive");
  if (!(search_cell >= 0) || !std::isfinite(search_cell)) return invalid(why, "search_cell: must be >= 0 m (0 = auto)");
  return true;
}

std::size_t crop_near_camera(PointCloud& cloud, const CropOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("crop options: " + why);
  const float r2 = static_cast<float>(o.radius * o.radius);
  const bool use_radius = o.radius > 0;
  if (!use_radius && !o.box_body) return 0;
  const Eigen::Matrix3f R = o.T_body_camera.linear().cast<float>();
  const Eigen::Vector3f t = o.T_body_camera.translation().cast<float>();
  Eigen::AlignedBox3f box;
  if (o.box_body) box = o.box_body->cast<float>();
  return erase_unless(cloud, [&](const Eigen::Vector3f& p) {
    if (use_radius && p.squaredNorm() < r2) return false;
    if (o.box_body && box.contains(R * p + t)) return false;
    return true;
  });
}

PointCloud voxel_downsample(const PointCloud& cloud, double voxel) {
  if (!(voxel > 0) || !std::isfinite(voxel)) throw InvalidArgument("voxel size must be positive");
  PointCloud out;
  const std::size_t n = cloud.size();
  if (n == 0) return out;
  Eigen::Array3d lo = Eigen::Array3d::Constant(std::numeric_limits<double>::max());
  Eigen::Array3d hi = -lo;
  for (const auto& p : cloud.points) {
    lo = lo.min(p.cast<double>().array());
    hi = hi.max(p.cast<double>().array());
  }
  // Voxels aligned to multiples of `voxel`, indices relative to the lowest.
  const Eigen::Array3d base = (lo / voxel).floor();
  const Eigen::Array3d span = (hi / voxel).floor() - base + 1.0;
  if ((span > static_cast<double>(1 << 21)).any()) {
    throw InvalidArgument("voxel grid too large: the cloud spans " + std::to_string((hi - lo).maxCoeff()) +
                          " m, more than 2^21 voxels of " + std::to_string(voxel) + " m");
  }
  auto voxel_z = [&](const Eigen::Vector3f& p) {
    return static_cast<std::uint32_t>(std::clamp(std::floor(p.z() / voxel) - base.z(), 0.0, span.z() - 1));
  };
  auto emit = [&](const std::uint32_t* begin, const std::uint32_t* end) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto* i = begin; i != end; ++i) sum += cloud.points[*i].cast<double>();
    out.points.push_back((sum / static_cast<double>(end - begin)).cast<float>());
  };
  // Output order: by voxel row y, column x, then layer z (both paths agree).
  const double columns = span.x() * span.y();
  if (columns <= 4.0 * static_cast<double>(n) + (1 << 20)) {
    detail::ColumnGrid grid;
    grid.build(cloud.points, base.x() * voxel, base.y() * voxel, voxel, static_cast<int>(span.x()),
               static_cast<int>(span.y()));
    std::vector<std::pair<std::uint32_t, std::uint32_t>> cell;  // (layer, point index)
    std::vector<std::uint32_t> members;
    for (std::size_t c = 0; c < grid.columns(); ++c) {
      const std::uint32_t b = grid.start[c], e = grid.start[c + 1];
      if (b == e) continue;
      cell.clear();
      for (std::uint32_t s = b; s < e; ++s) cell.emplace_back(voxel_z(cloud.points[grid.order[s]]), grid.order[s]);
      std::sort(cell.begin(), cell.end());
      for (std::size_t s = 0; s < cell.size();) {
        std::size_t t = s;
        members.clear();
        while (t < cell.size() && cell[t].first == cell[s].first) members.push_back(cell[t++].second);
        emit(members.data(), members.data() + members.size());
        s = t;
      }
    }
  } else {  // sparse cloud over a wide area: sort 64-bit voxel keys instead
    const auto sx = static_cast<std::uint64_t>(span.x()), sz = static_cast<std::uint64_t>(span.z());
    std::vector<std::uint64_t> keys(n);
    std::vector<std::uint32_t> idx(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d p = cloud.points[i].cast<double>();
      auto cell = [&](int a) {
        return static_cast<std::uint64_t>(std::clamp(std::floor(p[a] / voxel) - base[a], 0.0, span[a] - 1));
      };
      keys[i] = (cell(1) * sx + cell(0)) * sz + cell(2);
      idx[i] = static_cast<std::uint32_t>(i);
    }
    radix_sort(keys, idx, bit_width(static_cast<std::uint64_t>(span.x() * span.y() * span.z())));
    for (std::size_t i = 0; i < n;) {
      std::size_t j = i;
      while (j < n && keys[j] == keys[i]) ++j;
      emit(idx.data() + i, idx.data() + j);
      i = j;
    }
  }
  out.mark_unorganized();
  return out;
}

std::size_t remove_statistical_outliers(PointCloud& cloud, const OutlierOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("outlier options: " + why);
  const std::size_t n = cloud.size();
  if (o.k <= 0 || n < 2) return 0;
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(o.k), n - 1);
  const auto& pts = cloud.points;
  // Columns sized to hold about k points each, so that the 3x3 block
  // around a point almost always holds its k nearest neighbours.
  Eigen::Vector2f lo = Eigen::Vector2f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector2f hi = -lo;
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  const double area = std::max(1e-12, static_cast<double>(hi.x() - lo.x()) * (hi.y() - lo.y()));
  double size = o.search_cell > 0 ? o.search_cell : std::sqrt(area * static_cast<double>(k) / static_cast<double>(n));
  size = std::max(size, 1e-6);
  const double cols = std::ceil((hi.x() - lo.x()) / size + 1) * std::ceil((hi.y() - lo.y()) / size + 1);
  const double max_cols = 4.0 * static_cast<double>(n) + (1 << 20);
  if (cols > max_cols) size *= std::sqrt(cols / max_cols);
  detail::ColumnGrid grid;
  grid.build(pts, lo.x(), lo.y(), size, static_cast<int>((hi.x() - lo.x()) / size) + 1,
             static_cast<int>((hi.y() - lo.y()) / size) + 1);
  const int max_ring = std::max(grid.nx, grid.ny);
  // Beyond this many rings an unfinished search gives up and pads with the
  // ring distance: the point is isolated and gets a large mean distance.
  const int ring_limit = std::min(max_ring, 16);

  std::vector<float> mean_dist(n);
  std::vector<float> best(k);  // ascending squared distances
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& p = pts[i];
    const int cx = grid.col_x(p.x()), cy = grid.col_y(p.y());
    std::size_t found = 0;
    auto offer = [&](float d2) {
      if (found < k) {
        std::size_t pos = found++;
        while (pos > 0 && best[pos - 1] > d2) {
          best[pos] = best[pos - 1];
          --pos;
        }
        best[pos] = d2;
      } else if (d2 < best[k - 1]) {
        std::size_t pos = k - 1;
        while (pos > 0 && best[pos - 1] > d2) {
          best[pos] = best[pos - 1];
          --pos;
        }
        best[pos] = d2;
      }
    };
    auto visit = [&](int x, int y) {
      grid.for_each_in(x, y, [&](std::uint32_t j) {
        if (j != i) offer((pts[j] - p).squaredNorm());
      });
    };
    int ring = 0;
    visit(cx, cy);
    for (;;) {
      // Everything within `ring * size` horizontally has been seen.
      const double reach = ring * grid.size;
      if (found == k && best[k - 1] <= reach * reach) break;
      if (ring >= ring_limit) break;
      ++ring;
      for (int x = cx - ring; x <= cx + ring; ++x) {
        visit(x, cy - ring);
        visit(x, cy + ring);
      }
      for (int y = cy - ring + 1; y <= cy + ring - 1; ++y) {
        visit(cx - ring, y);
        visit(cx + ring, y);
      }
    }
    double sum = 0;
    for (std::size_t m = 0; m < found; ++m) sum += std::sqrt(static_cast<double>(best[m]));
    const double pad = (ring + 1) * grid.size;
    sum += static_cast<double>(k - found) * pad;
    mean_dist[i] = static_cast<float>(sum / static_cast<double>(k));
  }
  double mu = 0, sq = 0;
  for (float d : mean_dist) mu += d;
  mu /= static_cast<double>(n);
  for (float d : mean_dist) sq += (d - mu) * (d - mu);
  const double sigma = std::sqrt(sq / static_cast<double>(n > 1 ? n - 1 : 1));
  const double limit = mu + o.std_ratio * sigma;
  std::size_t w = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (mean_dist[i] <= limit) cloud.points[w++] = cloud.points[i];
  }
  const std::size_t removed = n - w;
  cloud.points.resize(w);
  if (removed > 0) cloud.mark_unorganized();
  return removed;
}

}  // namespace touchdown::terrain
