#pragma once
/// \file
/// Units and angles shared by every module: the library works in SI units
/// and radians; degrees appear only in files and on the command line.
#include <cmath>
#include <numbers>

namespace touchdown {

/// Radians per degree.
inline constexpr double kRadPerDeg = std::numbers::pi / 180.0;

constexpr double deg_to_rad(double degrees) { return degrees * kRadPerDeg; }
constexpr double rad_to_deg(double radians) { return radians / kRadPerDeg; }

/// The angle in (−π, π].
inline double wrap_to_pi(double radians) {
  const double a = std::remainder(radians, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

}  // namespace touchdown
