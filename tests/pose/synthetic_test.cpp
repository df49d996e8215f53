#include "touchdown/pose/sim/synthetic.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <numbers>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <set>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/sim/aruco_baseline.hpp"
#include "touchdown/pose/sim/pose_benchmark.hpp"

namespace tp = touchdown::pose;

namespace {

using touchdown::pose_test::d435;
using touchdown::pose_test::f450;

tp::CameraModel distorted() {
  tp::CameraModel c = d435();
  c.distortion = {-0.12, 0.03, 0.0015, -0.001, 0.0};
  return c;
}

// Everything random switched off: exact spots on a flat background.
tp::RenderOptions clean() {
  tp::RenderOptions o;
  o.noise_sigma = 0;
  o.led_dropout_probability = 0;
  o.distractor_count = 0;
  o.depth_noise_k = 0;
  o.depth_invalid_fraction = 0;
  o.render_marker = false;
  return o;
}

// The drone above the camera: body z ≈ camera z, yawed, slightly tilted.
Eigen::Isometry3d below(double distance, double yaw_deg = 30, double tilt_deg = 5, double lateral = 0.03) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(tilt_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(lateral, -lateral, distance);
  return T;
}

int channel_of(tp::LedColor c) {
  switch (c) {
    case tp::LedColor::Blue:
      return 0;
    case tp::LedColor::Green:
      return 1;
    default:
      return 2;
  }
}

// Intensity-weighted centroid of channel `ch` (minus the background) over
// the pixels above `threshold` within `radius` of `near`.
Eigen::Vector2d blob_centroid(const touchdown::BgrImage& img, const Eigen::Vector2d& near, int ch, double bg,
                              double threshold = 8, int radius = 14) {
  double sw = 0, su = 0, sv = 0;
  const int u0 = static_cast<int>(std::lround(near.x())), v0 = static_cast<int>(std::lround(near.y()));
  for (int v = std::max(0, v0 - radius); v <= std::min(img.height - 1, v0 + radius); ++v) {
    for (int u = std::max(0, u0 - radius); u <= std::min(img.width - 1, u0 + radius); ++u) {
      const double w = img.pixels[3 * (static_cast<std::size_t>(v) * img.width + u) + ch] - bg;
      if (w < threshold) continue;
      sw += w, su += w * u, sv += w * v;
    }
  }
  return sw > 0 ? Eigen::Vector2d(su / sw, sv / sw) : Eigen::Vector2d(-1e9, -1e9);
}

const std::uint8_t* pixel(const touchdown::BgrImage& img, const Eigen::Vector2d& uv) {
  const auto u = static_cast<std::size_t>(std::lround(uv.x())), v = static_cast<std::size_t>(std::lround(uv.y()));
  return img.pixels.data() + 3 * (v * img.width + u);
}

class SyntheticCentroid : public ::testing::TestWithParam<bool> {};

}  // namespace

TEST(RenderOptions, DefaultsValidAndBadValuesNamed) {
  using O = tp::RenderOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"noise_sigma:", [](O& o) { o.noise_sigma = -1; }},
      {"aruco_dictionary:", [](O& o) { o.aruco_dictionary = "3X3_7"; }},
      {"aruco_id:", [](O& o) { o.aruco_id = 50; }},  // 4X4_50 has ids 0..49
      {"motion_blur_samples:", [](O& o) { o.motion_blur_samples = 0; }},
      {"led_dropout_probability:", [](O& o) { o.led_dropout_probability = std::nan(""); }},
      {"exposure_s:", [](O& o) { o.exposure_s = 0.5; }},  // longer than a 30 Hz frame
  });
  O o;
  o.led_dropout_probability = std::nan("");
  EXPECT_THROW(tp::SyntheticCamera(d435(), f450(), o), touchdown::InvalidArgument);
}

// Oracle: a noise-free spot is centred on CameraModel::project of its LED
// (with and without lens distortion), in the LED's colour.
TEST_P(SyntheticCentroid, SpotCentroidIsTheProjection) {
  const tp::CameraModel cam = GetParam() ? distorted() : d435();
  const tp::Constellation k = f450();
  tp::RenderOptions o = clean();
  o.bloom_fraction = 0;  // the halo of a neighbouring LED would bias the centroid
  const tp::SyntheticCamera renderer(cam, k, o);
  tp::RenderedFrame frame;
  int checked = 0;
  for (const double d : {0.5, 1.0, 1.5}) {
    for (const double yaw : {0.0, 37.0, 200.0}) {
      const Eigen::Isometry3d T = below(d, yaw, 8, 0.04 * d);
      renderer.render(T, T, 1, 0, frame);
      ASSERT_EQ(frame.led_visible.size(), k.leds.size());
      for (std::size_t i = 0; i < k.leds.size(); ++i) {
        ASSERT_TRUE(frame.led_visible[i]) << "LED " << i;
        const Eigen::Vector2d uv = cam.project(T * k.leds[i].p_body);
        const int ch = channel_of(k.leds[i].color);
        // Window: half-way to the nearest other LED, so that no other spot leaks in.
        double nearest = 1e9;
        for (std::size_t j = 0; j < k.leds.size(); ++j) {
          if (j != i) nearest = std::min(nearest, (cam.project(T * k.leds[j].p_body) - uv).norm());
        }
        const int radius = std::min(14, static_cast<int>(nearest / 2));
        if (radius < 5) continue;  // two LEDs merge in this view (the legs' parallax): no single-spot oracle
        const Eigen::Vector2d c = blob_centroid(frame.colour, uv, ch, o.background_level, 8, radius);
        EXPECT_LT((c - uv).norm(), 0.3) << "LED " << i << " at d=" << d << " yaw=" << yaw << ": " << c.transpose()
                                        << " vs " << uv.transpose();
        // The saturated core in the LED's colour.
        const std::uint8_t* p = pixel(frame.colour, uv);
        if (k.leds[i].color == tp::LedColor::White) {
          EXPECT_GE(std::min({p[0], p[1], p[2]}), 250);
        } else {
          EXPECT_EQ(p[ch], 255);
          for (int other = 0; other < 3; ++other) {
            if (other != ch) {
              EXPECT_LT(p[other], 200) << "LED " << i << " channel " << other;
            }
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 9 * 5);  // most LEDs are isolated in most views
}
INSTANTIATE_TEST_SUITE_P(Distortion, SyntheticCentroid, ::testing::Values(false, true));

// Issue 11: a 32768 x 32768 camera file (valid for the pose pipeline) made
// the renderer allocate ~30 GB and end in std::bad_alloc.
TEST(SyntheticCamera, RefusesImagesLargerThanItsLimit) {
  tp::CameraModel cam = d435();
  cam.width = cam.height = 32768;
  cam.fx = cam.fy = 20000;
  cam.cx = cam.cy = 16383.5;
  try {
    const tp::SyntheticCamera synth(cam, f450());
    ADD_FAILURE() << "a 32768 x 32768 camera was accepted";
  } catch (const touchdown::InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("32768 x 32768"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("16777216"), std::string::npos) << e.what();
  }
  cam.width = cam.height = 4096;  // the limit itself is accepted
  cam.cx = cam.cy = 2047.5;
  EXPECT_NO_THROW(tp::SyntheticCamera(cam, f450()));
}

TEST(SyntheticCamera, SpotsGrowAsTheDroneComesClose) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  const tp::SyntheticCamera renderer(cam, k, clean());
  tp::RenderedFrame frame;
  auto saturated_pixels = [&](double d) {
    const Eigen::Isometry3d T = below(d, 0, 0, 0);
    renderer.render(T, T, 1, 0, frame);
    int n = 0;
    for (std::size_t i = 2; i < frame.colour.pixels.size(); i += 3) n += frame.colour.pixels[i] == 255;
    return n;
  };
  const int near = saturated_pixels(0.5), far = saturated_pixels(2.5);
  EXPECT_GT(far, 0);
  EXPECT_GT(near, 2 * far);
}

TEST(SyntheticCamera, DepthAtAnLedIsItsDepth) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  tp::RenderOptions o = clean();
  o.depth_noise_k = 0.0025;
  o.distractor_count = 3;
  const tp::SyntheticCamera renderer(cam, k, o);
  tp::RenderedFrame frame;
  for (const double d : {0.6, 1.5, 3.0}) {
    const Eigen::Isometry3d T = below(d, 20, 0, 0.02);
    renderer.render(T, T, 5, 1, frame);
    ASSERT_EQ(frame.depth.width, cam.width);
    ASSERT_EQ(frame.depth.height, cam.height);
    for (const auto& led : k.leds) {
      const Eigen::Vector3d p = T * led.p_body;
      const Eigen::Vector2d uv = cam.project(p);
      const auto u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
      const double z = frame.depth.pixels[static_cast<std::size_t>(v) * cam.width + u] * cam.depth_scale;
      const double sigma = o.depth_noise_k * p.z() * p.z();
      EXPECT_NEAR(z, p.z(), 5 * sigma + cam.depth_scale) << "d=" << d;
    }
    // Far corners of the image see the ceiling (or a lamp), beyond 4 m.
    const double corner = frame.depth.pixels[0] * cam.depth_scale;
    EXPECT_GT(corner, 3.5);
  }
}

TEST(SyntheticCamera, DepthNoiseAndInvalidPixels) {
  const tp::CameraModel cam = d435();
  tp::RenderOptions o = clean();
  o.depth_noise_k = 0.0025;
  o.depth_invalid_fraction = 0.05;
  const tp::SyntheticCamera renderer(cam, f450(), o);
  tp::RenderedFrame frame;
  const Eigen::Isometry3d T = below(1.0);
  renderer.render(T, T, 9, 0, frame);
  std::size_t invalid = 0;
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (int v = 0; v < 40; ++v) {  // the top rows: ceiling only
    for (int u = 0; u < cam.width; ++u) {
      const std::uint16_t q = frame.depth.pixels[static_cast<std::size_t>(v) * cam.width + u];
      if (q == 0) {
        ++invalid;
        continue;
      }
      const double z = q * cam.depth_scale;
      sum += z, sum2 += z * z, ++n;
    }
  }
  const double frac = static_cast<double>(invalid) / (40.0 * cam.width);
  EXPECT_NEAR(frac, 0.05, 0.01);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, o.ceiling_distance, 0.01);
  EXPECT_NEAR(sd, o.depth_noise_k * o.ceiling_distance * o.ceiling_distance, 0.01);
}

TEST(SyntheticCamera, DeterministicInSeedAndFrame) {
  const tp::SyntheticCamera renderer(d435(), f450(), tp::RenderOptions{});
  tp::RenderedFrame a, b, c, d;
  const Eigen::Isometry3d T = below(0.8), T_prev = below(0.82, 27, 6, 0.02);
  renderer.render(T, T_prev, 42, 7, a);
  renderer.render(T, T_prev, 42, 7, b);
  EXPECT_EQ(a.colour.pixels, b.colour.pixels);
  EXPECT_EQ(a.depth.pixels, b.depth.pixels);
  EXPECT_EQ(a.led_visible, b.led_visible);
  renderer.render(T, T_prev, 43, 7, c);
  EXPECT_NE(a.colour.pixels, c.colour.pixels);
  EXPECT_NE(a.depth.pixels, c.depth.pixels);
  renderer.render(T, T_prev, 42, 8, d);
  EXPECT_NE(a.colour.pixels, d.colour.pixels);
}

TEST(SyntheticCamera, DropoutProbabilityOneDrawsNoLed) {
  tp::RenderOptions o = clean();
  o.led_dropout_probability = 1;
  const tp::SyntheticCamera renderer(d435(), f450(), o);
  tp::RenderedFrame frame;
  const Eigen::Isometry3d T = below(1.0);
  renderer.render(T, T, 3, 0, frame);
  for (bool v : frame.led_visible) EXPECT_FALSE(v);
  EXPECT_EQ(*std::max_element(frame.colour.pixels.begin(), frame.colour.pixels.end()), 6);
}

TEST(SyntheticCamera, DropoutRateIsRespected) {
  tp::RenderOptions o = clean();
  o.led_dropout_probability = 0.25;
  const tp::SyntheticCamera renderer(d435(), f450(), o);
  tp::RenderedFrame frame;
  const Eigen::Isometry3d T = below(1.0);
  int dropped = 0, total = 0;
  for (std::uint64_t f = 0; f < 200; ++f) {
    renderer.render(T, T, 11, f, frame);
    for (bool v : frame.led_visible) dropped += !v, ++total;
  }
  EXPECT_NEAR(static_cast<double>(dropped) / total, 0.25, 0.04);
}

// Emission geometry is the constellation's: an LED is drawn only when the
// camera is inside its cone; an LED without a normal is always drawn.
TEST(SyntheticCamera, LedsEmitIntoTheirCones) {
  tp::Constellation k = f450();
  k.leds[0].normal = Eigen::Vector3d::UnitX();  // sideways, 45° cone
  k.leds[0].half_angle_deg = 45;
  k.leds[1].normal = Eigen::Vector3d::Zero();  // omnidirectional
  const tp::SyntheticCamera renderer(d435(), k, clean());
  tp::RenderedFrame frame;
  // Seen from below: the downward LEDs and the omnidirectional one; not the
  // sideways one (the camera is ~90° off its axis).
  Eigen::Isometry3d T = below(1.0, 0, 0, 0);
  renderer.render(T, T, 1, 0, frame);
  EXPECT_FALSE(frame.led_visible[0]);
  for (std::size_t i = 1; i < k.leds.size(); ++i) EXPECT_TRUE(frame.led_visible[i]) << i;
  // Seen from the top: only the omnidirectional LED.
  T.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  renderer.render(T, T, 1, 0, frame);
  for (std::size_t i = 0; i < k.leds.size(); ++i) EXPECT_EQ(frame.led_visible[i], i == 1) << i;
  // Seen from the front (body +x toward the camera): the sideways LED.
  T.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitZ()).toRotationMatrix();
  renderer.render(T, T, 1, 0, frame);
  EXPECT_TRUE(frame.led_visible[0]);
  EXPECT_TRUE(frame.led_visible[1]);
}

TEST(SyntheticCamera, LedsEmitOnlyDownward) {
  const tp::SyntheticCamera renderer(d435(), f450(), clean());
  tp::RenderedFrame frame;
  // Upside down: the camera sees the drone's top, the LEDs shine away.
  Eigen::Isometry3d T = below(1.0, 0, 0, 0);
  T.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  renderer.render(T, T, 1, 0, frame);
  for (bool v : frame.led_visible) EXPECT_FALSE(v);
  // Not finite: misuse.
  Eigen::Isometry3d bad = T;
  bad.translation().x() = std::nan("");
  EXPECT_THROW(renderer.render(bad, T, 1, 0, frame), touchdown::InvalidArgument);
  // Behind the camera: nothing.
  T = below(-1.0, 0, 0, 0);
  renderer.render(T, T, 1, 0, frame);
  for (bool v : frame.led_visible) EXPECT_FALSE(v);
}

TEST(SyntheticCamera, MotionBlurSmearsAlongTheMotion) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  tp::RenderOptions o = clean();
  o.bloom_fraction = 0;
  const tp::SyntheticCamera renderer(cam, k, o);
  tp::RenderedFrame still, moving;
  const Eigen::Isometry3d T = below(0.5, 0, 0, 0);
  Eigen::Isometry3d T_prev = T;
  T_prev.translation().x() -= 0.1;  // 3 m/s sideways at 30 fps
  renderer.render(T, T, 1, 0, still);
  renderer.render(T, T_prev, 1, 0, moving);
  const Eigen::Vector2d uv = cam.project(T * k.leds[0].p_body);
  // Horizontal extent of the red spot (pixels above 128) along its row.
  auto extent = [&](const touchdown::BgrImage& img, int dir) {
    int u = static_cast<int>(std::lround(uv.x()));
    const auto v = static_cast<std::size_t>(std::lround(uv.y()));
    int n = 0;
    while (img.pixels[3 * (v * img.width + static_cast<std::size_t>(u)) + 2] > 128) u += dir, ++n;
    return n;
  };
  const int still_width = extent(still.colour, 1) + extent(still.colour, -1);
  const int moving_width = extent(moving.colour, 1) + extent(moving.colour, -1);
  // Smear ≈ f·v·exposure / z = 615 · 3 m/s · 4 ms / 0.47 m ≈ 16 px.
  EXPECT_GT(moving_width, still_width + 8);
  // Centred on the frame's pose.
  const Eigen::Vector2d c = blob_centroid(moving.colour, uv, 2, o.background_level, 8, 24);
  EXPECT_LT((c - uv).norm(), 0.5);
}

TEST(SyntheticCamera, DistractorLampsAreFarAndBright) {
  const tp::CameraModel cam = d435();
  tp::RenderOptions o = clean();
  o.distractor_count = 4;
  o.led_dropout_probability = 1;
  const tp::SyntheticCamera renderer(cam, f450(), o);
  tp::RenderedFrame frame;
  const Eigen::Isometry3d T = below(1.0);
  renderer.render(T, T, 77, 0, frame);
  int bright = 0;
  for (std::size_t p = 0; p < frame.depth.pixels.size(); ++p) {
    const std::uint8_t* px = frame.colour.pixels.data() + 3 * p;
    if (std::min({px[0], px[1], px[2]}) < 200) continue;
    ++bright;
    const double z = frame.depth.pixels[p] * cam.depth_scale;
    EXPECT_GE(z, o.distractor_min_depth - 1e-3);
    EXPECT_LE(z, std::max(o.ceiling_distance, o.distractor_max_depth) + 1e-3);
  }
  EXPECT_GT(bright, 30);  // a few lamps, larger than LED spots
  // Lamps stay put from frame to frame (fixed per seed).
  tp::RenderedFrame next;
  renderer.render(T, T, 77, 1, next);
  EXPECT_EQ(frame.colour.pixels, next.colour.pixels);
}

// The baseline's marker: found by cv::aruco at short range, corners where the
// camera model puts them, and too dim to pass the LED threshold.
TEST(SyntheticCamera, MarkerIsDetectedWhereProjected) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  tp::RenderOptions o;  // noise on
  o.led_dropout_probability = 1;
  o.distractor_count = 0;
  const tp::SyntheticCamera renderer(cam, k, o);
  tp::RenderedFrame frame;
  const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50);
  auto params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  for (const double yaw : {0.0, 70.0, 160.0}) {
    const Eigen::Isometry3d T = below(0.6, yaw, 10, 0.03);
    renderer.render(T, T, 2, 0, frame);
    ASSERT_TRUE(frame.marker_visible);
    const cv::Mat bgr(frame.colour.height, frame.colour.width, CV_8UC3, frame.colour.pixels.data());
    double max_value = 0;
    cv::minMaxLoc(bgr.reshape(1), nullptr, &max_value);
    EXPECT_LT(max_value, 200);  // below the LED threshold
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(grey, dict, corners, ids, params);
    ASSERT_EQ(ids.size(), 1u) << "yaw " << yaw;
    EXPECT_EQ(ids[0], o.aruco_id);
    const double s = o.aruco_size / 2;
    const Eigen::Vector3d model[4] = {{-s, s, 0}, {s, s, 0}, {s, -s, 0}, {-s, -s, 0}};
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector2d uv = cam.project(T * k.T_body_marker * model[c]);
      EXPECT_NEAR(corners[0][static_cast<std::size_t>(c)].x, uv.x(), 1.0) << "yaw " << yaw << " corner " << c;
      EXPECT_NEAR(corners[0][static_cast<std::size_t>(c)].y, uv.y(), 1.0) << "yaw " << yaw << " corner " << c;
    }
  }
  // Seen from above, the marker faces away: not drawn.
  Eigen::Isometry3d T = below(0.6, 0, 0, 0);
  T.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  renderer.render(T, T, 2, 0, frame);
  EXPECT_FALSE(frame.marker_visible);
}

// The renderer and the ArUco baseline share one dictionary table: every
// name the baseline lists, in any letter case and with or without "DICT_",
// is accepted by both, and the rendered marker is found by cv::aruco with
// the dictionary of that name and the right id.
TEST(SyntheticCamera, EveryBaselineDictionaryRendersADetectableMarker) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  const auto names = tp::aruco_dictionary_names();
  ASSERT_EQ(names.size(), 21u);
  for (std::size_t index = 0; index < names.size(); ++index) {
    const std::string& name = names[index];
    std::string lower = name;
    for (auto& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    for (const std::string& spelling : {name, lower, "DICT_" + name}) {
      tp::PoseBenchmarkOptions b;
      b.camera = cam;
      b.constellation = k;
      b.aruco.dictionary = spelling;
      std::string why;
      EXPECT_TRUE(b.validate(&why)) << spelling << ": " << why;
      EXPECT_TRUE(b.rendered_options().validate(&why)) << spelling << ": " << why;
    }
    tp::RenderOptions o;
    o.led_dropout_probability = 1;
    o.distractor_count = 0;
    o.aruco_dictionary = lower;
    const tp::SyntheticCamera renderer(cam, k, o);
    tp::RenderedFrame frame;
    // 1 m: at 0.4-0.5 m OpenCV's default detector misses the 7x7 markers
    // (cells wider than its largest adaptive-threshold window); every
    // dictionary is found at 1 m.
    const Eigen::Isometry3d T = below(1.0, 30, 5, 0.02);
    renderer.render(T, T, 2, 0, frame);
    ASSERT_TRUE(frame.marker_visible) << name;
    const cv::Mat bgr(frame.colour.height, frame.colour.width, CV_8UC3, frame.colour.pixels.data());
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    // The baseline lists the names in OpenCV's enum order.
    const auto dict = cv::aruco::getPredefinedDictionary(static_cast<int>(index));
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(grey, dict, corners, ids);
    EXPECT_EQ(ids.size(), 1u) << name;
    if (!ids.empty()) {
      EXPECT_EQ(ids[0], o.aruco_id) << name;
    }
  }
  // An unknown name is refused by both, naming the key.
  tp::PoseBenchmarkOptions b;
  b.camera = cam;
  b.constellation = k;
  b.aruco.dictionary = "4X4_51";
  std::string why;
  EXPECT_FALSE(b.validate(&why));
  EXPECT_NE(why.find("aruco: dictionary: unknown ArUco dictionary '4X4_51'"), std::string::npos) << why;
  tp::RenderOptions o;
  o.aruco_dictionary = "4X4_51";
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("aruco_dictionary: unknown dictionary '4X4_51' (known: 4X4_50, "), std::string::npos) << why;
}

TEST(Trajectory, KeepsLedsInsideAndSpansTheDistances) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  const tp::TrajectoryOptions o;
  for (const auto kind : {tp::TrajectoryKind::Static, tp::TrajectoryKind::Moving}) {
    const auto traj = tp::make_trajectory(kind, 181, 4, cam, k, o);
    ASSERT_EQ(traj.size(), 181u);
    double dmin = 1e9, dmax = 0, max_step = 0, max_tilt = 0;
    for (std::size_t i = 0; i < traj.size(); ++i) {
      const auto& T = traj[i].T_camera_body;
      EXPECT_NEAR(traj[i].t, static_cast<double>(i) / o.fps, 1e-12);
      const double d = (T * k.centroid()).norm();
      dmin = std::min(dmin, d), dmax = std::max(dmax, d);
      for (const auto& led : k.leds) {
        const Eigen::Vector2d uv = cam.project(T * led.p_body);
        EXPECT_GE(uv.x(), o.margin_px - 1e-9);
        EXPECT_GE(uv.y(), o.margin_px - 1e-9);
        EXPECT_LE(uv.x(), cam.width - 1 - o.margin_px + 1e-9);
        EXPECT_LE(uv.y(), cam.height - 1 - o.margin_px + 1e-9);
      }
      // Underside toward the camera.
      const double tilt = std::acos(std::clamp(T.linear()(2, 2), -1.0, 1.0)) * 180 / std::numbers::pi;
      max_tilt = std::max(max_tilt, tilt);
      if (i > 0) max_step = std::max(max_step, (T.translation() - traj[i - 1].T_camera_body.translation()).norm());
    }
    EXPECT_NEAR(dmin, o.min_distance, 0.02 * o.min_distance) << static_cast<int>(kind);
    EXPECT_NEAR(dmax, o.max_distance, 0.02 * o.max_distance) << static_cast<int>(kind);
    EXPECT_LE(max_tilt, 21.0);
    if (kind == tp::TrajectoryKind::Moving) {
      EXPECT_LT(max_step, 0.3);  // smooth
      EXPECT_GT(max_tilt, 8.0);
    }
  }
  // A constellation that faces another way is turned toward the camera.
  const tp::Constellation board = touchdown::pose_test::front_board();
  for (const auto kind : {tp::TrajectoryKind::Static, tp::TrajectoryKind::Moving}) {
    for (const auto& s : tp::make_trajectory(kind, 60, 5, cam, board, o)) {
      const Eigen::Vector3d camera_body = s.T_camera_body.inverse().translation();
      for (const auto& led : board.leds) EXPECT_TRUE(led.emits_toward(camera_body));
      // Body +x (the board's axis) points at the camera within the tilt.
      const Eigen::Vector3d x_camera = s.T_camera_body.linear() * Eigen::Vector3d::UnitX();
      EXPECT_LT(std::acos(-x_camera.z()) * 180 / std::numbers::pi, 21.0);
    }
  }
  // Deterministic in the seed.
  const auto a = tp::make_trajectory(tp::TrajectoryKind::Moving, 30, 9, cam, k);
  const auto b = tp::make_trajectory(tp::TrajectoryKind::Moving, 30, 9, cam, k);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].T_camera_body.isApprox(b[i].T_camera_body, 0));
}

// The source paper's geometry: the ground vehicle's camera looks back,
// tilted up; the drone follows behind and above, level within its tilt,
// heading toward the vehicle, its front board facing the camera.
TEST(Trajectory, ChaseGeometryIsThePapers) {
  const tp::CameraModel cam = d435();
  const tp::Constellation board = touchdown::pose_test::front_board();
  tp::TrajectoryOptions o;
  o.geometry = tp::CameraGeometry::Chase;
  o.camera_tilt_deg = 20;
  const double t = 20 * std::numbers::pi / 180;
  // The world (x forward, z up) in the camera frame.
  Eigen::Matrix3d R_world_camera;
  R_world_camera << 0, -std::sin(t), -std::cos(t), 1, 0, 0, 0, -std::cos(t), std::sin(t);
  for (const auto kind : {tp::TrajectoryKind::Static, tp::TrajectoryKind::Moving}) {
    const auto traj = tp::make_trajectory(kind, 90, 6, cam, board, o);
    double max_tilt = 0, max_heading = 0, dmin = 1e9, dmax = 0;
    for (const auto& s : traj) {
      const Eigen::Isometry3d T_world_body = Eigen::Isometry3d(R_world_camera) * s.T_camera_body;
      const Eigen::Vector3d p = T_world_body.translation();
      EXPECT_LT(p.x(), 0);  // behind the vehicle
      EXPECT_GT(p.z(), 0);  // above the camera
      const Eigen::Matrix3d& R = T_world_body.linear();
      max_tilt = std::max(max_tilt, std::acos(std::clamp(R(2, 2), -1.0, 1.0)) * 180 / std::numbers::pi);
      max_heading = std::max(max_heading, std::abs(std::atan2(R(1, 0), R(0, 0))) * 180 / std::numbers::pi);
      const Eigen::Vector3d camera_body = s.T_camera_body.inverse().translation();
      for (const auto& led : board.leds) EXPECT_TRUE(led.emits_toward(camera_body));
      const double d = (s.T_camera_body * board.centroid()).norm();
      dmin = std::min(dmin, d), dmax = std::max(dmax, d);
    }
    EXPECT_LE(max_tilt, 21.0) << static_cast<int>(kind);
    // ±15° of sway, plus what roll × pitch (≤ 14° each) turns the nose by.
    EXPECT_LE(max_heading, 19.0) << static_cast<int>(kind);
    EXPECT_NEAR(dmin, o.min_distance, 0.02 * o.min_distance);
    EXPECT_NEAR(dmax, o.max_distance, 0.02 * o.max_distance);
  }
}

TEST(Trajectory, BadOptionsThrow) {
  const tp::CameraModel cam = d435();
  const tp::Constellation k = f450();
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Static, 0, 1, cam, k), touchdown::InvalidArgument);
  tp::TrajectoryOptions o;
  o.min_distance = 2, o.max_distance = 1;
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Moving, 10, 1, cam, k, o), touchdown::InvalidArgument);
  o = {};
  o.min_distance = 0.05;  // the constellation cannot fit
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Moving, 10, 1, cam, k, o), touchdown::InvalidArgument);
  // Issue 11: 100,000,000 frames ended in std::bad_alloc (136 bytes a sample),
  // and a drone 1e9 m away was rendered with every LED "visible".
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Static, tp::kMaxTrajectoryFrames + 1, 1, cam, k),
               touchdown::InvalidArgument);
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Static, 100000000, 1, cam, k), touchdown::InvalidArgument);
  o.max_distance = 1e9;
  EXPECT_THROW(tp::make_trajectory(tp::TrajectoryKind::Static, 10, 1, cam, k, o), touchdown::InvalidArgument);
  o.max_distance = tp::kMaxTrajectoryDistance;
  EXPECT_TRUE(o.validate(nullptr));
  // validate() names the field.
  using O = tp::TrajectoryOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"fps:", [](O& t) { t.fps = 0; }},
      {"margin_px:", [](O& t) { t.margin_px = -1; }},
      {"min_distance, max_distance:", [](O& t) { t.max_distance = 0.1; }},
      {"min_distance, max_distance:", [](O& t) { t.max_distance = 101; }},
      {"camera_tilt_deg:", [](O& t) { t.camera_tilt_deg = 95; }},
  });
}

// ---- the harsh profile -------------------------------------------------------------------

namespace {

// One LED of `colour` facing the camera at `distance` on the optical axis
// (three helpers far off-axis keep the constellation valid; they face away).
tp::Constellation single_led(tp::LedColor colour, double spacing = 0) {
  tp::Constellation k;
  const Eigen::Vector3d toward(0, 0, -1), away(0, 0, 1);
  k.leds = {{{0, 0, 0}, colour, toward}};
  if (spacing > 0) k.leds.push_back({{spacing, 0, 0}, colour, toward});
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.5, 0.5, 0), Eigen::Vector3d(-0.5, 0.5, 0.01), Eigen::Vector3d(0.5, -0.5, 0.02)}) {
    k.leds.push_back({p, tp::LedColor::White, away});
  }
  return k;
}

Eigen::Isometry3d ahead(double distance) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0, 0, distance);
  return T;
}

// The harsh spot model without the random parts: clean(), then the harsh
// profile, then what the profile switched back on switched off again.
tp::RenderOptions harsh_quiet() {
  tp::RenderOptions o = tp::apply_profile(clean(), tp::RenderProfile::Harsh);
  o.noise_sigma = 0;
  o.led_dropout_probability = 0;
  o.distractor_count = 0;
  o.reflection_probability = 0;
  o.exposure_step_stops = 0;
  o.led_gain_spread_stops = 0;
  return o;
}

}  // namespace

TEST(RenderProfile, NamesRoundTripAndHarshIsValid) {
  for (const auto p : {tp::RenderProfile::Clean, tp::RenderProfile::Harsh}) {
    EXPECT_EQ(touchdown::from_string<tp::RenderProfile>(tp::to_string(p)), p);
  }
  EXPECT_THROW((void)touchdown::from_string<tp::RenderProfile>("Harsh"), touchdown::InvalidArgument);
  std::string why;
  EXPECT_TRUE(tp::apply_profile({}, tp::RenderProfile::Harsh).validate(&why)) << why;
  EXPECT_EQ(tp::apply_profile({}, tp::RenderProfile::Clean).led_gain, tp::RenderOptions{}.led_gain);
  using O = tp::RenderOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"exposure_step_frames:", [](O& o) { o.exposure_step_frames = 0; }},
      {"led_dropout_frames:", [](O& o) { o.led_dropout_frames = 0; }},
      {"reflection_probability:", [](O& o) { o.reflection_probability = 1.5; }},
      {"distractor_led_like_fraction:", [](O& o) { o.distractor_led_like_fraction = -0.1; }},
      {"led_gain_spread_stops:", [](O& o) { o.led_gain_spread_stops = std::nan(""); }},
  });
}

// White cores: a bright red, green or blue LED clips to white at its
// centre while its halo keeps the hue; the clean profile's core is the
// LED's colour. At 0.5 and 2.5 m.
TEST(RenderProfile, HarshCoresClipToWhiteWithAHueHalo) {
  for (const auto colour : {tp::LedColor::Red, tp::LedColor::Green, tp::LedColor::Blue}) {
    const int ch = channel_of(colour);
    for (const double d : {0.5, 2.5}) {
      tp::RenderedFrame harsh, plain;
      tp::SyntheticCamera(d435(), single_led(colour), harsh_quiet()).render(ahead(d), ahead(d), 1, 0, harsh);
      tp::SyntheticCamera(d435(), single_led(colour), clean()).render(ahead(d), ahead(d), 1, 0, plain);
      const Eigen::Vector2d uv = d435().project(Eigen::Vector3d(0, 0, d));
      const std::uint8_t* core = pixel(harsh.colour, uv);
      EXPECT_GE(std::min({core[0], core[1], core[2]}), 250) << tp::to_string(colour) << " at " << d;
      const std::uint8_t* plain_core = pixel(plain.colour, uv);
      EXPECT_LT(std::min({plain_core[0], plain_core[1], plain_core[2]}), 120) << tp::to_string(colour);
      // Along a ray outward: a pixel that is bright but unclipped, in the hue.
      bool hue_seen = false;
      for (int r = 1; r < 20 && !hue_seen; ++r) {
        const std::uint8_t* q = pixel(harsh.colour, uv + Eigen::Vector2d(r, 0));
        const int others = std::max(q[(ch + 1) % 3], q[(ch + 2) % 3]);
        hue_seen = q[ch] >= 60 && q[ch] < 250 && q[ch] > 2 * others;
      }
      EXPECT_TRUE(hue_seen) << tp::to_string(colour) << " at " << d;
    }
  }
}

// Exposure steps hold for a run of frames and change the brightness by
// whole stops; with exposure_step_stops = 0 nothing changes.
TEST(RenderProfile, ExposureStepsHoldPerRun) {
  tp::RenderOptions o = harsh_quiet();
  o.white_cores = false;  // a clipped-to-colour spot: its halo's sum scales with the exposure
  o.exposure_step_stops = 1;
  o.exposure_step_frames = 5;
  const tp::Constellation k = single_led(tp::LedColor::Red);
  const tp::SyntheticCamera renderer(d435(), k, o);
  tp::RenderedFrame frame;
  std::vector<double> sums;
  for (std::uint64_t f = 0; f < 40; ++f) {
    renderer.render(ahead(1.0), ahead(1.0), 3, f, frame);
    double s = 0;
    for (std::size_t i = 2; i < frame.colour.pixels.size(); i += 3) s += frame.colour.pixels[i];
    sums.push_back(s);
  }
  std::set<long> levels;
  for (std::size_t f = 0; f < sums.size(); ++f) {
    if (f % 5) {
      EXPECT_EQ(sums[f], sums[f - 1]) << "frame " << f << " inside a run";
    }
    levels.insert(std::lround(sums[f]));
  }
  EXPECT_GE(levels.size(), 2u);  // 8 runs of 3 possible levels
  EXPECT_LE(levels.size(), 3u);
}

// Rolling drop-outs: the share of frames an LED is missing stays the
// probability, and the drop-outs come in runs.
TEST(RenderProfile, RollingDropoutsComeInRuns) {
  tp::RenderOptions o = clean();
  o.led_dropout_probability = 0.25;
  o.led_dropout_frames = 10;
  const tp::SyntheticCamera renderer(d435(), f450(), o);
  tp::RenderedFrame frame;
  const Eigen::Isometry3d T = below(1.0);
  int dropped = 0, total = 0, changes = 0;
  std::vector<bool> last;
  for (std::uint64_t f = 0; f < 400; ++f) {
    renderer.render(T, T, 11, f, frame);
    for (std::size_t i = 0; i < frame.led_visible.size(); ++i) {
      dropped += !frame.led_visible[i], ++total;
      if (!last.empty() && last[i] != frame.led_visible[i]) ++changes;
    }
    last = frame.led_visible;
  }
  EXPECT_NEAR(static_cast<double>(dropped) / total, 0.25, 0.06);
  // Independent per frame, an LED would change state ~2·0.25·0.75 = 37 % of
  // the frames; in runs of 10 at most 2 changes per 10 frames.
  EXPECT_LT(static_cast<double>(changes) / total, 0.1);
}

// Merge flags: two LEDs 8 mm apart at 1.5 m share one lit disc; 10 cm
// apart they do not.
TEST(RenderProfile, MergeFlagsMarkTouchingSpots) {
  for (const double spacing : {0.008, 0.1}) {
    tp::RenderedFrame frame;
    tp::SyntheticCamera(d435(), single_led(tp::LedColor::Green, spacing), harsh_quiet())
        .render(ahead(1.5), ahead(1.5), 1, 0, frame);
    ASSERT_TRUE(frame.led_visible[0] && frame.led_visible[1]);
    EXPECT_EQ(frame.led_merged[0], spacing < 0.05) << spacing;
    EXPECT_EQ(frame.led_merged[1], spacing < 0.05) << spacing;
    EXPECT_FALSE(frame.led_merged[2]);  // faces away: not drawn, not merged
  }
}

// Reflections off the airframe: an extra, dimmer spot near a reflecting
// LED, with the airframe's depth.
TEST(RenderProfile, ReflectionsAddDimSpotsNearTheirLeds) {
  tp::RenderOptions o = harsh_quiet();
  o.reflection_probability = 1;
  o.reflection_offset = 0.04;
  const tp::Constellation k = single_led(tp::LedColor::Red);
  tp::RenderedFrame with, without;
  tp::SyntheticCamera(d435(), k, o).render(ahead(1.0), ahead(1.0), 5, 0, with);
  o.reflection_probability = 0;
  tp::SyntheticCamera(d435(), k, o).render(ahead(1.0), ahead(1.0), 5, 0, without);
  // Lit pixels (red ≥ 100) away from the LED's own spot: only with the reflection.
  const Eigen::Vector2d uv = d435().project(Eigen::Vector3d(0, 0, 1.0));
  auto far_lit = [&](const tp::RenderedFrame& f) {
    int n = 0;
    for (int v = 0; v < f.colour.height; ++v) {
      for (int u = 0; u < f.colour.width; ++u) {
        const double r = (Eigen::Vector2d(u, v) - uv).norm();
        if (r > 10 && r < 40 && f.colour.pixels[3 * (static_cast<std::size_t>(v) * f.colour.width + u) + 2] >= 100) ++n;
      }
    }
    return n;
  };
  EXPECT_EQ(far_lit(without), 0);
  EXPECT_GT(far_lit(with), 3);
}

// A reflection returns reflection_gain of its LED's light, however wide
// its spot: the red light summed around each spot (unclipped, no bloom, no
// noise) against the option, at a near and a far range.
TEST(RenderProfile, ReflectionReturnsItsShareOfTheLedsLight) {
  for (const double distance : {0.6, 2.5}) {
    for (const double share : {0.3, 1.0}) {
      tp::RenderOptions o = clean();
      o.led_gain = 0.95;  // no pixel clips; the reflection far above the 8-bit steps
      o.bloom_fraction = 0;
      o.reflection_probability = 1;
      o.reflection_gain = share;
      o.reflection_offset = 0.08 * distance;  // ~50 px apart: two separate spots
      const tp::Constellation k = single_led(tp::LedColor::Red);
      tp::RenderedFrame frame;
      tp::SyntheticCamera(d435(), k, o).render(ahead(distance), ahead(distance), 5, 0, frame);
      const touchdown::BgrImage& img = frame.colour;
      const Eigen::Vector2d uv = d435().project(Eigen::Vector3d(0, 0, distance));
      const double bg = img.pixels[2];  // a corner: background only
      double near = 0, far = 0;
      for (int v = 0; v < img.height; ++v) {
        for (int u = 0; u < img.width; ++u) {
          const double r = (Eigen::Vector2d(u, v) - uv).norm();
          if (r > 80) continue;
          const double red = img.pixels[3 * (static_cast<std::size_t>(v) * img.width + u) + 2] - bg;
          (r < 20 ? near : far) += red;
        }
      }
      ASSERT_GT(near, 0);
      EXPECT_NEAR(far / near, share, 0.1 * share) << "distance " << distance;
    }
  }
}

TEST(RandomConstellation, ValidDeterministicAndVaried) {
  std::set<std::size_t> sizes;
  for (std::uint64_t s = 0; s < 40; ++s) {
    const tp::Constellation a = tp::random_constellation(s), b = tp::random_constellation(s);
    std::string why;
    ASSERT_TRUE(a.validate(&why)) << s << ": " << why;
    ASSERT_EQ(a.leds.size(), b.leds.size());
    for (std::size_t i = 0; i < a.leds.size(); ++i) {
      EXPECT_EQ(a.leds[i].p_body, b.leds[i].p_body);
      EXPECT_TRUE(a.leds[i].has_normal());
      EXPECT_GE(a.leds[i].half_angle_deg, 50);
      EXPECT_LE(a.leds[i].half_angle_deg, 90);
    }
    EXPECT_GE(a.leds.size(), 5u);
    EXPECT_LE(a.leds.size(), 8u);
    sizes.insert(a.leds.size());
  }
  EXPECT_EQ(sizes.size(), 4u);
  EXPECT_NE(tp::random_constellation(1).leds[0].normal, tp::random_constellation(2).leds[0].normal);
}

// Rolling shutter: a LED moving sideways at v is drawn where it was when
// its row was read, δ = readout (v_row / (h − 1) − ½) after the frame's
// time: shifted by fx v δ / z against a global shutter (a pinhole, no blur).
TEST(SyntheticCamera, RollingShutterShiftsAMovingLedByItsRowsReadoutTime) {
  tp::CameraModel cam = d435();
  cam.distortion = {0, 0, 0, 0, 0};
  const tp::Constellation k = single_led(tp::LedColor::Red);
  tp::RenderOptions o = clean();
  o.bloom_fraction = 0;
  o.motion_blur_samples = 1;
  tp::RenderOptions rs = o;
  rs.rolling_shutter_s = 0.03;
  std::string why;
  ASSERT_TRUE(rs.validate(&why)) << why;
  const double z = 0.6, v = 3.0;
  for (const double y : {0.2, -0.15}) {  // below and above the image centre
    Eigen::Isometry3d T = ahead(z);
    T.translation().y() = y;
    Eigen::Isometry3d T_prev = T;
    T_prev.translation().x() -= v / o.frame_rate_hz;  // moving along the camera's x at v
    tp::RenderedFrame global, rolling;
    tp::SyntheticCamera(cam, k, o).render(T, T_prev, 1, 0, global);
    tp::SyntheticCamera(cam, k, rs).render(T, T_prev, 1, 0, rolling);
    const Eigen::Vector2d uv = cam.project(T * k.leds[0].p_body);
    const Eigen::Vector2d g = blob_centroid(global.colour, uv, 2, o.background_level);
    const double delta = rs.rolling_shutter_s * (uv.y() / (cam.height - 1) - 0.5);
    const Eigen::Vector2d expected = g + Eigen::Vector2d(cam.fx * v * delta / z, 0);
    const Eigen::Vector2d r = blob_centroid(rolling.colour, expected, 2, o.background_level);
    EXPECT_GT(std::abs(cam.fx * v * delta / z), 5.0) << "the shift must be visible for the test to show anything";
    EXPECT_NEAR(r.x(), expected.x(), 0.3) << y;
    EXPECT_NEAR(r.y(), expected.y(), 0.3) << y;
  }
  tp::RenderOptions bad = o;
  bad.rolling_shutter_s = 0.05;  // longer than a frame at 30 Hz
  EXPECT_FALSE(bad.validate(&why));
  EXPECT_NE(why.find("rolling_shutter_s"), std::string::npos) << why;
}
