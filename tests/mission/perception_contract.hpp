#pragma once
// The contract a mission perception (touchdown::mission::Perception) keeps,
// as a test a user's own implementation can run: give it a factory (seed →
// perception) and a path of truths the camera can see.
//
//   TEST(MyPerception, KeepsTheContract) {
//     touchdown::mission::test::expect_perception_contract(
//         [](std::uint64_t seed) { return std::make_unique<MyPerception>(seed); }, my_path());
//   }
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "touchdown/mission/perception.hpp"

namespace touchdown::mission::test {

using PerceptionMaker = std::function<std::unique_ptr<Perception>(std::uint64_t seed)>;

/// Checks, over `path` (truths in time order, the drone in view):
/// - a positive rate, and a frame's times: t_capture = the truth's t and
///   t_available ≥ t_capture;
/// - a pose (ok) is finite with a finite positive σ, and the σ is honest:
///   the RMS of the per-axis error over σ is at most `max_normalised_rms`
///   and no error exceeds 6 σ + `slack` [m];
/// - at least `min_ok_share` of the frames have a pose;
/// - the same seed gives the same measurements.
inline void expect_perception_contract(const PerceptionMaker& make, const std::vector<PerceptionTruth>& path,
                                       double min_ok_share = 0.5, double max_normalised_rms = 3.0,
                                       double slack = 0.01) {
  ASSERT_FALSE(path.empty());
  auto a = make(7), b = make(7);
  ASSERT_TRUE(a && b);
  EXPECT_GT(a->rate_hz(), 0);
  int ok = 0;
  double sum = 0;
  for (const PerceptionTruth& truth : path) {
    const PoseMeasurement m = a->capture(truth), n = b->capture(truth);
    EXPECT_EQ(m.t_capture, truth.t);
    EXPECT_GE(m.t_available, m.t_capture);
    EXPECT_EQ(m.ok, n.ok) << "t = " << truth.t;
    EXPECT_EQ(m.p_pad, n.p_pad) << "t = " << truth.t;
    if (!m.ok) continue;
    ++ok;
    ASSERT_TRUE(m.p_pad.allFinite()) << "t = " << truth.t;
    ASSERT_TRUE(m.sigma > 0 && std::isfinite(m.sigma)) << "t = " << truth.t << ": sigma " << m.sigma;
    const Eigen::Vector3d e = m.p_pad - truth.p_pad_com;
    EXPECT_LE(e.cwiseAbs().maxCoeff(), 6 * m.sigma + slack) << "t = " << truth.t << ": error " << e.transpose();
    sum += e.squaredNorm() / (3 * m.sigma * m.sigma);
  }
  EXPECT_GE(ok, min_ok_share * static_cast<double>(path.size()));
  if (ok > 0) {
    EXPECT_LE(std::sqrt(sum / ok), max_normalised_rms);
  }
}

}  // namespace touchdown::mission::test
