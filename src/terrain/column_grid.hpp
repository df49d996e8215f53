#pragma once
// Points grouped by the 2-D column (square of edge `size` in x, y) they fall
// in, by a counting sort: O(n + columns) time, 4 bytes per point plus 4 per
// column. Neighbour queries then visit only nearby columns. Internal.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

namespace touchdown::terrain::detail {

struct ColumnGrid {
  double x0 = 0, y0 = 0, size = 1;
  int nx = 0, ny = 0;
  std::vector<std::uint32_t> start;  // nx*ny + 1 offsets into `order`
  std::vector<std::uint32_t> order;  // point indices grouped by column, ascending within a column

  [[nodiscard]] int col_x(float x) const {
    return std::clamp(static_cast<int>(std::floor((x - x0) / size)), 0, nx - 1);
  }
  [[nodiscard]] int col_y(float y) const {
    return std::clamp(static_cast<int>(std::floor((y - y0) / size)), 0, ny - 1);
  }
  [[nodiscard]] std::size_t columns() const { return static_cast<std::size_t>(nx) * ny; }

  /// Groups `pts` into the given grid (points outside are clamped to it).
  void build(const std::vector<Eigen::Vector3f>& pts, double origin_x, double origin_y, double cell, int cols_x,
             int cols_y) {
    x0 = origin_x;
    y0 = origin_y;
    size = cell;
    nx = cols_x;
    ny = cols_y;
    start.assign(columns() + 1, 0);
    order.resize(pts.size());
    // `order` first holds each point's column, then the grouping.
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto c = static_cast<std::uint32_t>(static_cast<std::size_t>(col_y(pts[i].y())) * nx + col_x(pts[i].x()));
      order[i] = c;
      ++start[c + 1];
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::uint32_t> grouped(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) grouped[start[order[i]]++] = static_cast<std::uint32_t>(i);
    // `start` was advanced to the column ends; shift it back.
    for (std::size_t c = columns(); c > 0; --c) start[c] = start[c - 1];
    start[0] = 0;
    order.swap(grouped);
  }

  template <typename Visit>
  void for_each_in(int x, int y, Visit&& visit) const {
    if (x < 0 || y < 0 || x >= nx || y >= ny) return;
    const std::size_t c = static_cast<std::size_t>(y) * nx + x;
    for (std::uint32_t s = start[c]; s < start[c + 1]; ++s) visit(order[s]);
  }
};

}  // namespace touchdown::terrain::detail
