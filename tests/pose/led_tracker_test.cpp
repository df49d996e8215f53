#include "touchdown/pose/led_tracker.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "pose/ambiguity.hpp"
#include "pose/assignment.hpp"
#include "pose/pose_filter.hpp"
#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/pose/gauss_newton.hpp"

using namespace touchdown::pose_test;

namespace {

using touchdown::pose_test::d435;
using touchdown::pose_test::f450;

// Drone above the camera, underside facing it (body z ≈ camera z).
Eigen::Isometry3d looking_up(touchdown::Rng& rng, double distance) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double pitch = rng.uniform(-0.3, 0.3), roll = rng.uniform(-0.3, 0.3);  // drawn last factor first
  const double yaw = rng.uniform(-M_PI, M_PI);
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() << rng.uniform(-0.1, 0.1) * distance, rng.uniform(-0.1, 0.1) * distance, distance;
  return T;
}

std::vector<tp::Blob> blobs_of(const tp::Constellation& k, const tp::PinholeCamera& cam, const Eigen::Isometry3d& T,
                               touchdown::Rng& rng, double noise_px, bool with_colour = true) {
  std::vector<tp::Blob> out;
  for (const auto& led : k.leds) {
    tp::Blob b;
    b.uv_undistorted = cam.project(T * led.p_body) + noise_px * normal_vector2(rng);
    b.uv_px = b.uv_undistorted;
    b.color = with_colour ? led.color : tp::LedColor::Unknown;
    b.intensity = 1000 + rng.uniform(0, 100);
    b.area = 9;
    out.push_back(b);
  }
  return out;
}

// LED l on blob l (blobs_of's order), every LED of k; −1 beyond them.
std::array<int, tp::kMaxLeds> each_led_on_its_blob(const tp::Constellation& k) {
  std::array<int, tp::kMaxLeds> assignment{};
  assignment.fill(-1);
  for (std::size_t l = 0; l < k.leds.size(); ++l) assignment[l] = static_cast<int>(l);
  return assignment;
}

// Blobs that also carry the depth a stereo camera measures at them.
void add_depth(std::vector<tp::Blob>& blobs, const tp::Constellation& k, const tp::PinholeCamera& cam,
               const Eigen::Isometry3d& T, touchdown::Rng& rng) {
  for (std::size_t i = 0; i < blobs.size() && i < k.leds.size(); ++i) {
    const Eigen::Vector3d p = T * k.leds[i].p_body;
    const double z = p.z() + 0.0025 * p.z() * p.z() * rng.normal();
    blobs[i].has_point = true;
    blobs[i].p_camera = cam.back_project(blobs[i].uv_undistorted, z);
  }
}

// Drone in front of the camera with its front (body +x) toward it, as the
// paper's chase camera sees it: body +x ≈ camera −z, roll about it free.
Eigen::Isometry3d front_toward_camera(touchdown::Rng& rng, double distance) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double pitch = rng.uniform(-0.4, 0.4), roll = rng.uniform(-0.4, 0.4);  // drawn last factor first
  const double yaw = rng.uniform(-M_PI, M_PI);
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() << rng.uniform(-0.1, 0.1) * distance, rng.uniform(-0.1, 0.1) * distance, distance;
  return T;
}

// The F450 seen from below, its yaw 0.3 rad, `z` [m] from the camera; in
// frame `frame` of a slow drift (0.01 rad, 4 mm across and 5 mm nearer per
// frame), turned `turn` [rad] more about the optical axis.
Eigen::Isometry3d f450_from_below(double z, int frame = 0, double turn = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3 + 0.01 * frame + turn, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << 0.05 + 0.004 * frame, 0.02, z - 0.005 * frame;
  return T;
}

using touchdown::test::rotation_error;

}  // namespace

TEST(Led, EmissionConeIsTheNormalAndHalfAngle) {
  tp::Led led;
  led.p_body = {0.1, 0, 0};
  EXPECT_TRUE(led.emits_toward({-5, 3, 2}));  // no normal: every direction
  led.normal = {1, 0, 0};
  led.half_angle_deg = 70;
  auto at = [&](double deg) {  // a camera 2 m from the LED, `deg` off its axis
    const double a = deg * M_PI / 180;
    return Eigen::Vector3d(led.p_body + 2.0 * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
  };
  EXPECT_TRUE(led.emits_toward(at(0)));
  EXPECT_TRUE(led.emits_toward(at(69.9)));
  EXPECT_FALSE(led.emits_toward(at(70.1)));
  EXPECT_FALSE(led.emits_toward(at(180)));
  EXPECT_TRUE(led.emits_toward(at(74), 5 * M_PI / 180));  // within the margin
  EXPECT_FALSE(led.emits_toward(at(76), 5 * M_PI / 180));
  EXPECT_FALSE(led.emits_toward(led.p_body));  // no direction
}

// The paper's setup: a forward-facing board seen from the front. The
// search once assumed LEDs shine along body −z and rejected every pose.
TEST(Correspondence, ForwardFacingBoardSeenFromTheFront) {
  const auto k = front_board();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(25);
  for (int trial = 0; trial < 30; ++trial) {
    const auto T = front_toward_camera(rng, rng.uniform(0.5, 1.2));  // farther: see Ambiguity tests
    const auto blobs = blobs_of(k, cam, T, rng, 0.0);
    const auto c = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok) << trial;
    EXPECT_EQ(c.matched, 6);
    for (std::size_t l = 0; l < k.leds.size(); ++l) EXPECT_EQ(c.blob_of_led[l], int(l)) << trial;
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 1e-9);
    EXPECT_LT(rotation_error(c.fit.T_camera_body, T), 1e-9);
  }
}

// A constellation with two rear LEDs (normal −x) seen from the front is
// found on its four front LEDs alone, and a pose that would put a matched
// LED's camera outside its cone is refused.
TEST(Correspondence, LedsShiningAwayAreNotMatched) {
  tp::Constellation k;
  const Eigen::Vector3d fwd(1, 0, 0), back(-1, 0, 0);
  k.leds = {{{0.14, 0.09, 0.05}, tp::LedColor::Red, fwd},    {{0.15, -0.08, 0.06}, tp::LedColor::Green, fwd},
            {{0.13, 0.06, -0.06}, tp::LedColor::Green, fwd}, {{0.16, -0.05, -0.05}, tp::LedColor::Red, fwd},
            {{-0.14, 0.05, 0.0}, tp::LedColor::Blue, back},  {{-0.15, -0.05, 0.02}, tp::LedColor::White, back}};
  for (auto& l : k.leds) l.half_angle_deg = 60;
  const auto cam = d435().pinhole();
  touchdown::Rng rng(26);
  int ok = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const auto T = front_toward_camera(rng, rng.uniform(0.4, 1.0));  // four LEDs: close enough to be certain
    auto blobs = blobs_of(k, cam, T, rng, 0.0);
    add_depth(blobs, k, cam, T, rng);  // four near-coplanar LEDs: depth settles the mirrored tilt
    blobs.resize(4);                   // the rear LEDs are not seen
    const auto c = tp::find_correspondences(cam, k, blobs);
    // Four LEDs leave some views poorly determined (Uncertain); the
    // assignment is right either way.
    ASSERT_TRUE(c.ok() || c.status == tp::PoseStatus::Uncertain) << trial << " " << tp::to_string(c.status);
    ok += c.ok();
    EXPECT_EQ(c.matched, 4);
    EXPECT_EQ(c.blob_of_led[4], -1);
    EXPECT_EQ(c.blob_of_led[5], -1);
    // Exact pixels, noisy depths (fused into the fit): mm, not µm.
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 3e-3);
  }
  EXPECT_GE(ok, 15);
  // Seen from behind, the front LEDs' blobs cannot be the front LEDs.
  const auto T = front_toward_camera(rng, 1.0);
  Eigen::Isometry3d behind = T;
  behind.linear() = T.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto blobs = blobs_of(k, cam, behind, rng, 0.0);
  blobs.resize(4);  // the front LEDs, now facing away, drawn anyway
  EXPECT_NE(tp::find_correspondences(cam, k, blobs).status, tp::PoseStatus::Ok);
}

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
    if (c.status == tp::PoseStatus::Uncertain) {  // five LEDs far away: the tilt is poorly determined
      EXPECT_GT(T.translation().z(), 1.5) << trial;
      continue;
    }
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

// Six brighter spots of the LEDs' colours (reflections, lamps) ranked
// before the six LEDs: the first pass over the 10 brightest holds only four
// LEDs and gives no pose; the second pass (max_blobs_retry) finds it. With
// the retry off (max_blobs_retry = max_blobs) there is no pose.
TEST(Correspondence, SecondPassFindsLedsOutshoneByReflections) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(23);
  for (int trial = 0; trial < 10; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.5, 1.2));
    const auto leds = blobs_of(k, cam, T, rng, 0.05);
    std::vector<tp::Blob> blobs;
    for (std::size_t i = 0; i < 6; ++i) {  // each a wide spot 40-80 px off an LED, brighter
      tp::Blob b = leds[i % leds.size()];
      const double a = rng.uniform(0, 2 * std::numbers::pi);
      b.uv_undistorted += rng.uniform(40, 80) * Eigen::Vector2d(std::cos(a), std::sin(a));
      b.uv_px = b.uv_undistorted;
      b.intensity = 3000 + rng.uniform(0, 100);
      blobs.push_back(b);
    }
    blobs.insert(blobs.end(), leds.begin(), leds.end());
    const auto c = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok) << trial;
    EXPECT_EQ(c.matched, static_cast<int>(k.leds.size())) << trial;
    for (std::size_t l = 0; l < k.leds.size(); ++l) EXPECT_EQ(c.blob_of_led[l], int(6 + l)) << trial;
    tp::CorrespondenceOptions first_only;
    first_only.max_blobs_retry = first_only.max_blobs;
    EXPECT_FALSE(tp::find_correspondences(cam, k, blobs, first_only).ok()) << trial;
  }
}

// A blob far larger than the other matched LEDs' is an LED joined with its
// reflection (its centre between the two): it stays out of the fit while
// four others remain (split blobs go out only after it), and is used when
// fewer remain. At an LED's size, the fit takes it and is pulled.
TEST(Correspondence, BlobFarLargerThanTheOthersStaysOutOfTheFit) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(29);
  for (int trial = 0; trial < 10; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.8, 1.5));
    auto blobs = blobs_of(k, cam, T, rng, 0.0);
    blobs[2].uv_undistorted += Eigen::Vector2d(2.0, 1.5);  // pulled toward its reflection
    blobs[2].uv_px = blobs[2].uv_undistorted;
    const auto pulled = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(pulled.status, tp::PoseStatus::Ok) << trial;
    EXPECT_GT(pulled.fit.rms_px, 0.2) << trial;
    blobs[2].area = 3 * blobs[0].area;
    blobs[4].split = blobs[5].split = true;  // four whole + two split: the joined one goes, the split stay
    const auto c = tp::find_correspondences(cam, k, blobs);
    ASSERT_EQ(c.status, tp::PoseStatus::Ok) << trial;
    EXPECT_EQ(c.blob_of_led[2], 2) << trial;  // matched, not fitted
    EXPECT_LT(c.fit.rms_px, 1e-6) << trial;
    EXPECT_LT((c.fit.T_camera_body.translation() - T.translation()).norm(), 1e-6) << trial;
    // LEDs 4 and 5 unseen: three whole ones are too few, the joined one is used.
    std::array<int, tp::kMaxLeds> assignment{};
    assignment.fill(-1);
    for (int l = 0; l < 4; ++l) assignment[static_cast<std::size_t>(l)] = l;
    tp::detail::MatchedSet set;
    tp::detail::gather(k, blobs, assignment, tp::CorrespondenceOptions{}, set);
    EXPECT_EQ(set.n, 4u) << trial;
    assignment[4] = 4;  // with split LED 4: four without the joined one, which goes; the split one stays
    tp::detail::gather(k, blobs, assignment, tp::CorrespondenceOptions{}, set);
    EXPECT_EQ(set.n, 4u) << trial;
  }
}

// The crowding model of a blob centre (CorrespondenceOptions::crowded_*):
// by the nearest other blob's distance in the blob's radii — none beyond
// crowded_radii, the full crowded_bias_px within half of it, the quadratic
// fall in between — and at least split_bias · r for a split blob; gather()
// carries it per matched point, and no bias span when every one is 0.
TEST(Correspondence, CrowdedAndSplitBlobsCarryTheirOwnError) {
  const tp::CorrespondenceOptions o;
  const double noise = o.detection_sigma_px * o.detection_sigma_px;
  const double r = 3.0;
  auto blob_at = [&](double u) {
    tp::Blob b;
    b.area = std::numbers::pi * r * r;
    b.uv_px = b.uv_undistorted = Eigen::Vector2d(u, 100);
    return b;
  };
  auto variance_with_neighbour_at = [&](double radii) {
    const std::vector<tp::Blob> blobs{blob_at(100), blob_at(100 + radii * r)};
    return tp::detail::blob_bias_variance(blobs[0], blobs, o, noise);
  };
  EXPECT_EQ(variance_with_neighbour_at(8.5), 0.0);
  EXPECT_EQ(variance_with_neighbour_at(o.crowded_radii), 0.0);
  EXPECT_NEAR(variance_with_neighbour_at(6.0), std::pow(o.crowded_bias_px * 0.25, 2), 1e-15);
  EXPECT_NEAR(variance_with_neighbour_at(4.0), std::pow(o.crowded_bias_px, 2), 1e-15);
  EXPECT_NEAR(variance_with_neighbour_at(2.0), std::pow(o.crowded_bias_px, 2), 1e-15);
  std::vector<tp::Blob> lone{blob_at(100)};
  EXPECT_EQ(tp::detail::blob_bias_variance(lone[0], lone, o, noise), 0.0);
  lone[0].split = true;
  EXPECT_NEAR(tp::detail::blob_bias_variance(lone[0], lone, o, noise), std::pow(o.split_bias * r, 2), 1e-15);
  tp::CorrespondenceOptions off = o;
  off.crowded_bias_px = 0;
  const std::vector<tp::Blob> pair{blob_at(100), blob_at(100 + 3 * r)};
  EXPECT_EQ(tp::detail::blob_bias_variance(pair[0], pair, off, noise), 0.0);

  // gather(): per matched point, in the set's order.
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(36);
  const Eigen::Isometry3d T = front_toward_camera(rng, 1.0);
  auto blobs = blobs_of(k, cam, T, rng, 0.0);
  const std::array<int, tp::kMaxLeds> assignment = each_led_on_its_blob(k);
  tp::detail::MatchedSet set;
  tp::detail::gather(k, blobs, assignment, off, set);
  EXPECT_TRUE(set.biases().empty());
  blobs.push_back(blobs[1]);  // a lamp right beside LED 1's blob
  blobs.back().uv_px += Eigen::Vector2d(1.0, 0);
  tp::detail::gather(k, blobs, assignment, o, set);
  ASSERT_EQ(set.biases().size(), set.n);
  for (std::size_t i = 0; i < set.n; ++i) {
    const double expected =
        tp::detail::blob_bias_variance(blobs[static_cast<std::size_t>(set.blob[i])], blobs, o, noise);
    EXPECT_EQ(set.biases()[i], expected) << i;
    if (set.blob[i] == 1) {
      EXPECT_GT(expected, 0.0);
    }
  }
}

// A small spot's centre error (CorrespondenceOptions::small_blob_sigma_px3):
// (k / area)² above the noise the fit is judged by, nothing below it, and
// gather() carries it for the noise it is given. The oracle is the
// formula; the figures are chosen so that each branch changes the answer.
TEST(Correspondence, ASmallBlobCarriesItsErrorAboveTheNoiseFloor) {
  tp::CorrespondenceOptions o;
  o.large_blob_sigma_px = 0;  // the small-spot term alone (the large one: the next test)
  tp::Blob b;
  b.area = 10;
  const std::vector<tp::Blob> lone{b};
  const double k = o.small_blob_sigma_px3;
  ASSERT_GT(k, 0.0);
  const double own = std::pow(k / b.area, 2);
  EXPECT_NEAR(tp::detail::blob_bias_variance(lone[0], lone, o, 1e-4), own - 1e-4, 1e-15);
  EXPECT_NEAR(tp::detail::blob_bias_variance(lone[0], lone, o, 0.0), own, 1e-15);
  EXPECT_EQ(tp::detail::blob_bias_variance(lone[0], lone, o, own), 0.0);   // the floor has caught up
  EXPECT_EQ(tp::detail::blob_bias_variance(lone[0], lone, o, 0.04), 0.0);  // the default 0.2 px
  tp::Blob large = b;
  large.area = 100;  // ten times the area: a hundredth of the variance
  const std::vector<tp::Blob> big{large};
  EXPECT_NEAR(tp::detail::blob_bias_variance(big[0], big, o, 0.0), own / 100, 1e-15);
  tp::CorrespondenceOptions off = o;
  off.small_blob_sigma_px3 = 0;
  EXPECT_EQ(tp::detail::blob_bias_variance(lone[0], lone, off, 0.0), 0.0);
  off.small_blob_sigma_px3 = -1;
  EXPECT_FALSE(off.validate(nullptr));

  // gather(): the noise given, else detection_sigma_px².
  const auto kon = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(37);
  const Eigen::Isometry3d T = front_toward_camera(rng, 1.0);
  auto blobs = blobs_of(kon, cam, T, rng, 0.0);
  for (auto& blob : blobs) blob.area = 10;
  const std::array<int, tp::kMaxLeds> assignment = each_led_on_its_blob(kon);
  tp::detail::MatchedSet set;
  tp::detail::gather(kon, blobs, assignment, o, set);
  EXPECT_TRUE(set.biases().empty());  // 0.2 px covers a 10-px spot
  tp::detail::gather(kon, blobs, assignment, o, set, 1e-4);
  ASSERT_EQ(set.biases().size(), set.n);
  for (std::size_t i = 0; i < set.n; ++i) {
    EXPECT_NEAR(set.biases()[i], own - 1e-4, 1e-15) << i;
  }
}

// A large spot's own error grows as large_blob_sigma_px · √area, added in
// variance to the small-spot term; the blob carries its excess over the
// noise floor: nothing at the default 0.007 px floor up to ~200 px, about
// 0.008 px at 450 px.
TEST(Correspondence, ALargeBlobCarriesItsErrorAboveTheNoiseFloor) {
  const tp::CorrespondenceOptions o;
  const double kl = o.large_blob_sigma_px, ks = o.small_blob_sigma_px3;
  ASSERT_GT(kl, 0.0);
  auto lone_variance = [&](double area, double floor, const tp::CorrespondenceOptions& opt) {
    tp::Blob b;
    b.area = area;
    const std::vector<tp::Blob> lone{b};
    return tp::detail::blob_bias_variance(lone[0], lone, opt, floor);
  };
  const double floor = 0.007 * 0.007;
  for (const double area : {100.0, 450.0, 2000.0}) {
    const double own = std::pow(ks / area, 2) + kl * kl * area;
    EXPECT_NEAR(lone_variance(area, 0.0, o), own, 1e-15) << area;
    EXPECT_NEAR(lone_variance(area, floor, o), std::max(0.0, own - floor), 1e-15) << area;
  }
  EXPECT_EQ(lone_variance(150, floor, o), 0.0);  // within the camera's floor
  EXPECT_GT(lone_variance(450, floor, o), 0.0);
  EXPECT_GT(lone_variance(2000, floor, o), 3 * lone_variance(450, floor, o));  // growing with the spot
  tp::CorrespondenceOptions off = o;
  off.large_blob_sigma_px = 0;
  EXPECT_EQ(lone_variance(450, floor, off), 0.0);
  off.large_blob_sigma_px = -1;
  std::string why;
  EXPECT_FALSE(off.validate(&why));
  EXPECT_NE(why.find("large_blob_sigma_px"), std::string::npos) << why;
}

// The P3P pre-test drops hypotheses whose fourth LED is far from where the
// first three put it, before EPnP: the same assignments as without it, from
// far fewer EPnP solves (six LED-coloured distractors around the board and
// one LED unseen, so that the search never stops early).
TEST(Correspondence, P3pPreTestKeepsTheAnswerAndSavesSolves) {
  const auto k = f450();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(31);
  tp::CorrespondenceOptions off;
  off.p3p_gate = 0;
  std::size_t with = 0, without = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.6, 2.5));
    auto blobs = blobs_of(k, cam, T, rng, 0.2);
    blobs.pop_back();
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const auto& b : blobs) centre += b.uv_undistorted / static_cast<double>(blobs.size());
    for (int d = 0; d < 6; ++d) {  // distractors among the LEDs
      tp::Blob x = blobs[static_cast<std::size_t>(d % 5)];
      const double dy = rng.uniform(-60, 60);  // drawn y first, as recorded
      x.uv_undistorted = centre + Eigen::Vector2d(rng.uniform(-60, 60), dy);
      x.uv_px = x.uv_undistorted;
      blobs.push_back(x);
    }
    const auto on = tp::find_correspondences(cam, k, blobs);
    const auto plain = tp::find_correspondences(cam, k, blobs, off);
    EXPECT_EQ(on.status, plain.status) << trial;
    EXPECT_EQ(on.blob_of_led, plain.blob_of_led) << trial;
    with += on.hypotheses;
    without += plain.hypotheses;
  }
  EXPECT_LT(2 * with, without) << with << " vs " << without;
  std::printf("P3P pre-test: %zu EPnP solves vs %zu without\n", with, without);
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

// A board moving faster than the tracking gate per frame (a constant
// 0.04 m/frame across a camera 0.6 m away: ~40 px per frame, gate 15 px):
// the first frames are searched, after which the track's velocity, taken
// from the previous frame's pose even when that came from the search,
// predicts the LEDs within the gate. Without it every frame is searched.
TEST(LedTracker, FastBoardIsTrackedOnceItsVelocityIsKnown) {
  const auto k = f450();
  const auto model = d435();
  const auto cam = model.pinhole();
  tp::LedTracker tracker(model, k);
  touchdown::Rng rng(27);
  Eigen::Isometry3d T = looking_up(rng, 0.6);
  T.translation().x() = -0.25;
  int reinit = 0;
  for (int f = 0; f < 12; ++f) {
    T.translation().x() += 0.04;
    T.linear() = T.linear() * Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const auto& e = tracker.track_blobs(blobs_of(k, cam, T, rng, 0.1));
    ASSERT_TRUE(e.ok()) << "frame " << f << ": " << tp::to_string(e.status);
    reinit += e.reinitialised;
    EXPECT_LT((e.T_camera_body.translation() - T.translation()).norm(), 0.01) << f;
  }
  EXPECT_LE(reinit, 2);
}

// A tracked fit that jumped off a prediction from vouched-for poses is not
// taken: with the jump limits made tiny, every frame of a smooth track goes
// to the full search; with the defaults only the first.
// Two LEDs 1.5 cm apart seen from 1.2 m: their spots merge into one blob
// between them, 1.7× a single LED's area (not enough for the joined-blob
// rule). The LED it is matched to must not pull the fit: the other LED's
// reprojection falls inside the blob, so the blob leaves the fit (five
// LEDs remain).
TEST(LedTracker, BlobTwoLedsShareIsMergedAndStaysOutOfTheFit) {
  tp::Constellation k;
  const std::array<tp::LedColor, 7> colours{tp::LedColor::Red,   tp::LedColor::Green, tp::LedColor::Blue,
                                            tp::LedColor::White, tp::LedColor::Red,   tp::LedColor::Green,
                                            tp::LedColor::Blue};
  const std::array<Eigen::Vector3d, 7> at{Eigen::Vector3d(-0.2, -0.15, 0),   Eigen::Vector3d(0.2, -0.15, 0.06),
                                          Eigen::Vector3d(0.2, 0.15, 0),     Eigen::Vector3d(-0.2, 0.15, 0.08),
                                          Eigen::Vector3d(0, 0, 0.03),       Eigen::Vector3d(0.2, -0.135, 0.06),
                                          Eigen::Vector3d(-0.05, 0.12, 0.04)};
  for (std::size_t i = 0; i < at.size(); ++i) k.leds.push_back({at[i], colours[i]});
  const auto cam = d435();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  T.translation() << 0.1, -0.05, 1.2;
  auto run = [&](double margin) {
    tp::TrackerOptions o;
    o.shared_blob_margin_px = margin;
    tp::LedTracker tracker(cam, k, o);
    touchdown::Rng rng(48);
    double worst = 0;
    int ok = 0;
    for (int f = 0; f < 20; ++f) {
      auto blobs = blobs_of(k, cam.pinhole(), T, rng, 0.05);
      for (auto& b : blobs) b.area = 30;
      blobs[1].uv_undistorted = blobs[1].uv_px = 0.5 * (blobs[1].uv_undistorted + blobs[5].uv_undistorted);
      blobs[1].area = 50;
      blobs.erase(blobs.begin() + 5);
      const auto& e = tracker.track_blobs(blobs);
      if (!e.ok()) continue;
      ++ok;
      worst = std::max(worst, rotation_error(e.T_camera_body, T));
      if (margin < 0) continue;
      EXPECT_EQ(e.points, 5) << f;                       // the merged blob is out of the fit
      for (std::size_t l = 0; l < k.leds.size(); ++l) {  // and held by the two LEDs merged in it
        const int b = tracker.led_to_blob()[l];
        EXPECT_GE(b, 0) << f << " LED " << l;
        if (b < 0) continue;
        EXPECT_EQ(tracker.blobs()[static_cast<std::size_t>(b)].area == 50, l == 1 || l == 5) << f << " LED " << l;
      }
    }
    return std::pair{ok, worst};
  };
  const auto [ok_on, worst_on] = run(0.5);
  EXPECT_GE(ok_on, 19);
  EXPECT_LT(worst_on, 0.005);
  // Without the rule the blob pulls the fit: the poses are worse, or — now
  // that the track's pooled noise is not capped at the 0.2 px default — its
  // residual widens the σ past the limit and no pose is reported (seen: 0
  // of 20 Ok).
  const auto [ok_off, worst_off] = run(-1);
  EXPECT_TRUE(ok_off <= ok_on / 2 || worst_off > 3 * worst_on) << ok_off << " Ok, worst " << worst_off;
}

TEST(LedTracker, JumpOffThePredictionGoesToTheSearch) {
  const auto k = f450();
  const auto model = d435();
  const auto cam = model.pinhole();
  tp::TrackerOptions tight;
  tight.max_jump_m = 1e-6;
  tight.max_jump_rad = 1e-6;
  for (const bool jump_limited : {false, true}) {
    tp::LedTracker tracker(model, k, jump_limited ? tight : tp::TrackerOptions{});
    touchdown::Rng rng(33);
    Eigen::Isometry3d T = looking_up(rng, 1.0);
    int reinit = 0;
    for (int f = 0; f < 10; ++f) {
      T.translation().x() += 0.01;
      const auto& e = tracker.track_blobs(blobs_of(k, cam, T, rng, 0.1));
      ASSERT_TRUE(e.ok()) << f;
      reinit += e.reinitialised;
    }
    EXPECT_EQ(reinit, jump_limited ? 10 : 1) << jump_limited;
  }
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
  using C = tp::CorrespondenceOptions;
  touchdown::test::expect_validate_names_fields<C>({
      {"search_min_leds:", [](C& c) { c.search_min_leds = 3; }},
      {"min_leds:", [](C& c) { c.min_leds = 2; }},
      {"max_sigma_rotation_rad:", [](C& c) { c.max_sigma_rotation_rad = 0; }},
      {"attitude_max_sigma_position_m:", [](C& c) { c.attitude_max_sigma_position_m = 0; }},
      {"attitude_max_sigma_rotation_rad:", [](C& c) { c.attitude_max_sigma_rotation_rad = -1; }},
  });
  using O = tp::TrackerOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"noise_pool_frames:", [](O& t) { t.noise_pool_frames = -1; }},
      {"noise_pool_min_fits:", [](O& t) { t.noise_pool_min_fits = 0; }},
      {"noise_pool_min_fits:", [](O& t) { t.noise_pool_min_fits = 31; }},
      {"shared_blob_margin_px:", [](O& t) { t.shared_blob_margin_px = std::nan(""); }},
      {"min_detection_sigma_px:", [](O& t) { t.min_detection_sigma_px = 0; }},
      {"min_detection_sigma_px:", [](O& t) { t.min_detection_sigma_px = 0.5; }},
      {"unpooled_noise_confidence:", [](O& t) { t.unpooled_noise_confidence = 1; }},
      {"unpooled_noise_confidence:", [](O& t) { t.unpooled_noise_confidence = -0.1; }},
      {"outlier_rms_factor:", [](O& t) { t.outlier_rms_factor = -1; }},
      {"track_min_leds:", [](O& t) { t.track_min_leds = 2; }},
      {"track_min_leds:", [](O& t) { t.track_min_leds = 5; }},
      {"few_led_jump_m:", [](O& t) { t.few_led_jump_m = 0; }},
      {"few_led_jump_rad:", [](O& t) { t.few_led_jump_rad = std::nan(""); }},
      {"few_point_prediction_sigma_factor:", [](O& t) { t.few_point_prediction_sigma_factor = 0.5; }},
  });
}

// Without a prior, four LEDs of a board that should show six are not
// enough: four exact blobs of the front board give no pose from the search
// (the two others dropped out), five do; a four-LED view of a board whose
// other LEDs face away still does (Correspondence.LedsShiningAwayAreNotMatched).
TEST(Correspondence, SearchNeedsFiveLedsWhenMoreShouldShow) {
  const auto k = tp::front_board_constellation();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(48);
  for (int trial = 0; trial < 10; ++trial) {
    const auto T = front_toward_camera(rng, rng.uniform(0.5, 0.9));
    auto blobs = blobs_of(k, cam, T, rng, 0.0);
    add_depth(blobs, k, cam, T, rng);
    auto four = blobs;
    four.resize(4);
    EXPECT_EQ(tp::find_correspondences(cam, k, four).status, tp::PoseStatus::NoConsistentCorrespondence) << trial;
    auto five = blobs;
    five.resize(5);
    const auto c = tp::find_correspondences(cam, k, five);
    EXPECT_TRUE(c.ok() || c.status == tp::PoseStatus::Uncertain) << trial << " " << tp::to_string(c.status);
    EXPECT_EQ(c.matched, 5) << trial;
    tp::CorrespondenceOptions lax;
    lax.search_min_leds = 4;  // the old rule accepts the four
    EXPECT_NE(tp::find_correspondences(cam, k, four, lax).status, tp::PoseStatus::NoConsistentCorrespondence) << trial;
  }
}

// ---- never a confident wrong pose (issue 9, item 3) ---------------------------

namespace {

// A quasi-planar board (5 mm relief) in the body x-y plane, shining along
// −z, with no rigid symmetry.
tp::Constellation quasi_planar_board() {
  tp::Constellation k;
  const Eigen::Vector3d down(0, 0, -1);
  k.leds = {
      {{0.090, 0.060, -0.050}, tp::LedColor::Red, down},     {{0.090, -0.060, -0.055}, tp::LedColor::Red, down},
      {{-0.090, -0.060, -0.050}, tp::LedColor::Green, down}, {{-0.090, 0.060, -0.055}, tp::LedColor::Green, down},
      {{0.000, 0.080, -0.052}, tp::LedColor::Blue, down},    {{0.030, -0.020, -0.050}, tp::LedColor::White, down}};
  return k;
}

// The quasi-planar board 0.1–0.4 rad off facing the camera, turned freely
// about its normal, at a distance in [z_min, z_max] [m].
Eigen::Isometry3d board_seen_from_below(touchdown::Rng& rng, double z_min, double z_max) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double axis_y = rng.uniform(-1, 1);  // drawn right to left, as recorded
  const Eigen::Vector3d axis(rng.uniform(-1, 1), axis_y, 0);
  const double tilt = rng.uniform(0.1, 0.4);
  T.linear() = (Eigen::AngleAxisd(rng.uniform(-M_PI, M_PI), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(tilt, axis.normalized()))
                   .toRotationMatrix();
  T.translation() << rng.uniform(-0.1, 0.1), rng.uniform(-0.05, 0.05), rng.uniform(z_min, z_max);
  return T;
}

bool wrong(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  return (estimate.translation() - truth.translation()).norm() > 0.1 || rotation_error(estimate, truth) > 0.1;
}

}  // namespace

// A square of four white LEDs: a quarter turn maps it onto itself, so no
// single frame tells the four poses apart. Once reported "found" with an
// exact fit and 2 rad of rotation error; now Ambiguous.
TEST(Ambiguity, SymmetricConstellationIsAmbiguousNotAGuess) {
  tp::Constellation k;
  for (int i = 0; i < 4; ++i) {
    const double a = M_PI / 2 * i + M_PI / 4;
    k.leds.push_back({{0.1 * std::cos(a), 0.1 * std::sin(a), 0.0}, tp::LedColor::White, {0, 0, -1}});
  }
  const auto cam = d435().pinhole();
  touchdown::Rng rng(41);
  for (int trial = 0; trial < 20; ++trial) {
    const auto T = looking_up(rng, rng.uniform(0.5, 2.5));
    const auto c = tp::find_correspondences(cam, k, blobs_of(k, cam, T, rng, 0.1));
    EXPECT_EQ(c.status, tp::PoseStatus::Ambiguous) << trial;
  }
  // One LED of another colour breaks the symmetry (the normals rule out
  // the flip about its diagonal).
  k.leds[0].color = tp::LedColor::Red;
  const auto T = looking_up(rng, 0.6);
  const auto c = tp::find_correspondences(cam, k, blobs_of(k, cam, T, rng, 0.0));
  ASSERT_EQ(c.status, tp::PoseStatus::Ok);
  EXPECT_FALSE(wrong(c.fit.T_camera_body, T));
}

// The branch test in the camera's measured noise (the tracker's noise pool:
// CorrespondenceOptions::detection_sigma_measured). A quiet camera (0.03 px)
// sees the quasi-planar board at 1.5–3 m: against the 0.2 px default the
// mirrored branch's misfit looks like noise and many frames stay open;
// judged by the measured noise and the better branch's residual, the true
// branch is kept — and never switched away from.
TEST(Ambiguity, MeasuredNoiseSettlesWhatTheDefaultFloorCannot) {
  const auto k = quasi_planar_board();
  const auto cam = d435().pinhole();
  const auto shape = tp::detail::ConstellationShape::of(k);
  touchdown::Rng rng(48);
  tp::CorrespondenceOptions by_default, measured;
  measured.detection_sigma_px = 0.03;
  measured.detection_sigma_measured = true;
  int keep_default = 0, keep_measured = 0, switch_measured = 0, trials = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Isometry3d T = board_seen_from_below(rng, 1.5, 3.0);
    const auto blobs = blobs_of(k, cam, T, rng, 0.03);
    const std::array<int, tp::kMaxLeds> assignment = each_led_on_its_blob(k);
    tp::detail::MatchedSet set;
    tp::detail::gather(k, blobs, assignment, by_default, set);
    const auto fit = tp::refine_pose_gauss_newton(cam, set.points(), set.pixels(), T);
    ASSERT_TRUE(fit.ok()) << trial;
    const auto a = tp::detail::resolve_branches(cam, k, shape, blobs, assignment, set, fit, nullptr, by_default);
    const auto b = tp::detail::resolve_branches(cam, k, shape, blobs, assignment, set, fit, nullptr, measured);
    ++trials;
    keep_default += a.verdict == tp::detail::BranchVerdict::Keep;
    keep_measured += b.verdict == tp::detail::BranchVerdict::Keep;
    switch_measured += b.verdict == tp::detail::BranchVerdict::Switch;
  }
  EXPECT_EQ(switch_measured, 0);  // the true branch is never given up
  // Seen: 17 of 60 kept by default, 60 of 60 in the measured noise.
  EXPECT_GE(keep_measured, 55) << keep_default << " / " << keep_measured << " of " << trials;
  EXPECT_GT(keep_measured, keep_default + 20) << keep_default << " / " << keep_measured << " of " << trials;
}

// When the reprojection rules out one branch and the depth pattern the
// other, the two independent χ² add and the stronger evidence wins. Blobs
// at the true pose's exact projections with the depths the mirrored branch
// would show: with a quiet camera's noise (image χ² ∝ 1/σ²) the image
// keeps the fit, as σ grows the depths switch it — never back — and in
// between the sum may be too small to decide (Ambiguous). A prediction
// does not overrule the measurements. With the true depths, the fit is kept.
TEST(Ambiguity, ReprojectionAndDepthDisagreeingAddUp) {
  const auto k = quasi_planar_board();
  const auto cam = d435().pinhole();
  const auto shape = tp::detail::ConstellationShape::of(k);
  touchdown::Rng rng(53);
  int both_ends = 0, contradicted = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Isometry3d T = board_seen_from_below(rng, 0.8, 1.6);
    auto blobs = blobs_of(k, cam, T, rng, 0.0);
    const std::array<int, tp::kMaxLeds> assignment = each_led_on_its_blob(k);
    tp::CorrespondenceOptions o;
    o.detection_sigma_measured = true;
    tp::detail::MatchedSet set;
    tp::detail::gather(k, blobs, assignment, o, set);
    const auto fit = tp::refine_pose_gauss_newton(cam, set.points(), set.pixels(), T);
    ASSERT_TRUE(fit.ok()) << trial;
    auto verdict_at = [&](double sigma_px, const Eigen::Isometry3d* predicted = nullptr) {
      o.detection_sigma_px = sigma_px;
      return tp::detail::resolve_branches(cam, k, shape, blobs, assignment, set, fit, predicted, o);
    };
    const auto plain = verdict_at(0.005);
    if (!plain.alternative.ok() || plain.verdict != tp::detail::BranchVerdict::Keep) continue;  // no distinct branch
    const Eigen::Isometry3d mirrored = plain.alternative.T_camera_body;
    auto set_depths = [&](const Eigen::Isometry3d& pose) {
      for (std::size_t l = 0; l < k.leds.size(); ++l) {
        blobs[l].has_point = true;
        blobs[l].p_camera = cam.back_project(blobs[l].uv_undistorted, (pose * k.leds[l].p_body).z());
      }
    };
    set_depths(T);
    EXPECT_EQ(verdict_at(0.05).verdict, tp::detail::BranchVerdict::Keep) << trial;
    set_depths(mirrored);
    bool switched = false, kept = false;
    for (const double sigma : {0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0}) {
      const auto d = verdict_at(sigma);
      if (d.verdict == tp::detail::BranchVerdict::Switch) switched = true;
      if (d.verdict == tp::detail::BranchVerdict::Keep) {
        EXPECT_FALSE(switched) << trial << ": kept again at σ " << sigma;
        kept = true;
      }
      if (d.contradicted) {
        ++contradicted;
        EXPECT_EQ(verdict_at(sigma, &T).verdict, d.verdict) << trial << " σ " << sigma;
      }
    }
    both_ends += kept && switched;
  }
  EXPECT_GE(both_ends, 10);
  EXPECT_GE(contradicted, 10);
}

// A prediction settles a branch the image leaves open — but one not made
// from Ok poses (after a too-uncertain frame) only where the image does not
// lean the other way. Blobs at the mirrored branch's exact projections, the
// fit refined on the true pose's branch: the image leans toward the other
// branch by a χ² of 4 (under branch_chi2, 9). Vouched, the prediction keeps
// the fit; unvouched, it cannot (Ambiguous), but it may switch to the
// branch the image leans toward; no prediction: Ambiguous.
TEST(Ambiguity, AnUnvouchedPredictionDoesNotOverruleALeaningImage) {
  using tp::detail::BranchVerdict;
  const auto k = quasi_planar_board();
  const auto cam = d435().pinhole();
  const auto shape = tp::detail::ConstellationShape::of(k);
  touchdown::Rng rng(61);
  int cases = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const Eigen::Isometry3d T = board_seen_from_below(rng, 1.5, 3.0);
    const Eigen::Isometry3d mirrored = tp::detail::mirrored_branch(T, shape);
    if (!tp::detail::distinct_poses(T, mirrored, tp::CorrespondenceOptions{})) continue;
    const auto blobs = blobs_of(k, cam, mirrored, rng, 0.0);
    const std::array<int, tp::kMaxLeds> assignment = each_led_on_its_blob(k);
    tp::CorrespondenceOptions o;
    o.detection_sigma_measured = true;
    tp::detail::MatchedSet set;
    tp::detail::gather(k, blobs, assignment, o, set);
    const auto fit = tp::refine_pose_gauss_newton(cam, set.points(), set.pixels(), T);
    if (!fit.ok() || !tp::detail::distinct_poses(fit.T_camera_body, mirrored, o)) continue;  // slid onto the other
    const double excess = static_cast<double>(set.n) * fit.rms_px * fit.rms_px;  // the alternative fits exactly
    if (!(excess > 1e-12)) continue;
    o.detection_sigma_px = std::sqrt(excess / 4);  // the image leans toward the other branch at χ² 4
    auto verdict = [&](const Eigen::Isometry3d* predicted, bool vouched) {
      return tp::detail::resolve_branches(cam, k, shape, blobs, assignment, set, fit, predicted, o, {}, vouched);
    };
    const auto none = verdict(nullptr, true);
    if (!none.alternative.ok() || none.alternative.rms_px > 0.1 * fit.rms_px) continue;  // not the exact branch
    ++cases;
    EXPECT_EQ(none.verdict, BranchVerdict::Ambiguous) << trial;
    const Eigen::Isometry3d on_fit = fit.T_camera_body;
    const Eigen::Isometry3d on_other = none.alternative.T_camera_body;
    EXPECT_EQ(verdict(&on_fit, true).verdict, BranchVerdict::Keep) << trial;
    EXPECT_EQ(verdict(&on_fit, false).verdict, BranchVerdict::Ambiguous) << trial;
    EXPECT_EQ(verdict(&on_other, false).verdict, BranchVerdict::Switch) << trial;
    EXPECT_EQ(verdict(&on_other, true).verdict, BranchVerdict::Switch) << trial;
  }
  EXPECT_GE(cases, 10);
}

// The mirrored branch of a planar board seen from afar reprojects almost
// as well as the truth and is a different pose (the weak-perspective flip).
TEST(Ambiguity, MirroredBranchIsTheOtherPlanarSolution) {
  const auto k = quasi_planar_board();
  const auto cam = d435().pinhole();
  const auto shape = tp::detail::ConstellationShape::of(k);
  EXPECT_GT(std::abs(shape.plane_normal.z()), 0.99);  // the board's plane is body x-y
  EXPECT_FALSE(shape.symmetric);
  touchdown::Rng rng(42);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.35, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();  // 20° tilt
  T.translation() << 0.1, -0.05, 3.0;
  const auto blobs = blobs_of(k, cam, T, rng, 0.0);
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Vector2d> uv;
  for (std::size_t i = 0; i < k.leds.size(); ++i) {
    p.push_back(k.leds[i].p_body);
    uv.push_back(blobs[i].uv_undistorted);
  }
  const auto alt = tp::refine_pose_gauss_newton(cam, p, uv, tp::detail::mirrored_branch(T, shape));
  ASSERT_TRUE(alt.ok());
  EXPECT_GT(rotation_error(alt.T_camera_body, T), 0.3);  // a different pose ...
  EXPECT_LT(alt.rms_px, 0.5);                            // ... that fits nearly as well
}

// Quasi-planar board far away and near-frontal, noisy blobs, no depth: every
// pose reported Ok is right; frames the evidence cannot settle are
// Ambiguous. With depth at the blobs, the branches are told apart.
TEST(Ambiguity, QuasiPlanarBoardIsNeverConfidentlyWrong) {
  const auto k = quasi_planar_board();
  const auto cam = d435().pinhole();
  touchdown::Rng rng(43);
  int ok = 0, ambiguous = 0, uncertain = 0, ok_with_depth = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Isometry3d T = board_seen_from_below(rng, 0.8, 1.6);
    auto blobs = blobs_of(k, cam, T, rng, 0.4);
    const auto c = tp::find_correspondences(cam, k, blobs);
    if (c.ok()) {
      ++ok;
      EXPECT_FALSE(wrong(c.fit.T_camera_body, T)) << trial << " rot err " << rotation_error(c.fit.T_camera_body, T);
    }
    ambiguous += c.status == tp::PoseStatus::Ambiguous;
    uncertain += c.status == tp::PoseStatus::Uncertain;
    add_depth(blobs, k, cam, T, rng);
    const auto d = tp::find_correspondences(cam, k, blobs);
    if (d.ok()) {
      ++ok_with_depth;
      EXPECT_FALSE(wrong(d.fit.T_camera_body, T)) << trial;
    }
  }
  // Seen 2026-11-23: 18 ok, 29 ambiguous, 13 uncertain; 36 ok with depth.
  EXPECT_GT(ambiguous, 10) << ok << " ok, " << uncertain << " uncertain";  // the mechanism does fire at this range ...
  EXPECT_GT(ok_with_depth, ok + 10);  // ... and depth settles much of what it could not
}

// The reported 1-σ position and rotation match the scatter of the
// estimates under 0.5 px of blob noise — more than the 0.2 px default floor
// assumes — within a factor of two, once the track has pooled its fits'
// noise (the seventh frame of each track: the first is the search, not
// pooled; the pool is not capped at the default floor). Seen: 1.15× and
// 1.12×; before the pool vouches the σ is an upper bound (below).
TEST(LedTracker, SigmaMatchesTheObservedScatter) {
  const auto k = f450();
  const auto cam = d435();
  touchdown::Rng rng(44);
  const Eigen::Isometry3d T = f450_from_below(1.0);
  double sum_sq = 0, sum_sigma = 0, sum_rot_sq = 0, sum_rot_sigma = 0;
  const int trials = 200;
  tp::TrackerOptions o;
  o.correspondence.max_sigma_position_m = o.correspondence.max_sigma_rotation_rad = 1;  // calibration, not the gate
  for (int i = 0; i < trials; ++i) {
    tp::LedTracker tracker(cam, k, o);
    for (int f = 0; f <= o.noise_pool_min_fits; ++f) (void)tracker.track_blobs(blobs_of(k, cam.pinhole(), T, rng, 0.5));
    const auto& e = tracker.track_blobs(blobs_of(k, cam.pinhole(), T, rng, 0.5));
    ASSERT_TRUE(e.ok()) << i << ": " << tp::to_string(e.status);
    sum_sq += (e.T_camera_body.translation() - T.translation()).squaredNorm();
    sum_sigma += e.sigma_position_m;
    sum_rot_sq += std::pow(rotation_error(e.T_camera_body, T), 2);
    sum_rot_sigma += e.sigma_rotation_rad;
  }
  const double rms = std::sqrt(sum_sq / trials), sigma = sum_sigma / trials;
  EXPECT_GT(sigma, 0.75 * rms);
  EXPECT_LT(sigma, 1.5 * rms);
  const double rot_rms = std::sqrt(sum_rot_sq / trials), rot_sigma = sum_rot_sigma / trials;
  EXPECT_GT(rot_sigma, 0.75 * rot_rms);
  EXPECT_LT(rot_sigma, 1.5 * rot_rms);
}

// The χ² quantile behind the bound, against the closed form for 2 degrees
// of freedom (−2 ln(1 − p)) and printed tables (NIST/SEMATECH e-Handbook,
// 1.3.6.7.4), the 99.9 % point for 6 included (the NEES bound of the
// benchmarks, 22.458).
TEST(LedTracker, ChiSquareQuantileMatchesTables) {
  for (const double p : {0.001, 0.05, 0.5, 0.95, 0.999}) {
    EXPECT_NEAR(tp::detail::chi2_quantile(2, p), -2 * std::log(1 - p), 1e-9) << p;
  }
  EXPECT_NEAR(tp::detail::chi2_quantile(1, 0.05), 0.00393, 1e-5);
  EXPECT_NEAR(tp::detail::chi2_quantile(6, 0.05), 1.635, 1e-3);
  EXPECT_NEAR(tp::detail::chi2_quantile(10, 0.05), 3.940, 1e-3);
  EXPECT_NEAR(tp::detail::chi2_quantile(3, 0.999), 16.266, 1e-3);
  EXPECT_NEAR(tp::detail::chi2_quantile(6, 0.999), 22.458, 1e-3);
  EXPECT_NEAR(tp::detail::chi2_quantile(30, 0.95), 43.773, 1e-3);
}

// The first frame of a track, on a camera noisier than the default floor:
// its σ rests on the frame's own σ̂² (6 degrees of freedom here), which is
// often well below the noise by chance. Raised to its 95 % upper bound
// (TrackerOptions::unpooled_noise_confidence) the σ covers the error: few
// Ok frames beyond 3 σ — where the point estimate leaves several times as
// many.
TEST(LedTracker, FirstFrameSigmaCoversTheErrorOfANoisyCamera) {
  const auto k = f450();
  const auto cam = d435();
  const Eigen::Isometry3d T = f450_from_below(1.0);
  auto beyond = [&](double confidence) {
    touchdown::Rng rng(46);
    tp::TrackerOptions o;
    o.unpooled_noise_confidence = confidence;
    o.correspondence.max_sigma_position_m = o.correspondence.max_sigma_rotation_rad = 1;  // every frame counts
    int ok = 0, out = 0;
    for (int i = 0; i < 1000; ++i) {
      tp::LedTracker tracker(cam, k, o);
      const auto& e = tracker.track_blobs(blobs_of(k, cam.pinhole(), T, rng, 0.5));
      if (!e.ok()) continue;
      ++ok;
      out += (e.T_camera_body.translation() - T.translation()).norm() > 3 * e.sigma_position_m ||
             rotation_error(e.T_camera_body, T) > 3 * e.sigma_rotation_rad;
    }
    return std::pair{ok, out};
  };
  const auto [ok, out] = beyond(tp::TrackerOptions{}.unpooled_noise_confidence);
  const auto [ok_point, out_point] = beyond(0);
  EXPECT_GT(ok, 900);
  EXPECT_GT(ok_point, 900);
  EXPECT_LE(out, 10);                          // seen: 3 of 1000
  EXPECT_GE(out_point, 3 * std::max(out, 3));  // seen: 36
}

// A sensor quieter than the default floor (detection_sigma_px = 0.2 px):
// once the track has pooled its fits' noise, the reported sigma follows the
// observed scatter instead of the floor; with the pool off it overstates it.
TEST(LedTracker, PooledNoiseFloorFollowsAQuietSensor) {
  const auto k = f450();
  const auto cam = d435();
  const Eigen::Isometry3d T = f450_from_below(1.5);
  auto run = [&](int pool) {
    touchdown::Rng rng(45);
    tp::TrackerOptions o;
    o.noise_pool_frames = pool;
    tp::LedTracker tracker(cam, k, o);
    double sum_sq = 0, sum_sigma = 0;
    int n = 0;
    for (int i = 0; i < 400; ++i) {
      const auto& e = tracker.track_blobs(blobs_of(k, cam.pinhole(), T, rng, 0.06));
      EXPECT_TRUE(e.ok());
      if (i < 40 || !e.ok()) continue;  // the pool is warm after 10 tracked fits
      sum_sq += std::pow(rotation_error(e.T_camera_body, T), 2);
      sum_sigma += e.sigma_rotation_rad;
      ++n;
    }
    return std::pair{std::sqrt(sum_sq / n), sum_sigma / n};
  };
  const auto [rms, sigma] = run(30);
  EXPECT_GT(sigma, 0.5 * rms);
  EXPECT_LT(sigma, 2.0 * rms);
  const auto [rms_fixed, sigma_fixed] = run(0);
  EXPECT_GT(sigma_fixed, 2.5 * rms_fixed);
}

// The pool replaces the default floor once it holds noise_pool_min_fits
// tracked fits, not before: with a quiet sensor the sigma drops at that
// frame (the first frame is the search's, which is not pooled).
TEST(LedTracker, PooledFloorStartsAfterItsMinimumFits) {
  const auto k = f450();
  const auto cam = d435();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 0.05, 0.02, 1.5;
  for (const int min_fits : {3, 8}) {
    touchdown::Rng rng(46);
    tp::TrackerOptions o;
    o.noise_pool_min_fits = min_fits;
    tp::LedTracker tracker(cam, k, o);
    std::vector<double> sigma;
    for (int i = 0; i < 12; ++i) {
      const auto& e = tracker.track_blobs(blobs_of(k, cam.pinhole(), T, rng, 0.03));
      ASSERT_TRUE(e.ok()) << i;
      sigma.push_back(e.sigma_rotation_rad);
    }
    // Frame i is fitted with i - 1 pooled fits.
    for (int i = 1; i < 12; ++i) {
      if (i - 1 < min_fits) {
        EXPECT_GT(sigma[i], 2 * sigma[11]) << "min_fits " << min_fits << " frame " << i;
      } else {
        EXPECT_LT(sigma[i], 1.5 * sigma[11]) << "min_fits " << min_fits << " frame " << i;
      }
    }
  }
}

namespace {

// Frame f of 40 of an approach from `far` to 0.9 m at a steady speed,
// turning slowly (0.3 rad about the camera's z over the 40 frames).
Eigen::Isometry3d approach(const Eigen::Isometry3d& far, int f) {
  const double s = f / 39.0;
  Eigen::Isometry3d T = far;
  T.translation() = far.translation() * (1 - s) + Eigen::Vector3d(0.02, -0.01, 0.9) * s;
  T.linear() = Eigen::AngleAxisd(0.3 * s, Eigen::Vector3d::UnitZ()).toRotationMatrix() * far.linear();
  return T;
}

}  // namespace

// A tracked frame may rest on three LEDs right after an Ok frame
// (TrackerOptions::track_min_leds: an LED dropped out or left the image):
// the prediction picks the P3P solution and vouches for it. A 4-LED board
// (four of the F450's LEDs, not planar) loses one LED in frames 12 and 20:
// both Ok on three points and right, their σ covering the error, and the
// track goes on (frame 13 Ok; without the option 12 is too few blobs and 13
// a new search that needs confirming). Not Ok on three LEDs after a frame
// without a pose (24, after the track was lost in 23), nor when the board
// turned 0.08 rad more than the prediction (frame 28: nothing else checks a
// three-point fit) — unless few_led_jump_rad allows it.
TEST(LedTracker, ATrackedFrameRestsOnThreeLedsAfterAnOkFrame) {
  const auto f = f450();
  tp::Constellation k;
  for (const int i : {0, 2, 4, 5}) k.leds.push_back(f.leds[static_cast<std::size_t>(i)]);
  const auto cam = d435();
  auto pose = [](int frame) { return f450_from_below(1.0, frame, frame >= 28 ? 0.08 : 0.0); };
  auto run = [&](const tp::TrackerOptions& o) {
    tp::LedTracker tracker(cam, k, o);
    touchdown::Rng rng(49);
    std::vector<tp::PoseEstimate> out;
    for (int frame = 0; frame < 29; ++frame) {
      auto blobs = blobs_of(k, cam.pinhole(), pose(frame), rng, 0.1);
      if (frame == 12 || frame == 20 || frame == 24 || frame == 28) blobs.erase(blobs.begin() + 1);  // LED 1 out
      if (frame == 23) blobs.resize(2);
      out.push_back(tracker.track_blobs(blobs));
    }
    return out;
  };
  auto right = [&](const tp::PoseEstimate& e, int frame) {
    const Eigen::Isometry3d T = pose(frame);
    const double dp = (e.T_camera_body.translation() - T.translation()).norm();
    const double dr = rotation_error(e.T_camera_body, T);
    return dp < 0.01 && dr < 0.01 && dp < 3 * e.sigma_position_m && dr < 3 * e.sigma_rotation_rad;
  };
  const tp::TrackerOptions defaults;
  const auto with = run(defaults);
  for (const int frame : {12, 20}) {
    const tp::PoseEstimate& e = with[static_cast<std::size_t>(frame)];
    ASSERT_TRUE(e.ok()) << frame << ": " << tp::to_string(e.status);
    EXPECT_EQ(e.points, 3) << frame;
    EXPECT_TRUE(right(e, frame)) << frame;
  }
  EXPECT_TRUE(with[11].ok() && with[13].ok() && with[22].ok() && with[27].ok());
  EXPECT_EQ(with[23].status, tp::PoseStatus::TooFewBlobs);
  EXPECT_EQ(with[24].status, tp::PoseStatus::TooFewBlobs);
  EXPECT_FALSE(with[28].ok()) << tp::to_string(with[28].status);
  tp::TrackerOptions loose;
  loose.few_led_jump_rad = 0.1;
  const auto turned = run(loose);
  ASSERT_TRUE(turned[28].ok()) << tp::to_string(turned[28].status);
  EXPECT_TRUE(right(turned[28], 28));
  tp::TrackerOptions off;
  off.track_min_leds = off.correspondence.min_leds;
  const auto without = run(off);
  EXPECT_EQ(without[12].status, tp::PoseStatus::TooFewBlobs);
  EXPECT_EQ(without[20].status, tp::PoseStatus::TooFewBlobs);
  EXPECT_FALSE(without[13].ok());
  EXPECT_TRUE(without[14].ok());
}

// One wrong blob in a tracked fit: in frame 12 of a tracked F450 (six LEDs)
// LED 3's spot is replaced by a flash 4 px off its place. The fit
// reprojects far worse than the track's pooled noise; without that blob it
// fits at the noise again, so the blob leaves the fit
// (TrackerOptions::outlier_rms_factor = 5; off by default) and the pose
// stays right on five LEDs. With the test off the flash pulls the fit.
TEST(LedTracker, AWrongBlobLeavesATrackedFit) {
  const auto k = f450();
  const auto cam = d435();
  auto pose = [](int frame) { return f450_from_below(1.6, frame); };
  auto run = [&](double factor) {
    tp::TrackerOptions o;
    o.outlier_rms_factor = factor;
    o.correspondence.max_sigma_position_m = o.correspondence.max_sigma_rotation_rad = 1;  // the error, not the gate
    tp::LedTracker tracker(cam, k, o);
    touchdown::Rng rng(50);
    tp::PoseEstimate e;
    for (int frame = 0; frame <= 12; ++frame) {
      auto blobs = blobs_of(k, cam.pinhole(), pose(frame), rng, 0.05);
      if (frame == 12) blobs[3].uv_undistorted = blobs[3].uv_px = blobs[3].uv_undistorted + Eigen::Vector2d(4, 0);
      e = tracker.track_blobs(blobs);
    }
    return std::pair{e, tracker.led_to_blob()[3]};
  };
  const auto [with, led3] = run(5);
  ASSERT_TRUE(with.ok()) << tp::to_string(with.status);
  EXPECT_EQ(with.points, 5);
  EXPECT_EQ(led3, -1);
  EXPECT_LT(with.rms_px, 0.2);
  const Eigen::Isometry3d T = pose(12);
  const double err = rotation_error(with.T_camera_body, T);
  const auto [without, kept] = run(0);
  ASSERT_TRUE(without.ok()) << tp::to_string(without.status);
  EXPECT_EQ(without.points, 6);
  EXPECT_GT(without.rms_px, 0.5);
  EXPECT_GT(rotation_error(without.T_camera_body, T), 3 * err);
}

// Four LEDs of a larger constellation in a tracked fit must reproject
// within minimal_fit_rms_px, as in the search: the F450 seen with two LEDs
// hidden and one of the four spots 5 px off (a reflection taken for it)
// gives no pose in frame 12, where a fit on four absorbs the error to
// 0.6 px RMS (the σ limit lifted: the rule holds whatever limit a user
// sets; a 3 px error is absorbed to 0.28 px, below the rule).
TEST(LedTracker, FourLedsOfALargerBoardMustFitAsInTheSearch) {
  const auto k = f450();
  const auto cam = d435();
  auto frame12 = [&](double minimal_fit_rms_px) {
    tp::TrackerOptions o;
    o.correspondence.minimal_fit_rms_px = minimal_fit_rms_px;
    o.correspondence.max_sigma_position_m = o.correspondence.max_sigma_rotation_rad = 1;  // the rule, not the gate
    tp::LedTracker tracker(cam, k, o);
    touchdown::Rng rng(51);
    tp::PoseEstimate e;
    for (int frame = 0; frame <= 12; ++frame) {
      auto blobs = blobs_of(k, cam.pinhole(), f450_from_below(1.0, frame), rng, 0.05);
      if (frame >= 10) blobs.resize(4);  // LEDs 4 and 5 hidden
      if (frame == 12) blobs[1].uv_undistorted = blobs[1].uv_px = blobs[1].uv_undistorted + Eigen::Vector2d(5, 0);
      e = tracker.track_blobs(blobs);
      if (frame == 11) {
        EXPECT_TRUE(e.ok()) << tp::to_string(e.status);  // four clean LEDs: tracked
      }
    }
    return e;
  };
  const tp::PoseEstimate e = frame12(tp::CorrespondenceOptions{}.minimal_fit_rms_px);
  EXPECT_FALSE(e.ok()) << e.rms_px << " px";
  const tp::PoseEstimate loose = frame12(10);  // the rule off: the fit absorbs the error
  EXPECT_TRUE(loose.ok() && loose.rms_px > 0.5) << tp::to_string(loose.status) << ", " << loose.rms_px << " px";
}

// A board too far to vouch for gives Uncertain frames — no pose, the 1-σ
// that failed the gate — but the track goes on: the later frames are
// matched against its prediction (not re-searched), and when the drone
// comes close the tracked pose is Ok and right. 0.3 px of blob noise: with
// 0.5 px this small board's rotation σ, now measured from the track's
// pooled noise rather than capped at the 0.2 px default, stays above 0.03
// down to 0.9 m.
TEST(LedTracker, UncertainFramesKeepTheTrack) {
  const auto k = tp::front_board_constellation();
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  tp::LedTracker tracker(camera, k);
  touchdown::Rng rng(47);
  const Eigen::Isometry3d far = front_toward_camera(rng, 3.2);
  int uncertain = 0, searched_after_first = 0;
  for (int f = 0; f < 40; ++f) {
    const Eigen::Isometry3d T = approach(far, f);
    auto blobs = blobs_of(k, cam, T, rng, 0.3);
    add_depth(blobs, k, cam, T, rng);
    const tp::PoseEstimate& e = tracker.track_blobs(blobs);
    if (e.status == tp::PoseStatus::Uncertain) {
      ++uncertain;
      EXPECT_TRUE(e.T_camera_body.isApprox(Eigen::Isometry3d::Identity())) << f;  // no pose
      EXPECT_TRUE(e.sigma_position_m > 0.03 || e.sigma_rotation_rad > 0.03) << f;
    }
    if (f > 0 && e.reinitialised) ++searched_after_first;
    if (e.ok()) {
      EXPECT_FALSE(wrong(e.T_camera_body, T)) << f;
    }
    if (f == 39) {
      ASSERT_TRUE(e.ok()) << tp::to_string(e.status);
      EXPECT_LT((e.T_camera_body.translation() - T.translation()).norm(), 0.01);
    }
  }
  EXPECT_GE(uncertain, 5);             // the far part is uncertain ...
  EXPECT_EQ(searched_after_first, 0);  // ... and tracked through, never re-searched
}

// ---- temporal fusion (pose_filter.hpp) ------------------------------------------------

namespace {

// A measurement of T with left-twist noise of covariance diag(sp², sr²).
Eigen::Isometry3d noisy(const Eigen::Isometry3d& T, touchdown::Rng& rng, double sp, double sr) {
  tp::Vector6d xi;
  for (int i = 0; i < 3; ++i) xi[i] = sp * rng.normal();
  for (int i = 3; i < 6; ++i) xi[i] = sr * rng.normal();
  return tp::se3_exp(xi) * T;
}

tp::Matrix6d diag_cov(double sp, double sr) {
  tp::Matrix6d C = tp::Matrix6d::Zero();
  C.diagonal() << sp * sp, sp * sp, sp * sp, sr * sr, sr * sr, sr * sr;
  return C;
}

}  // namespace

// Oracle: the body-frame covariance is the left one transported by the
// adjoint: exp(ξ)·T = T·exp(Ad(T⁻¹)ξ) for small ξ.
TEST(PoseFilter, LeftToBodyIsTheAdjoint) {
  touchdown::Rng rng(50);
  for (int k = 0; k < 20; ++k) {
    const auto T = random_pose(rng);
    tp::Vector6d xi;
    for (int i = 0; i < 6; ++i) xi[i] = 1e-6 * rng.normal();
    const tp::Vector6d eta = tp::se3_log(T.inverse() * tp::se3_exp(xi) * T);
    EXPECT_LT((eta - tp::detail::left_to_body(T) * xi).norm(), 1e-11);
  }
}

// A hovering drone measured with known noise: the fused pose is closer to
// the truth than the frames, its covariance shrinks with the frames, and
// its reported sigma matches the observed scatter of the fused poses.
TEST(PoseFilter, FusesAStaticPoseAndReportsItsScatter) {
  touchdown::Rng rng(51);
  const double sp = 0.02, sr = 0.04;
  double single2 = 0, fused2 = 0, predicted2 = 0;
  int n = 0, restarts = 0;
  for (int run = 0; run < 40; ++run) {
    const auto T = random_pose(rng);
    tp::detail::PoseFilterOptions o;
    o.accel_position_m = 1e-4, o.accel_rotation_rad = 1e-4;  // the drone hovers
    tp::detail::PoseFilter f(o);
    for (int k = 0; k < 30; ++k) restarts += f.update(noisy(T, rng, sp, sr), diag_cov(sp, sr)) ? 0 : 1;
    const tp::Vector6d e = tp::se3_log(f.pose() * T.inverse());
    fused2 += e.tail<3>().squaredNorm();
    predicted2 += f.covariance().bottomRightCorner<3, 3>().trace();
    single2 += 3 * sr * sr;
    ++n;
  }
  EXPECT_LE(restarts, 6);               // the 99.9 % gate: ~1 false restart in 1,200 updates
  EXPECT_LT(fused2, single2 / 5);       // 30 frames: far better than one
  EXPECT_GT(fused2 / predicted2, 0.5);  // the covariance is honest ...
  EXPECT_LT(fused2 / predicted2, 2.0);  // ... within a factor of two
}

// A drone turning and moving at constant velocity: after a few frames the
// filter follows without lag, and a jump beyond the gate restarts it at
// the measurement.
TEST(PoseFilter, FollowsConstantVelocityAndRestartsOnAJump) {
  touchdown::Rng rng(52);
  tp::Vector6d v;
  v << 0.01, -0.005, 0.02, 0.02, -0.01, 0.05;  // per frame
  Eigen::Isometry3d T = random_pose(rng);
  tp::detail::PoseFilter f;
  const double sp = 0.002, sr = 0.004;
  for (int k = 0; k < 40; ++k) {
    T = T * tp::se3_exp(v);
    ASSERT_TRUE(f.update(noisy(T, rng, sp, sr), diag_cov(sp, sr))) << k;
  }
  EXPECT_LT((f.pose().translation() - T.translation()).norm(), 0.01);
  EXPECT_LT(rotation_error(f.pose(), T), 0.01);
  Eigen::Isometry3d jumped = T;
  jumped.translation() += Eigen::Vector3d(0.5, 0, 0);
  EXPECT_FALSE(f.update(jumped, diag_cov(sp, sr)));
  EXPECT_TRUE(f.pose().isApprox(jumped));
}

// The tracker with fuse_frames: on a board approaching from afar, at least
// as many frames Ok as frame by frame, none wrong (0.3 px of blob noise:
// seen 25 Ok, 35 Uncertain of 60).
// Fusion lowers the σ but does not admit a frame the σ limit rejects on its
// own (issue 33: a track on the wrong branch fused into confident wrong
// poses): fed the same blobs, the fused tracker is Ok on exactly the frames
// the single-frame one is, and never wrong.
TEST(LedTracker, FusedFramesAreOkOnlyWhenTheFrameIsAndNeverWrong) {
  const auto k = tp::front_board_constellation();
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  tp::TrackerOptions fused_options;
  fused_options.fuse_frames = true;
  tp::LedTracker alone(camera, k), fused(camera, k, fused_options);
  touchdown::Rng rng(53);
  const Eigen::Isometry3d far = front_toward_camera(rng, 3.0);
  int ok_alone = 0, ok_fused = 0, uncertain = 0;
  for (int f = 0; f < 60; ++f) {
    const double s = f / 59.0;
    Eigen::Isometry3d T = far;
    T.translation() = far.translation() * (1 - s) + Eigen::Vector3d(0.02, -0.01, 1.2) * s;
    auto blobs = blobs_of(k, cam, T, rng, 0.3);
    add_depth(blobs, k, cam, T, rng);
    const tp::PoseEstimate a = alone.track_blobs(blobs);
    const tp::PoseEstimate& e = fused.track_blobs(blobs);
    EXPECT_EQ(e.ok(), a.ok()) << f;
    uncertain += a.status == tp::PoseStatus::Uncertain;
    ok_alone += a.ok();
    if (!e.ok()) continue;
    ++ok_fused;
    EXPECT_FALSE(wrong(e.T_camera_body, T)) << f << " fused";
    EXPECT_LT((e.T_camera_body.translation() - T.translation()).norm(), 0.05) << f;
    EXPECT_LE(e.sigma_position_m, 0.03) << f;
  }
  EXPECT_EQ(ok_fused, ok_alone);
  EXPECT_GT(ok_alone, 10);
  EXPECT_GT(uncertain, 0);  // the far part is held back in both
}

// The σ limit with an attitude prior is its own option (issue 33): by
// default the same 0.03 for a fit that does not explain its frame (here the
// complete-fit rule is off, so every Ok frame is within it); lifted, the far
// frames are reported with the σ they have, and it covers their error: no
// frame wrong by 0.1 m or 0.1 rad beyond 3 σ. On these blobs (0.5 px noise)
// frame 4 came out 0.155 rad wrong with σ_rot 0.039 while the track's
// noise was the frame's own σ̂² — now its upper bound until the pool
// vouches (TrackerOptions::unpooled_noise_confidence): σ_rot 0.055.
TEST(LedTracker, AttitudeSigmaLimitIsItsOwnOption) {
  const auto k = tp::front_board_constellation();
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  tp::TrackerOptions limited;
  limited.complete_fit_significance = 0;
  tp::TrackerOptions lifted = limited;
  lifted.correspondence.attitude_max_sigma_position_m = 1.0;
  lifted.correspondence.attitude_max_sigma_rotation_rad = 1.0;
  tp::LedTracker with(camera, k, limited), without_limit(camera, k, lifted);
  touchdown::Rng rng(47);
  const Eigen::Isometry3d far = front_toward_camera(rng, 3.2);
  const Eigen::Vector3d g_camera = Eigen::Vector3d(0.1, 0.95, -0.3).normalized();
  int ok_loose = 0;
  for (int f = 0; f < 40; ++f) {
    const Eigen::Isometry3d T = approach(far, f);
    auto blobs = blobs_of(k, cam, T, rng, 0.5);
    add_depth(blobs, k, cam, T, rng);
    tp::AttitudePrior prior;
    prior.g_camera = g_camera;
    prior.g_body = (T.linear().transpose() * g_camera).normalized();
    prior.sigma_rad = 0.0175;
    const tp::PoseEstimate w = with.track_blobs(blobs, prior);
    const tp::PoseEstimate& l = without_limit.track_blobs(blobs, prior);
    if (w.ok()) {
      EXPECT_TRUE(w.sigma_position_m <= 0.03 && w.sigma_rotation_rad <= 0.03) << f;
    }
    ok_loose += l.ok() && (l.sigma_position_m > 0.03 || l.sigma_rotation_rad > 0.03);
    if (l.ok()) {
      const double dp = (l.T_camera_body.translation() - T.translation()).norm();
      const double dr = rotation_error(l.T_camera_body, T);
      EXPECT_FALSE((dp > 0.1 || dr > 0.1) && (dp > 3 * l.sigma_position_m || dr > 3 * l.sigma_rotation_rad))
          << f << ": " << dp << " m, " << dr << " rad off, sigma " << l.sigma_position_m << ", "
          << l.sigma_rotation_rad;
    }
  }
  EXPECT_GE(ok_loose, 3);  // reported, with their σ, instead of held back
}

// The attitude prior (issue 33, item 3) on the case above: the quasi-planar
// board far away and near-frontal, no depth, where the image alone leaves
// the mirrored tilt open. With both IMUs' gravity directions (1° each) the
// tilt is pinned: the mirrored branch is ruled out, so many frames that were
// Ambiguous are Ok, and none of them is wrong. Gravity in a random
// direction of the camera frame (the camera on a vehicle turns with it).
TEST(Ambiguity, AttitudePriorSettlesTheMirroredTilt) {
  const auto k = quasi_planar_board();
  const auto cam = d435();
  touchdown::Rng rng(43);
  const double sigma = 0.0175;
  int ok = 0, ambiguous = 0, ok_prior = 0, ambiguous_prior = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Eigen::Isometry3d T = board_seen_from_below(rng, 0.8, 1.6);
    const auto blobs = blobs_of(k, cam.pinhole(), T, rng, 0.4);
    const Eigen::Vector3d g = normal_vector3(rng).normalized();
    auto noisy = [&](const Eigen::Vector3d& v) {
      const Eigen::Vector3d a = normal_vector3(rng) * sigma;
      return (Eigen::AngleAxisd(a.norm(), a.normalized()) * v).normalized().eval();
    };
    tp::AttitudePrior prior;
    prior.g_camera = noisy(g);
    prior.g_body = noisy(T.linear().transpose() * g);
    prior.sigma_rad = sigma;
    tp::LedTracker plain(cam, k), with(cam, k);
    const auto& e = plain.track_blobs(blobs);
    ok += e.ok();
    ambiguous += e.status == tp::PoseStatus::Ambiguous;
    if (e.ok()) {
      EXPECT_FALSE(wrong(e.T_camera_body, T)) << trial;
    }
    const auto& f = with.track_blobs(blobs, prior);
    ok_prior += f.ok();
    ambiguous_prior += f.status == tp::PoseStatus::Ambiguous;
    if (f.ok()) {
      EXPECT_FALSE(wrong(f.T_camera_body, T)) << trial << " rot err " << rotation_error(f.T_camera_body, T);
    }
  }
  EXPECT_GT(ambiguous, 10);                       // the image alone leaves many open ...
  EXPECT_LT(ambiguous_prior, ambiguous / 3 + 1);  // ... the prior settles most
  EXPECT_GT(ok_prior, ok + 10) << ok << " ok without, " << ok_prior << " with";
}

TEST(LedTracker, BadAttitudePriorIsRejected) {
  const auto k = f450();
  const auto cam = d435();
  tp::LedTracker tracker(cam, k);
  touchdown::Rng rng(3);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 0, 0, 1;
  const auto blobs = blobs_of(k, cam.pinhole(), T, rng, 0.1);
  tp::AttitudePrior prior;
  prior.g_camera = Eigen::Vector3d::UnitY();
  prior.g_body = Eigen::Vector3d::UnitZ();
  prior.sigma_rad = 0;
  EXPECT_THROW(tracker.track_blobs(blobs, prior), touchdown::InvalidArgument);
  prior.sigma_rad = 0.01;
  prior.g_body = Eigen::Vector3d(0, 0, 1.1);
  EXPECT_THROW(tracker.track_blobs(blobs, prior), touchdown::InvalidArgument);
}

namespace {
// Frame f of 40 of a board receding from 1 m in front of the camera to
// `far` (same attitude throughout).
// Ok beyond the default 0.03 σ limits: only a fit that explains its
// frame is reported there (TrackerOptions::complete_fit_significance).
bool beyond_sigma_limits(const tp::PoseEstimate& e) {
  return e.ok() && (e.sigma_position_m > 0.03 || e.sigma_rotation_rad > 0.03);
}

// Pose e within 3 × its own σ of the truth T, in position and in rotation.
void expect_within_3_sigma(const tp::PoseEstimate& e, const Eigen::Isometry3d& T, const std::string& where) {
  const double dp = (e.T_camera_body.translation() - T.translation()).norm();
  const double dr = rotation_error(e.T_camera_body, T);
  EXPECT_TRUE(dp <= 3 * e.sigma_position_m && dr <= 3 * e.sigma_rotation_rad)
      << where << ": " << dp << " m, " << dr << " rad off, sigma " << e.sigma_position_m << ", "
      << e.sigma_rotation_rad;
}

Eigen::Isometry3d receding_to(const Eigen::Isometry3d& far, int f) {
  Eigen::Isometry3d T = far;
  const double s = f / 39.0;
  T.translation() = far.translation() * s + Eigen::Vector3d(0.02, -0.01, 1.0) * (1 - s);
  return T;
}
}  // namespace

// "Ok means unimodal" (issue 33, item 1): a tracked fit that explains its
// whole frame — every LED in view on a blob of its own, residuals at the
// track's pooled noise — is reported with the σ it has, beyond the 0.03
// limits (TrackerOptions::complete_fit_significance); a fit that does not
// stays under them. The front board recedes from 1 to 3.6 m (0.3 px noise),
// so that its far frames' σ passes 0.03. Variants of the same frames:
// - as rendered: far frames Ok beyond the limits, each within 3 σ;
// - the rule off: no Ok frame beyond the limits;
// - LED 2's blob missing from frame 20 on (in view, unmatched): none beyond
//   the limits from there;
// - LED 2's blob moved 3 px in frames 25, 30 and 35 (10× the noise: a
//   wrong blob in the fit): those frames not beyond the limits.
// In the variants, each frame the rendered run reported beyond the limits
// is `Uncertain` (held back with its σ, the track kept), not lost.
TEST(LedTracker, AFitThatExplainsItsFrameIsNotHeldToTheSigmaLimits) {
  const auto k = tp::front_board_constellation();
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  touchdown::Rng pose_rng(53);
  const Eigen::Isometry3d far = front_toward_camera(pose_rng, 3.6);
  auto pose = [&](int f) { return receding_to(far, f); };
  enum class Variant { AsRendered, RuleOff, Missing, Displaced };
  auto run = [&](Variant v) {
    tp::TrackerOptions o;
    if (v == Variant::RuleOff) o.complete_fit_significance = 0;
    tp::LedTracker tracker(camera, k, o);
    touchdown::Rng rng(59);
    std::vector<tp::PoseEstimate> out;
    for (int f = 0; f < 40; ++f) {
      auto blobs = blobs_of(k, cam, pose(f), rng, 0.3);
      if (f >= 20 && v == Variant::Missing) blobs.erase(blobs.begin() + 2);
      if (v == Variant::Displaced && f % 5 == 0 && f >= 25) blobs[2].uv_undistorted += Eigen::Vector2d(3.0, 0.0);
      out.push_back(tracker.track_blobs(blobs));
    }
    return out;
  };
  const auto rendered = run(Variant::AsRendered);
  int lifted = 0, lifted_late = 0;
  for (int f = 0; f < 40; ++f) {
    const tp::PoseEstimate& e = rendered[static_cast<std::size_t>(f)];
    if (!e.ok()) continue;
    expect_within_3_sigma(e, pose(f), "frame " + std::to_string(f));
    lifted += beyond_sigma_limits(e);
    lifted_late += f >= 20 && beyond_sigma_limits(e);
  }
  EXPECT_GE(lifted_late, 5);  // the far frames, reported with their σ
  for (const int f : {25, 30, 35}) EXPECT_TRUE(beyond_sigma_limits(rendered[static_cast<std::size_t>(f)])) << f;
  for (const Variant v : {Variant::RuleOff, Variant::Missing, Variant::Displaced}) {
    const auto out = run(v);
    for (int f = v == Variant::RuleOff ? 0 : 20; f < 40; ++f) {
      if (v == Variant::Displaced && (f % 5 != 0 || f < 25)) continue;
      const tp::PoseEstimate& e = out[static_cast<std::size_t>(f)];
      EXPECT_FALSE(beyond_sigma_limits(e)) << "variant " << static_cast<int>(v) << ", frame " << f << ": sigma "
                                           << e.sigma_position_m << ", " << e.sigma_rotation_rad;
      if (beyond_sigma_limits(rendered[static_cast<std::size_t>(f)])) {
        EXPECT_EQ(e.status, tp::PoseStatus::Uncertain) << "variant " << static_cast<int>(v) << ", frame " << f;
      }
    }
  }
  std::printf("complete fits beyond the limits: %d (%d from frame 20)\n", lifted, lifted_late);
}

// The LEDs a fit explains without holding them in the fit as whole spots
// (explains_frame): from frame 20 on LED 2's blob (a red LED) is
// - read White (at 3 m a spot lit by two neighbours of other colours reads
//   so) — no LED holds it, but it lies at LED 2's reprojection: the far
//   frames stay Ok beyond the limits, each within 3 σ;
// - the same, 3 px off (10× the noise): LED 2 in view without a blob of
//   its own, no frame beyond the limits;
// - read Blue (a colour the board does not have, not a white mix: maybe
//   another source): not LED 2's, no frame beyond the limits;
// - split (Blob::split; the fit leaves it out while five whole ones
//   remain) at LED 2's projection: beyond the limits as rendered, each
//   within 3 σ; 3 px off: none beyond them.
// Deterministic; measured 20 of the 20 far frames beyond the limits in
// both "as rendered" cases (0 and 0 before the rule took split and
// misread blobs).
TEST(LedTracker, AnLedOnAMisreadOrSplitBlobIsExplainedAtItsReprojection) {
  const auto k = tp::front_board_constellation();
  ASSERT_EQ(k.leds[2].color, tp::LedColor::Red);
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  touchdown::Rng pose_rng(53);
  const Eigen::Isometry3d far = front_toward_camera(pose_rng, 3.6);
  auto pose = [&](int f) { return receding_to(far, f); };
  enum class Blob2 { White, Blue, Split };
  auto run = [&](Blob2 kind, double offset_px) {
    tp::LedTracker tracker(camera, k, tp::TrackerOptions{});
    touchdown::Rng rng(59);
    std::vector<tp::PoseEstimate> out;
    for (int f = 0; f < 40; ++f) {
      auto blobs = blobs_of(k, cam, pose(f), rng, 0.3);
      if (f >= 20) {
        tp::Blob& b = blobs[2];
        if (kind == Blob2::Split) {
          b.split = true;
        } else {
          b.color = kind == Blob2::White ? tp::LedColor::White : tp::LedColor::Blue;
        }
        b.uv_undistorted.x() += offset_px;
        b.uv_px = b.uv_undistorted;
      }
      out.push_back(tracker.track_blobs(blobs));
    }
    return out;
  };
  for (const Blob2 kind : {Blob2::White, Blob2::Split}) {
    const auto at = run(kind, 0.0);
    const auto off = run(kind, 3.0);
    int lifted = 0;
    for (int f = 20; f < 40; ++f) {
      const tp::PoseEstimate& e = at[static_cast<std::size_t>(f)];
      EXPECT_FALSE(beyond_sigma_limits(off[static_cast<std::size_t>(f)])) << static_cast<int>(kind) << ", frame " << f;
      if (!e.ok()) continue;
      lifted += beyond_sigma_limits(e);
      expect_within_3_sigma(e, pose(f), std::to_string(static_cast<int>(kind)) + ", frame " + std::to_string(f));
    }
    std::printf("LED 2 %s: %d frames beyond the limits\n", kind == Blob2::Split ? "split" : "read white", lifted);
    EXPECT_GE(lifted, 15) << static_cast<int>(kind);
  }
  const auto blue = run(Blob2::Blue, 0.0);
  for (int f = 20; f < 40; ++f)
    EXPECT_FALSE(beyond_sigma_limits(blue[static_cast<std::size_t>(f)])) << "blue, frame " << f;
}

// Two LEDs' spots merged into one blob (far, or seen grazing): both LEDs
// hold the blob, it stays out of the fit, and a fit that explains its frame
// must put the LEDs' midpoint on it — then the far frames of a 7-LED board
// (five points in the fit) are reported with their σ (each within 3 σ).
// The 6-LED board's fit keeps four points: not enough to explain a frame
// (the midpoint is a loose check), so no frame is lifted past the limits;
// nor where the spot lies too far from the other LED to be a merge.
TEST(LedTracker, AMergedSpotIsExplainedByItsTwoLedsMidpoint) {
  const auto six = tp::front_board_constellation();
  auto k = six;
  k.leds.push_back({Eigen::Vector3d(0.13, 0.0, -0.03), tp::LedColor::Green});  // a seventh, mid-board
  const tp::CameraModel camera = d435();
  const auto cam = camera.pinhole();
  touchdown::Rng pose_rng(53);
  const Eigen::Isometry3d far = front_toward_camera(pose_rng, 3.6);
  auto pose = [&](int f) { return receding_to(far, f); };
  // The two LEDs of the six nearest each other in the image at the far end.
  std::size_t a = 0, b = 1;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < six.leds.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const double d = (cam.project(far * k.leds[i].p_body) - cam.project(far * k.leds[j].p_body)).norm();
      if (d < nearest) {
        nearest = d;
        a = j;
        b = i;
      }
    }
  }
  auto run = [&](const tp::Constellation& board, double across_radii, bool explain = true) {
    tp::TrackerOptions o;
    if (!explain) o.complete_fit_significance = 0;  // every frame held to the limits
    tp::LedTracker tracker(camera, board, o);
    touchdown::Rng rng(59);
    std::vector<tp::PoseEstimate> out;
    int held_by_both = 0;
    for (int f = 0; f < 40; ++f) {
      auto blobs = blobs_of(board, cam, pose(f), rng, 0.1);
      if (f >= 20) {  // one spot holding both: each LED 0.6 radii from its centre (at the midpoint)
        tp::Blob& m = blobs[a];
        const Eigen::Vector2d d = blobs[b].uv_undistorted - m.uv_undistorted;
        const double r = std::max(2.0, 0.5 * d.norm() / 0.6);
        m.uv_undistorted += 0.5 * d + across_radii * r * Eigen::Vector2d(-d.y(), d.x()).normalized();
        m.uv_px = m.uv_undistorted;
        m.area = M_PI * r * r;
        blobs.erase(blobs.begin() + static_cast<std::ptrdiff_t>(b));
      }
      out.push_back(tracker.track_blobs(blobs));
      const auto& l2b = tracker.led_to_blob();
      held_by_both += f >= 20 && l2b[a] >= 0 && l2b[a] == l2b[b];
    }
    return std::pair{out, held_by_both};
  };
  const auto [merged, held] = run(k, 0.0);
  const auto [limited, held_limited] = run(k, 0.0, false);
  EXPECT_GE(held, 15);  // the tracker assigns both LEDs to the merged spot
  int lifted = 0;       // frames Ok only because the fit explains them (its merged spot too)
  for (int f = 20; f < 40; ++f) {
    const tp::PoseEstimate& e = merged[static_cast<std::size_t>(f)];
    if (!e.ok()) continue;
    lifted += !limited[static_cast<std::size_t>(f)].ok();
    expect_within_3_sigma(e, pose(f), "frame " + std::to_string(f));
  }
  // The far frames, reported with their σ: 3 of them (deterministic; 6
  // with the pool's fixed factor 1.25 before 2026-11-28, whose larger σ
  // put more frames past the limits; the drop code before the merge: 0).
  EXPECT_GE(lifted, 3);
  // 3 radii across the line between the LEDs: too far from the other LED
  // to be its share — that LED is in view without a blob.
  const auto [far_off, held_far] = run(k, 3.0);
  EXPECT_EQ(held_far, 0);
  const auto [four, held_four] = run(six, 0.0);
  EXPECT_GE(held_four, 15);
  for (int f = 20; f < 40; ++f) {
    EXPECT_FALSE(beyond_sigma_limits(far_off[static_cast<std::size_t>(f)])) << "3 radii off, frame " << f;
    EXPECT_FALSE(beyond_sigma_limits(four[static_cast<std::size_t>(f)])) << "six LEDs, frame " << f;
  }
  std::printf("merged spot: held by both LEDs in %d frames, %d far frames Ok only as explained\n", held, lifted);
}
