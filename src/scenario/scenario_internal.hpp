#pragma once
// What the three parts of the scenario module's file format share:
// scenario.cpp (the bounds table, validation), scenario_io.cpp (the
// YAML/JSON reader and writer) and scenario_random.cpp (random scenarios).
// Private to the module.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/io_util.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario::detail {

// ---- constants of the bounds table ----------------------------------------------------

// 2^53: the largest integer every JSON reader (IEEE doubles) reads exactly.
inline constexpr std::uint64_t kMaxSeedInteger = std::uint64_t{1} << 53;
inline constexpr double kMaxSeed = static_cast<double>(kMaxSeedInteger);
// Half the side of the map area [m]: everything starts within ±kMapHalf.
inline constexpr double kMapHalf = 20.0;
// The largest dictionary (ARUCO_ORIGINAL) has 1024 codes; validate() checks
// an id against its own dictionary's size.
inline constexpr double kMaxMarkerId = 1023.0;
// A drone starting above a static object's footprint must clear its top by
// this much [m] (about the size of a landing drone, so it does not start in
// contact).
inline constexpr double kDroneClearance = 1.0;

/// The row of the bounds table named `key`, or nullptr.
const PropertyBound* find_bound(std::string_view key);

// ---- text helpers ---------------------------------------------------------------------

inline std::string num(double v) { return touchdown::detail::format_exact(v); }
std::string numbers_text(const double* v, int n);
std::string indexed(std::string_view list, std::size_t i, std::string_view prop);

// ---- geometry of the consistency checks -----------------------------------------------

// A rotated rectangle on the ground.
struct Footprint {
  Eigen::Vector2d centre;
  double yaw_rad = 0;
  Eigen::Vector2d half;  // half extents along its own x, y
  bool round = false;    // a disc of radius half.x() (poles, tree crowns)

  [[nodiscard]] bool contains(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = Eigen::Rotation2Dd(-yaw_rad) * (p - centre);
    if (round) return d.norm() <= half.x();
    return std::abs(d.x()) <= half.x() && std::abs(d.y()) <= half.y();
  }
};

// Separating-axis test of two rotated rectangles (touching counts as overlap).
bool overlap(const Footprint& a, const Footprint& b);
// A marker-like square with its white margin of one cell: the black-border
// edge `size` spans bits + 2 cells, the margin adds one cell on each side.
Footprint marker_square(const Eigen::Vector2d& centre, double yaw_deg, double size, int bits);
Footprint static_footprint(const StaticObject& o);

}  // namespace touchdown::scenario::detail
