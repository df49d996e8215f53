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
#include "touchdown/scenario/footprint.hpp"
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
using scenario::kDroneClearance;

/// The row of the bounds table named `key`, or nullptr.
const PropertyBound* find_bound(std::string_view key);

// ---- text helpers ---------------------------------------------------------------------

inline std::string num(double v) { return touchdown::detail::format_exact(v); }
std::string numbers_text(const double* v, int n);
std::string indexed(std::string_view list, std::size_t i, std::string_view prop);

// ---- geometry of the consistency checks -----------------------------------------------

// The footprints are public (footprint.hpp: the search's repairs use them).
using scenario::Footprint;
using scenario::marker_square;
using scenario::overlap;
using scenario::static_footprint;

}  // namespace touchdown::scenario::detail
