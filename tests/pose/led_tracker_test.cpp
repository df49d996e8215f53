#include "touchdown/pose/led_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

using namespace touchdown::pose_test;

namespace {

using touchdown::pose_test::d435;
using touchdown::pose_test::f450;

// Drone above the camera, underside facing it (body z ≈ camera z).
Eigen::Isometry3d looking_up(touchdown::Rng& rng, double distance) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(rng.uniform(-M_PI, M_PI), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(rng.uniform(-0.3, 0.3), Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(rng.uniform(-0.3, 0.3), Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() << rng.uniform(-0.1, 0.1) * distance, rng.uniform(-0.1, 0.1) * distance, distance;
  return T;
}

std::vector<tp::Blob> blobs_of(const tp::Constellation& k, const tp::PinholeCamera& cam, const Eigen::Isometry3d& T,
                               touchdown::Rng& rng, double noise_px, bool with_colour = true) {
  std::vector<tp::Blob> out;
  for (const auto& led : k.leds) {
    tp::Blob b;
    b.uv_undistorted = cam.project(T * led.p_body) + noise_px * Eigen::Vector2d(rng.normal(), rng.normal());
    b.uv_px = b.uv_undistorted;
    b.color = with_colour ? led.color : tp::LedColor::Unknown;
    b.intensity = 1000 + rng.uniform(0, 100);
    b.area = 9;
    out.push_back(b);
  }
  return out;
}

using touchdown::test::rotation_error;

}  // namespace

TEST(Correspondence, FindsThePermutationUnderColourPruning) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(21);
  for (int trial = 0; trial < 30; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.5, 3.0));
    auto blobs = blobs_of(k, cam, T, rng, 0.0);
    std::vector<int> order(blobs.size());
    std::iota(order.begin(), order.end(), 0);
    for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.next() % i]);
    std::vector<tp::Blob> shuffled;
    for (int i : order) shuffled.push_back(blobs[i]);
    const auto c = tp::find_correspondences(cam, k, shuffled);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok) << trial;
    EXPECT_EQ(c.matched, 6);
    for (std::size_t l = 0; l < k.leds.size(); ++l) EXPECT_EQ(order[c.blob_of_led[l]], int(l)) << trial;
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 1e-9);
    EXPECT_LT(rotation_error(c.fit.T_camera_body, T), 1e-9);
  }
}

TEST(Correspondence, HandlesASpuriousBlobAndAMissingLed) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(22);
  for (int trial = 0; trial < 30; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.5, 3.0));
    auto blobs = blobs_of(k, cam, T, rng, 0.3);
    const std::size_t missing = rng.next() % blobs.size();
    blobs.erase(blobs.begin() + static_cast<std::ptrdiff_t>(missing));
    tp::Blob spurious;  // a bright lamp of a colour class some LED has, inside the image
    spurious.uv_undistorted = {rng.uniform(50, 800), rng.uniform(50, 430)};
    spurious.color = trial % 2 ? tp::LedColor::White : tp::LedColor::Red;
    spurious.intensity = 5000;
    blobs.insert(blobs.begin(), spurious);
    const auto c = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok) << trial;
    EXPECT_EQ(c.matched, 5) << trial;
    EXPECT_EQ(c.blob_of_led[missing], -1);
    for (std::size_t l = 0; l < k.leds.size(); ++l) {
      if (l == missing) continue;
      const int expected = 1 + int(l < missing ? l : l - 1);
      EXPECT_EQ(c.blob_of_led[l], expected) << trial << " led " << l;
    }
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 0.01 * T.translation().z());
  }
}

TEST(Correspondence, WorksWithoutColourClasses) {
  auto k = f450();
  for (auto& l : k.leds) l.color = tp::LedColor::White;
  const auto cam = d435().pinhole();
  touchdown::Rng rng(23);
  for (int trial = 0; trial < 10; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.5, 2.5));
    const auto blobs = blobs_of(k, cam, T, rng, 0.2, false);
    const auto c = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok);
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 0.01 * T.translation().z());
    EXPECT_LT(rotation_error(c.fit.T_camera_body, T), 0.02);
  }
}

TEST(Correspondence, TooFewOrInconsistentBlobsGiveAStatusNotAPose) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(24);
  auto blobs = blobs_of(k, cam, looking_up(rng, 1.0), rng, 0.0);
  blobs.resize(3);
  EXPECT_EQ(tp::find_correspondences(cam, k, blobs).status, tp::PoseStatus::TooFewBlobs);
  // Six random blobs: nothing rigid explains them.
  std::vector<tp::Blob> noise(6);
  for (std::size_t i = 0; i < noise.size(); ++i) {
    noise[i].uv_undistorted = {rng.uniform(0, 848), rng.uniform(0, 480)};
    noise[i].color = k.leds[i].color;
  }
  const auto c = tp::find_correspondences(cam, k, noise);
  EXPECT_NE(c.status, tp::PoseStatus::Ok)
      << c.matched << " rms " << c.fit.rms_px << " z " << c.fit.T_camera_body.translation().transpose();
}

TEST(LedTracker, TracksASmoothTrajectoryWithoutReinitialising) {
  const auto k = f450();
  const auto model = d435();
  const auto cam = model.pinhole();
  tp::LedTracker tracker(model, k);
  touchdown::Rng rng(25);
  Eigen::Isometry3d T = looking_up(rng, 0.8);
  int reinit = 0;
  for (int f = 0; f < 200; ++f) {
    tp::Vector6d xi;
    xi << 0.004 * std::sin(f * 0.05), 0.003 * std::cos(f * 0.07), 0.006 * std::sin(f * 0.03), 0.004, -0.003, 0.02;
    T = tp::se3_exp(xi) * T;
    auto blobs = blobs_of(k, cam, T, rng, 0.3);
    if (f % 17 == 5) blobs.erase(blobs.begin() + f % 6);  // an LED drops out
    if (f % 23 == 7) {                                    // a reflection next to an LED
      tp::Blob dup = blobs[0];
      dup.uv_undistorted += Eigen::Vector2d(1.0, 0.5);
      dup.intensity *= 0.3;
      blobs.push_back(dup);
    }
    const auto& e = tracker.track_blobs(blobs);
    ASSERT_TRUE(e.ok()) << "frame " << f << ": " << tp::to_string(e.status);
    reinit += e.reinitialised;
    EXPECT_LT((e.T_camera_body.translation() - T.translation()).norm(), 0.01) << f;
    EXPECT_LT(rotation_error(e.T_camera_body, T), 0.03) << f;
  }
  EXPECT_EQ(reinit, 1);  // the first frame only
}

TEST(LedTracker, ReinitialisesAfterLossAndNeverInventsAPose) {
  const auto k = f450();
  const auto model = d435();
  const auto cam = model.pinhole();
  tp::LedTracker tracker(model, k);
  touchdown::Rng rng(26);
  const auto T1 = looking_up(rng, 1.0);
  ASSERT_TRUE(tracker.track_blobs(blobs_of(k, cam, T1, rng, 0.2)).ok());
  auto few = blobs_of(k, cam, T1, rng, 0.2);
  few.resize(2);
  EXPECT_EQ(tracker.track_blobs(few).status, tp::PoseStatus::TooFewBlobs);
  // The drone jumped elsewhere: the gate fails, the full search recovers.
  const auto T2 = looking_up(rng, 2.0);
  const auto& e = tracker.track_blobs(blobs_of(k, cam, T2, rng, 0.2));
  ASSERT_TRUE(e.ok());
  EXPECT_TRUE(e.reinitialised);
  EXPECT_LT((e.T_camera_body.translation() - T2.translation()).norm(), 0.02);
}

TEST(LedTracker, RejectsBadConfiguration) {
  auto k = f450();
  k.leds.resize(3);
  EXPECT_THROW(tp::LedTracker(d435(), k), touchdown::InvalidArgument);
  tp::TrackerOptions o;
  o.track_gate_px = -1;
  EXPECT_THROW(tp::LedTracker(d435(), f450(), o), touchdown::InvalidArgument);
}
