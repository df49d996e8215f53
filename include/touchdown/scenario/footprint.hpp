#pragma once
/// \file
/// Ground footprints of a scenario's things, for the consistency checks
/// that Scenario::validate makes and that the violation search's repairs
/// must satisfy the same way (one geometry for both).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

/// A drone starting above a static object's footprint must clear its top by
/// this much [m] (about the size of a landing drone, so it does not start in
/// contact).
inline constexpr double kDroneClearance = 1.0;

/// A rotated rectangle on the ground (or a disc).
struct Footprint {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double yaw_rad = 0;
  Eigen::Vector2d half = Eigen::Vector2d::Zero();  ///< half extents along its own x, y
  bool round = false;                              ///< a disc of radius half.x() (poles, tree crowns)

  [[nodiscard]] bool contains(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = Eigen::Rotation2Dd(-yaw_rad) * (p - centre);
    if (round) return d.norm() <= half.x();
    return std::abs(d.x()) <= half.x() && std::abs(d.y()) <= half.y();
  }
};

/// Separating-axis test of two rotated rectangles (touching counts as overlap).
bool overlap(const Footprint& a, const Footprint& b);
/// A marker-like square with its white margin of one cell: the black-border
/// edge `size` spans bits + 2 cells, the margin adds one cell on each side.
Footprint marker_square(const Eigen::Vector2d& centre, double yaw_deg, double size, int bits);
/// A static object's footprint (poles and trees round).
Footprint static_footprint(const StaticObject& o);

}  // namespace touchdown::scenario
