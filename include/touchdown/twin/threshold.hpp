#pragma once
/// \file
/// The geometric safety threshold of the landing sweep: the smaller of the
/// nutation at which the twin, resting on level ground, tips over, and the
/// nutation at which a propeller touches level ground when the twin pivots
/// about its support points (Airframe::support_points(): its feet, or the
/// body's bottom corners without landing gear).
#include <Eigen/Geometry>
#include <cstddef>

#include "touchdown/twin/airframe.hpp"

namespace touchdown::twin {

struct SafetyThreshold {
  /// (a) Tilt about the support edge nearest the centre of mass at which the
  /// centre of mass is above that edge: atan(d / h), d its horizontal
  /// distance to the edge line, h its height above the support points.
  double tip_rad = 0;
  /// The support points of that edge (indices into support_points(): feet).
  std::size_t tip_foot_a = 0, tip_foot_b = 0;
  /// (b) Smallest tilt, pivoting about one foot (or two) in any outward
  /// direction, at which the lowest point of a propeller disk (or of an
  /// arm, which can come first without landing gear) reaches the ground
  /// plane.
  double prop_strike_rad = 0;
  [[nodiscard]] double value() const { return tip_rad < prop_strike_rad ? tip_rad : prop_strike_rad; }
};

SafetyThreshold compute_safety_threshold(const Airframe& airframe);

/// Body pose (body → world) of the twin standing on level ground z = 0,
/// rotated by `angle` (radians) about the line through support points `a`
/// and `b` (feet centres or body corners), tilting over that edge: a and b
/// stay on the ground.
Eigen::Isometry3d pose_tilted_about_edge(const Airframe& airframe, std::size_t a, std::size_t b, double angle);

/// Body pose of the twin standing level on z = `ground_z` at (x, y) with heading `yaw`.
Eigen::Isometry3d pose_standing(const Airframe& airframe, double x, double y, double ground_z, double yaw);

}  // namespace touchdown::twin
