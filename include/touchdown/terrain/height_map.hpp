#pragma once
/// \file
/// 2.5-D height map of world-frame points, hole filling, and its
/// triangulation into a closed solid.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/mesh.hpp"
#include "touchdown/core/point_cloud.hpp"

namespace touchdown::terrain {

enum class CellAggregate { Max, Median };

/// How a region the camera never observed (an enclosed empty region that
/// interpolation did not fill: the inside of a cup, the shadow behind a
/// box) is filled so that the terrain stays a closed solid. Either way its
/// cells are marked CellState::Unknown and a landing over them is refused.
enum class UnknownFill {
  Block,  ///< a block up to the highest cell on the region's rim
  Pit,    ///< a pit `pit_depth` below the lowest cell on the rim
};

}  // namespace touchdown::terrain

template <>
struct touchdown::EnumNames<touchdown::terrain::CellAggregate> {
  static constexpr std::array<std::string_view, 2> names{"max", "median"};
};
template <>
struct touchdown::EnumNames<touchdown::terrain::UnknownFill> {
  static constexpr std::array<std::string_view, 2> names{"block", "pit"};
};

namespace touchdown::terrain {

inline std::string_view to_string(CellAggregate aggregate) { return enum_name(aggregate); }
inline std::string_view to_string(UnknownFill fill) { return enum_name(fill); }

struct HeightMapOptions {
  double cell = 0.02;  ///< cell edge, metres
  CellAggregate aggregate = CellAggregate::Median;
  double max_hole = 0.10;              ///< widest gap filled by interpolation, metres
  double max_fill_slope = 1.0;         ///< steeper gaps are shadows: filled at the lower side
  std::size_t max_cells = 50'000'000;  ///< refuse grids larger than this
  UnknownFill unknown_fill = UnknownFill::Block;
  double pit_depth = 1.0;  ///< metres below the lowest rim cell, for UnknownFill::Pit
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Empty: no data (outside the scan, or not yet filled). Measured: from
/// points. Filled: interpolated across a small gap. Unknown: in a region the
/// camera never observed, given a pessimistic height (UnknownFill).
enum class CellState : std::uint8_t { Empty, Measured, Filled, Unknown };

}  // namespace touchdown::terrain

template <>
struct touchdown::EnumNames<touchdown::terrain::CellState> {
  static constexpr std::array<std::string_view, 4> names{"empty", "measured", "filled", "unknown"};
};

namespace touchdown::terrain {

inline std::string_view to_string(CellState state) { return enum_name(state); }

/// Regular grid of heights. Cell (i, j) covers x ∈ [x0 + i·cell, x0 + (i+1)·cell)
/// and the same in y; its height is attached to the cell centre.
class HeightMap {
 public:
  HeightMap() = default;
  HeightMap(double x0, double y0, double cell, int nx, int ny);

  [[nodiscard]] int nx() const { return nx_; }
  [[nodiscard]] int ny() const { return ny_; }
  [[nodiscard]] double cell() const { return cell_; }
  [[nodiscard]] double x0() const { return x0_; }
  [[nodiscard]] double y0() const { return y0_; }
  [[nodiscard]] double centre_x(int i) const { return x0_ + (i + 0.5) * cell_; }
  [[nodiscard]] double centre_y(int j) const { return y0_ + (j + 0.5) * cell_; }
  [[nodiscard]] std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * nx_ + i; }

  [[nodiscard]] CellState state(int i, int j) const { return state_[index(i, j)]; }
  [[nodiscard]] bool valid(int i, int j) const { return state(i, j) != CellState::Empty; }
  [[nodiscard]] float height(int i, int j) const { return z_[index(i, j)]; }
  void set(int i, int j, float z, CellState s) {
    z_[index(i, j)] = z;
    state_[index(i, j)] = s;
  }
  [[nodiscard]] std::size_t count(CellState s) const;

  /// Height at (x, y) by bilinear interpolation of the surrounding valid
  /// cell centres (the nearest valid centre when some are missing); empty
  /// outside the grid or when no neighbouring cell is valid.
  [[nodiscard]] std::optional<double> height_at(double x, double y) const;

 private:
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 0, ny_ = 0;
  std::vector<float> z_;
  std::vector<CellState> state_;
};

/// Bins world-frame points (z up) into cells of `options.cell`, aggregating
/// each cell's z by max or median. Throws InvalidArgument when the grid
/// would exceed `options.max_cells` or the cloud is empty.
HeightMap build_height_map(const PointCloud& cloud_world, const HeightMapOptions& options);

struct HoleReport {
  std::size_t filled_cells = 0;      ///< empty cells filled by interpolation
  std::size_t large_holes = 0;       ///< enclosed empty regions left unfilled
  std::size_t large_hole_cells = 0;  ///< cells in those regions
};

/// Fills each empty cell that lies between measured cells no more than
/// `max_gap` apart along a row, column or diagonal, by linear interpolation
/// between them (averaged over the directions that bracket it). Where the
/// height changes across the gap by more than `max_fill_slope` × its length,
/// the gap is an occlusion shadow behind an edge (a depth camera cannot see
/// the ground just behind a box) and is filled at the lower side's height
/// instead of with a ramp. Only measured cells are used as sources, so the
/// result does not depend on the scan order. Enclosed regions that stay
/// empty are reported.
HoleReport fill_holes(HeightMap& map, double max_gap, double max_fill_slope = 1.0);

struct UnknownReport {
  std::size_t regions = 0;  ///< enclosed empty regions marked unknown
  std::size_t cells = 0;    ///< cells in them
};

/// Marks every enclosed empty region (4-connected, not touching the grid
/// border: the scan saw all around it but not into it) CellState::Unknown
/// and gives it a height by `fill` (a block at the highest rim cell, or a
/// pit `pit_depth` below the lowest). Empty regions that reach the border
/// stay empty: they are outside the scan. Call after fill_holes.
UnknownReport fill_unknown(HeightMap& map, UnknownFill fill, double pit_depth);

/// Triangulates the valid cells into a closed solid: the top surface through
/// the cell centres (two triangles per 2×2 block of valid cells), vertical
/// walls along every boundary, and a flat bottom `base_thickness` below the
/// lowest cell. Every edge is shared by exactly two triangles and all
/// triangles face outwards, so it is usable as a physics trimesh.
TriangleMesh triangulate_solid(const HeightMap& map, double base_thickness);

}  // namespace touchdown::terrain
