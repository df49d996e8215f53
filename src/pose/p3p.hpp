#pragma once
// Perspective-three-point (internal to touchdown::pose): the distances
// along three bearing rays to three points of known mutual distances, by
// Grunert's quartic (Grunert 1841, as derived in Haralick, Lee, Ottenberg
// & Nölle, "Review and analysis of solutions of the three point
// perspective pose estimation problem", IJCV 13(3), 1994, sec. 2.1).
// The correspondence search uses it to predict where a hypothesis' fourth
// LED must appear before it pays for EPnP. Fixed-size: no allocation.
#include <Eigen/Core>
#include <array>

namespace touchdown::pose::detail {

// Up to four solutions: per solution the distances s_i > 0 along the unit
// rays j_i to the three points (camera frame: Q_i = s_i j_i).
struct P3pSolutions {
  std::array<Eigen::Vector3d, 4> s;
  int count = 0;
};

// Rays j1..j3 (unit, camera frame) toward points with |P2−P3| = a,
// |P1−P3| = b, |P1−P2| = c [m]. Real roots of the quartic only (a double
// root split by noise into a complex pair is kept at its real part when
// the imaginary part is small), each polished by Newton's method on the
// quartic; solutions with a non-positive distance are dropped.
P3pSolutions solve_p3p(const Eigen::Vector3d& j1, const Eigen::Vector3d& j2, const Eigen::Vector3d& j3, double a,
                       double b, double c);

}  // namespace touchdown::pose::detail
