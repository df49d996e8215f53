#include "touchdown/core/random.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "touchdown/core/random_vector.hpp"

namespace td = touchdown;

TEST(Rng, SameSeedSameStreamSameDraws) {
  td::Rng a(42, 3), b(42, 3), c(42, 4), d(43, 3);
  bool differ_c = false, differ_d = false;
  for (int i = 0; i < 100; ++i) {
    const auto x = a.next();
    EXPECT_EQ(x, b.next());
    differ_c |= x != c.next();
    differ_d |= x != d.next();
  }
  EXPECT_TRUE(differ_c);
  EXPECT_TRUE(differ_d);
}

TEST(Rng, UniformAndNormalMoments) {
  td::Rng r(7);
  const int n = 200000;
  double su = 0, sn = 0, sn2 = 0;
  double umin = 1, umax = 0;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    su += u;
    const double g = r.normal();
    sn += g;
    sn2 += g * g;
  }
  EXPECT_GE(umin, 0.0);
  EXPECT_LT(umax, 1.0);
  EXPECT_NEAR(su / n, 0.5, 0.005);
  EXPECT_NEAR(sn / n, 0.0, 0.01);
  EXPECT_NEAR(sn2 / n, 1.0, 0.02);
}

// The vectors draw their last component first (the order the recorded
// results were made in) whatever the compiler: the same as one draw per
// statement in that order.
TEST(RandomVector, DrawsLastComponentFirstOnEveryCompiler) {
  td::Rng a(11, 2), b(11, 2);
  const Eigen::Vector3d v = td::normal_vector3(a);
  const double z = b.normal();
  const double y = b.normal();
  const double x = b.normal();
  EXPECT_EQ(v, Eigen::Vector3d(x, y, z));
  const Eigen::Vector2d w = td::normal_vector2(a);
  const double wy = b.normal();
  const double wx = b.normal();
  EXPECT_EQ(w, Eigen::Vector2d(wx, wy));
  EXPECT_NE(v.x(), v.z());        // the draws differ, so the order is visible
  EXPECT_EQ(a.next(), b.next());  // and each drew exactly its components
}
