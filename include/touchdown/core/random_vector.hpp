#pragma once
/// \file
/// Random Eigen vectors with a fixed order of draws.
///
/// C++ leaves the order in which a call's arguments are evaluated
/// unspecified: g++ evaluates `Eigen::Vector3d(rng.normal(), rng.normal(),
/// rng.normal())` right to left and clang++ left to right, so the same seed
/// gave two different vectors. Draw each number in its own statement, or
/// use these. They draw the last component first: the order g++ used, in
/// which every recorded result of the library (goldens, docs/results) was
/// made, so those results stay bit for bit.
#include <Eigen/Core>

#include "touchdown/core/random.hpp"

namespace touchdown {

/// A standard-normal 2-vector; draws y, then x.
inline Eigen::Vector2d normal_vector2(Rng& rng) {
  const double y = rng.normal();
  const double x = rng.normal();
  return {x, y};
}

/// A standard-normal 3-vector; draws z, then y, then x.
inline Eigen::Vector3d normal_vector3(Rng& rng) {
  const double z = rng.normal();
  const double y = rng.normal();
  const double x = rng.normal();
  return {x, y, z};
}

}  // namespace touchdown
