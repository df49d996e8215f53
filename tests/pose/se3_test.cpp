#include "touchdown/pose/se3.hpp"

#include <gtest/gtest.h>

#include "touchdown/core/random.hpp"

namespace tp = touchdown::pose;

TEST(Se3, ExpLogRoundTripAndKnownValues) {
  touchdown::Rng rng(3);
  for (int k = 0; k < 200; ++k) {
    tp::Vector6d xi;
    for (int i = 0; i < 6; ++i) xi[i] = rng.uniform(-1, 1);
    if (k % 3 == 0) xi.tail<3>() *= 1e-7;  // small-angle branch
    const auto T = tp::se3_exp(xi);
    EXPECT_NEAR((T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
    EXPECT_NEAR(T.linear().determinant(), 1, 1e-12);
    EXPECT_LT((tp::se3_log(T) - xi).norm(), 1e-9) << k;
  }
  // A pure rotation of 90° about z and a pure translation.
  tp::Vector6d rot = tp::Vector6d::Zero();
  rot[5] = M_PI / 2;
  EXPECT_TRUE((tp::se3_exp(rot) * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
  tp::Vector6d tr = tp::Vector6d::Zero();
  tr.head<3>() = Eigen::Vector3d(1, 2, 3);
  EXPECT_TRUE(tp::se3_exp(tr).translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE((tp::hat(Eigen::Vector3d(1, 2, 3)) * Eigen::Vector3d(4, 5, 6))
                  .isApprox(Eigen::Vector3d(1, 2, 3).cross(Eigen::Vector3d(4, 5, 6))));
}
