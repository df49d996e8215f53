#pragma once
// How the drone stands on the pad and what would upset it (internal; the
// mission's guard, state_machine.max_slide_ratio): the centre of mass's
// height above the feet, its distance to the support polygon's nearest
// edge, and the smallest tilt at which a propeller, an arm or (with a
// landing gear) the body reaches the plane of the feet.
#include <Eigen/Core>
#include <vector>

#include "touchdown/twin/airframe.hpp"

namespace touchdown::mission::detail {

struct Stance {
  double com_height = 0;   ///< centre of mass above the lowest support point, level [m]
  double inradius = 0;     ///< centre of mass to the support polygon's nearest edge (feet centres) [m]
  double strike_tilt = 0;  ///< the smallest tilt, about any horizontal axis, at which a part other than the support
                           ///< reaches the support's plane [rad]
  std::vector<Eigen::Vector3d> support;  ///< the support points from the centre of mass, body frame [m]
  double support_radius = 0;             ///< theirs [m]
};

/// The lowest support point's height relative to the centre of mass with
/// the body at attitude R (pad frame z up) [m], ≤ 0: level, −com_height.
double lowest_support(const Stance& s, const Eigen::Matrix3d& R);

/// The airframe's stance (a scan over tilt directions every 5°, tilts every
/// 0.25°, refined by bisection to 1e-4 rad).
Stance stance_of(const twin::Airframe& af);

/// The upset ratio of the guard for a side force `side` [N] on a drone of
/// `mass` [kg]: the largest of sliding, side / (μ (m g + hold)); tipping
/// once landed, side h / ((m g + hold) d); and striking while it flies
/// down holding station, side / (m g tan(strike_tilt)) (the tilt that
/// balances the side force against what would put a propeller on the pad).
double upset_ratio(const Stance& s, double side, double mass, double friction, double hold_force);

/// How far the centre of mass moves, horizontally, when the drone touches
/// down tilted by `tilt` [rad] on its leading feet and levels about them:
/// d (1 − cos θ) + h sin θ, with d the inradius and h the centre of mass's
/// height [m] (towards the side it leaned away from).
double levelling_shift(const Stance& s, double tilt);

}  // namespace touchdown::mission::detail
