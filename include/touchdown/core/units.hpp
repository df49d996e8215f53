#pragma once
/// \file
/// Units and angles shared by every module: the library works in SI units
/// and radians; degrees appear only in files and on the command line.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <vector>

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

/// Angles given in degrees that look like radians: every value within
/// ±2π and one not a whole number of degrees ([3.14159, 0, 1.5708]; 3.14).
/// The one rule behind the warnings of the files (rpy_deg) and of the
/// command line (--yaw-max, --slope): a warning, never an error.
inline bool look_like_radians(const std::vector<double>& degrees) {
  const double two_pi = 2 * std::numbers::pi;
  return !degrees.empty() &&
         std::all_of(degrees.begin(), degrees.end(), [&](double v) { return std::abs(v) <= two_pi; }) &&
         std::any_of(degrees.begin(), degrees.end(), [](double v) { return v != std::round(v); });
}

}  // namespace touchdown
