#include "touchdown/pose/calib/calibration.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <vector>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"

// Oracle tests of the LED constellation calibration: views of the F450
// constellation rendered exactly (or with Gaussian pixel noise) from known
// poses; the calibration starts from the constellation with every LED moved
// by about 1 cm and must recover the true one.

using touchdown::pose_test::kCamera;

namespace {

tp::Constellation true_constellation() {
  return tp::load_constellation(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/constellations/f450_leds.yaml");
}

// Each LED moved by exactly 1 cm in a random direction.
tp::Constellation perturbed(const tp::Constellation& k, touchdown::Rng& rng) {
  tp::Constellation out = k;
  for (auto& led : out.leds) {
    const Eigen::Vector3d d = normal_vector3(rng);
    led.p_body += 0.01 * d.normalized();
  }
  return out;
}

// Camera on the ground looking up at the drone: body z ≈ camera +z (the LEDs
// under the body face the camera), any yaw, up to ~20° of tilt, 0.5–2 m away.
Eigen::Isometry3d view_pose(touchdown::Rng& rng) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double pitch = rng.uniform(-0.35, 0.35), roll = rng.uniform(-0.35, 0.35);  // drawn last factor first
  const double yaw = rng.uniform(-M_PI, M_PI);
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  const double depth = rng.uniform(0.5, 2.0);
  T.translation() << rng.uniform(-0.25, 0.25) * depth, rng.uniform(-0.12, 0.12) * depth, depth;
  return T;
}

struct Scene {
  tp::Constellation truth, initial;
  std::vector<Eigen::Isometry3d> T_camera_body;  // true poses
  std::vector<tp::CalibrationView> views;
};

// `known`: number of views (the first ones) whose pose is given.
Scene make_scene(std::uint64_t seed, double noise_px, int known, int num_views = 20) {
  touchdown::Rng rng(seed);
  Scene s;
  s.truth = true_constellation();
  s.initial = perturbed(s.truth, rng);
  for (int v = 0; v < num_views; ++v) {
    const Eigen::Isometry3d T = view_pose(rng);
    tp::CalibrationView view;
    for (std::size_t k = 0; k < s.truth.leds.size(); ++k) {
      const Eigen::Vector2d uv = kCamera.project(T * s.truth.leds[k].p_body) + noise_px * normal_vector2(rng);
      view.observations.push_back({static_cast<int>(k), uv});
    }
    if (v < known) view.T_camera_body = T;
    s.T_camera_body.push_back(T);
    s.views.push_back(view);
  }
  return s;
}

double max_led_error(const tp::Constellation& a, const tp::Constellation& b) {
  double e = 0;
  for (std::size_t k = 0; k < a.leds.size(); ++k) e = std::max(e, (a.leds[k].p_body - b.leds[k].p_body).norm());
  return e;
}

// The similarity p' = s R p + t taking `from`'s LEDs onto `to`'s (Umeyama 1991).
struct Similarity {
  double s;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};
Similarity align(const tp::Constellation& from, const tp::Constellation& to) {
  Eigen::Matrix3Xd src(3, from.leds.size()), dst(3, to.leds.size());
  for (std::size_t k = 0; k < from.leds.size(); ++k) {
    src.col(k) = from.leds[k].p_body;
    dst.col(k) = to.leds[k].p_body;
  }
  const Eigen::Matrix4d S = Eigen::umeyama(src, dst, true);
  const double s = S.block<3, 1>(0, 0).norm();
  return {s, S.block<3, 3>(0, 0) / s, S.block<3, 1>(0, 3)};
}
tp::Constellation apply(const Similarity& g, tp::Constellation k) {
  for (auto& led : k.leds) led.p_body = g.s * g.R * led.p_body + g.t;
  return k;
}
// A camera pose in the similarity-transformed body frame: the same images.
Eigen::Isometry3d apply(const Similarity& g, const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = T.linear() * g.R.transpose();
  out.translation() = g.s * T.translation() - out.linear() * g.t;
  return out;
}

using touchdown::test::rotation_error;

}  // namespace

TEST(Calibration, KnownPosesNoiseFreeRecoversTheLedsExactly) {
  const Scene s = make_scene(1, 0.0, 20);
  ASSERT_GT(max_led_error(s.initial, s.truth), 0.009);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_TRUE(r.ok());
  EXPECT_LT(max_led_error(r.constellation, s.truth), 1e-6);
  EXPECT_LT(r.final_rms_px, 1e-6);
  EXPECT_GT(r.initial_rms_px, 1.0);
  ASSERT_EQ(r.T_camera_body.size(), s.views.size());
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    EXPECT_TRUE(r.T_camera_body[i].isApprox(*s.views[i].T_camera_body, 0)) << "known poses are returned unchanged";
  }
  // Colours and the marker pose come from the initial constellation.
  for (std::size_t k = 0; k < s.truth.leds.size(); ++k)
    EXPECT_EQ(r.constellation.leds[k].color, s.initial.leds[k].color);
  EXPECT_TRUE(r.constellation.T_body_marker.isApprox(s.initial.T_body_marker));
}

TEST(Calibration, KnownPosesWithPixelNoiseAreWithinTwoMillimetres) {
  const Scene s = make_scene(2, 0.3, 20);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_LT(max_led_error(r.constellation, s.truth), 2e-3);
  EXPECT_LT(r.final_rms_px, r.initial_rms_px);
  EXPECT_NEAR(r.final_rms_px, 0.3 * std::sqrt(2.0), 0.15);  // 2-D residual of σ = 0.3 px per axis
  // The reported uncertainty matches the actual error in magnitude.
  ASSERT_EQ(r.led_sigma_m.size(), s.truth.leds.size());
  for (std::size_t k = 0; k < s.truth.leds.size(); ++k) {
    const double error = (r.constellation.leds[k].p_body - s.truth.leds[k].p_body).norm();
    EXPECT_GT(r.led_sigma_m[k], 1e-5) << k;
    EXPECT_LT(r.led_sigma_m[k], 2e-3) << k;
    EXPECT_LT(error, 5 * r.led_sigma_m[k]) << k;
  }
}

TEST(Calibration, UnknownPosesNoiseFreeRecoversTheShapeInTheInitialGauge) {
  const Scene s = make_scene(3, 0.0, 0);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_LT(r.final_rms_px, 1e-6);
  EXPECT_LT(r.final_rms_px, r.initial_rms_px);
  // Up to a similarity, the true constellation.
  const Similarity g = align(r.constellation, s.truth);
  EXPECT_LT(max_led_error(apply(g, r.constellation), s.truth), 1e-5);
  // The poses, moved into the true body frame by the same similarity, are the true poses.
  ASSERT_EQ(r.T_camera_body.size(), s.views.size());
  for (std::size_t i = 0; i < s.views.size(); ++i) {
    const Eigen::Isometry3d T = apply(g, r.T_camera_body[i]);
    EXPECT_LT(rotation_error(T, s.T_camera_body[i]), 1e-6) << i;
    EXPECT_LT((T.translation() - s.T_camera_body[i].translation()).norm(), 1e-5) << i;
  }
  // The gauge is the initial constellation's: no similarity brings the result closer to it.
  const Similarity h = align(r.constellation, s.initial);
  EXPECT_NEAR(h.s, 1.0, 1e-9);
  EXPECT_LT(Eigen::AngleAxisd(h.R).angle(), 1e-9);
  EXPECT_LT(h.t.norm(), 1e-9);
  EXPECT_LT((r.constellation.centroid() - s.initial.centroid()).norm(), 1e-12);
}

TEST(Calibration, UnknownPosesWithPixelNoiseReportTheShapeUncertainty) {
  const Scene s = make_scene(11, 0.3, 0);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_LT(r.final_rms_px, r.initial_rms_px);
  const tp::Constellation aligned = apply(align(r.constellation, s.truth), r.constellation);
  EXPECT_LT(max_led_error(aligned, s.truth), 2e-3);
  // σ describes the shape (gauge projected out), so it is of the size of the
  // aligned error, not of the unobservable placement.
  ASSERT_EQ(r.led_sigma_m.size(), s.truth.leds.size());
  for (std::size_t k = 0; k < s.truth.leds.size(); ++k) {
    const double error = (aligned.leds[k].p_body - s.truth.leds[k].p_body).norm();
    EXPECT_GT(r.led_sigma_m[k], 1e-5) << k;
    EXPECT_LT(r.led_sigma_m[k], 2e-3) << k;
    EXPECT_LT(error, 5 * r.led_sigma_m[k]) << k;
  }
}

TEST(Calibration, OneKnownPoseFixesAllButTheScale) {
  const Scene s = make_scene(4, 0.0, 1);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  const Similarity g = align(r.constellation, s.truth);
  EXPECT_LT(max_led_error(apply(g, r.constellation), s.truth), 1e-5);
  EXPECT_LT(Eigen::AngleAxisd(g.R).angle(), 1e-5) << "orientation comes from the known pose";
  EXPECT_TRUE(r.T_camera_body[0].isApprox(*s.views[0].T_camera_body, 0));
  EXPECT_LT(r.final_rms_px, 1e-6);
}

TEST(Calibration, TwoKnownPosesMakeItMetric) {
  const Scene s = make_scene(5, 0.0, 2);
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_LT(max_led_error(r.constellation, s.truth), 1e-6);
  for (std::size_t i = 2; i < s.views.size(); ++i) {
    EXPECT_LT(rotation_error(r.T_camera_body[i], s.T_camera_body[i]), 1e-6) << i;
    EXPECT_LT((r.T_camera_body[i].translation() - s.T_camera_body[i].translation()).norm(), 1e-6) << i;
  }
}

TEST(Calibration, HuberLossRejectsAnOutlier) {
  Scene s = make_scene(6, 0.3, 20);
  s.views[7].observations[2].uv_px += Eigen::Vector2d(30.0, -40.0);  // 50 px off
  tp::CalibrationOptions huber;
  huber.huber_px = 2.0;
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views, huber);
  ASSERT_EQ(r.status, tp::CalibrationStatus::Converged) << r.message;
  EXPECT_LT(max_led_error(r.constellation, s.truth), 3e-3);
  EXPECT_LT(r.final_rms_px, r.initial_rms_px);
  tp::CalibrationOptions squared;
  squared.huber_px = 0;
  const auto q = tp::calibrate_constellation(kCamera, s.initial, s.views, squared);
  ASSERT_EQ(q.status, tp::CalibrationStatus::Converged) << q.message;
  const double huber_error = (r.constellation.leds[2].p_body - s.truth.leds[2].p_body).norm();
  const double squared_error = (q.constellation.leds[2].p_body - s.truth.leds[2].p_body).norm();
  EXPECT_LT(huber_error, squared_error) << "the outlier drags the squared-loss solution";
}

TEST(Calibration, IsDeterministic) {
  const Scene s = make_scene(7, 0.3, 0);
  const auto a = tp::calibrate_constellation(kCamera, s.initial, s.views);
  const auto b = tp::calibrate_constellation(kCamera, s.initial, s.views);
  ASSERT_EQ(a.status, tp::CalibrationStatus::Converged) << a.message;
  for (std::size_t k = 0; k < s.truth.leds.size(); ++k)
    EXPECT_EQ(a.constellation.leds[k].p_body, b.constellation.leds[k].p_body);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.led_sigma_m, b.led_sigma_m);
}

TEST(Calibration, LedSeenInOneViewIsInsufficientData) {
  Scene s = make_scene(8, 0.0, 20);
  for (std::size_t i = 1; i < s.views.size(); ++i) s.views[i].observations.pop_back();  // LED 5 only in view 0
  const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
  EXPECT_EQ(r.status, tp::CalibrationStatus::InsufficientData);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.message.find("LED 5"), std::string::npos) << r.message;
  EXPECT_TRUE(r.T_camera_body.empty());
  EXPECT_EQ(max_led_error(r.constellation, s.initial), 0.0);
}

TEST(Calibration, TooFewViewsOrLedsIsInsufficientData) {
  {
    Scene s = make_scene(9, 0.0, 20, 1);  // one view
    const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
    EXPECT_EQ(r.status, tp::CalibrationStatus::InsufficientData) << r.message;
  }
  {
    Scene s = make_scene(9, 0.0, 20, 0);  // no view
    const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
    EXPECT_EQ(r.status, tp::CalibrationStatus::InsufficientData) << r.message;
  }
  {
    Scene s = make_scene(9, 0.0, 0);  // an unknown pose with 3 LEDs cannot be initialised
    s.views[4].observations.resize(3);
    const auto r = tp::calibrate_constellation(kCamera, s.initial, s.views);
    EXPECT_EQ(r.status, tp::CalibrationStatus::InsufficientData);
    EXPECT_NE(r.message.find("views[4]"), std::string::npos) << r.message;
  }
}

TEST(Calibration, MisuseThrows) {
  const Scene s = make_scene(10, 0.0, 20, 4);
  auto with = [&](auto edit) {
    auto views = s.views;
    edit(views);
    return views;
  };
  using touchdown::InvalidArgument;
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) { v[1].observations[0].led = 6; })),
               InvalidArgument);
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) { v[1].observations[0].led = -1; })),
               InvalidArgument);
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) { v[1].observations[1].led = 0; })),
               InvalidArgument)
      << "an LED twice in one view";
  EXPECT_THROW(
      tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) { v[2].observations[0].uv_px.x() = NAN; })),
      InvalidArgument);
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) {
                                             v[0].T_camera_body->translation().z() = -3;  // drone behind the camera
                                           })),
               InvalidArgument);
  try {
    tp::calibrate_constellation(kCamera, s.initial, with([](auto& v) { v[3].observations[2].led = 17; }));
    ADD_FAILURE() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("views[3].observations[2].led"), std::string::npos) << e.what();
  }
  tp::CalibrationOptions bad;
  bad.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(bad.validate(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos) << why;
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, s.views, bad), InvalidArgument);
  bad = {};
  bad.huber_px = -1;
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, s.views, bad), InvalidArgument);
  bad = {};
  bad.function_tolerance = 0;
  EXPECT_THROW(tp::calibrate_constellation(kCamera, s.initial, s.views, bad), InvalidArgument);
  EXPECT_TRUE(tp::CalibrationOptions{}.validate(nullptr));
  tp::Constellation three = s.initial;
  three.leds.resize(3);
  EXPECT_THROW(tp::calibrate_constellation(kCamera, three, s.views), InvalidArgument);
}
