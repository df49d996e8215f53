// The downward camera (camera.hpp): the mask and areas against hand-computed
// projections, OpenCV's own ArUco detector on the rendered frames, depth
// against the analytic plane and solids, the z-buffer, determinism and the
// camera options.
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "scenario/render_cache.hpp"
#include "scenario/render_impl.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/camera.hpp"

namespace {

using touchdown::scenario::CameraFrame;
using touchdown::scenario::CameraOptions;
using touchdown::scenario::Label;
using touchdown::scenario::mask_value;
using touchdown::scenario::Renderer;
using touchdown::scenario::Scenario;
using touchdown::scenario::SceneState;

Scenario render_scenario(touchdown::scenario::MapKind map = touchdown::scenario::MapKind::Ground) {
  Scenario s;
  s.map = map;
  s.seed = 7;
  s.marker.dictionary = "4X4_50";
  s.marker.id = 3;
  s.marker.size = 1.0;
  s.marker.position = Eigen::Vector2d(0, 0);
  return s;
}

/// Body at `p`, yawed by `yaw_deg`; the camera's own tilt comes from the options.
SceneState render_state(const Eigen::Vector3d& p, double yaw_deg = 0, std::size_t dynamic = 0) {
  SceneState st;
  st.T_world_body = Eigen::Translation3d(p) * Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ());
  st.T_world_dynamic.assign(dynamic, Eigen::Isometry3d::Identity());
  return st;
}

cv::Mat render_mat(const CameraFrame& f) {
  return cv::Mat(f.height, f.width, CV_8UC3, const_cast<std::uint8_t*>(f.image.pixels.data())).clone();
}

/// The target's black-border corners (OpenCV's order: top-left, top-right,
/// bottom-right, bottom-left of the marker image) projected by hand.
std::array<Eigen::Vector2d, 4> render_true_corners(const Scenario& s, const CameraOptions& cam, const SceneState& st,
                                                   double side) {
  const double h = 0.5 * side, yaw = s.marker.yaw_deg * M_PI / 180;
  const Eigen::Vector2d ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
  const std::array<Eigen::Vector2d, 4> w{s.marker.position - h * ex + h * ey, s.marker.position + h * ex + h * ey,
                                         s.marker.position + h * ex - h * ey, s.marker.position - h * ex - h * ey};
  const Eigen::Isometry3d T_camera_world = (st.T_world_body * cam.T_body_camera()).inverse();
  std::array<Eigen::Vector2d, 4> out;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector3d q = cam.K() * (T_camera_world * Eigen::Vector3d(w[i].x(), w[i].y(), 0));
    out[i] = q.head<2>() / q.z();
  }
  return out;
}

struct RenderDetection {
  std::vector<int> ids;
  std::vector<std::vector<cv::Point2f>> corners;
};

RenderDetection render_detect(const CameraFrame& f, cv::aruco::PREDEFINED_DICTIONARY_NAME dict) {
  RenderDetection d;
  cv::aruco::detectMarkers(render_mat(f), cv::aruco::getPredefinedDictionary(dict), d.corners, d.ids);
  return d;
}

double render_perimeter(const std::array<Eigen::Vector2d, 4>& c) {
  double p = 0;
  for (std::size_t i = 0; i < 4; ++i) p += (c[(i + 1) % 4] - c[i]).norm();
  return p;
}

}  // namespace

TEST(RenderCamera, ValidateNamesTheKeyAndTheProblem) {
  CameraOptions ok;
  std::string why;
  EXPECT_TRUE(ok.validate(&why)) << why;
  const auto expect_refused = [](CameraOptions o, const std::string& key) {
    std::string msg;
    EXPECT_FALSE(o.validate(&msg));
    EXPECT_EQ(msg.rfind(key + ": ", 0), 0u) << msg;
  };
  CameraOptions o;
  o.width = 8;
  expect_refused(o, "width");
  o = {}, o.height = 5000;
  expect_refused(o, "height");
  o = {}, o.hfov_deg = 5;
  expect_refused(o, "hfov_deg");
  o = {}, o.hfov_deg = std::nan("");
  expect_refused(o, "hfov_deg");
  o = {}, o.tilt_deg = -1;
  expect_refused(o, "tilt_deg");
  o = {}, o.tilt_deg = 85;
  expect_refused(o, "tilt_deg");
  o = {}, o.rate_hz = 0;
  expect_refused(o, "rate_hz");
  o = {}, o.exposure_s = 0.5;
  expect_refused(o, "exposure_s");
  o = {}, o.offset_body.x() = std::numeric_limits<double>::infinity();
  expect_refused(o, "offset_body");
  EXPECT_FALSE(o.validate(nullptr));
  // The renderer refuses them too, naming the camera.
  try {
    Renderer r(render_scenario(), o);
    FAIL() << "accepted an infinite offset";
  } catch (const touchdown::InvalidArgument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("camera.offset_body: ", 0), 0u) << e.what();
  }
}

TEST(RenderCamera, IntrinsicsAndMountingByHand) {
  CameraOptions o;  // 640×480, 90° → fx = 320
  EXPECT_NEAR(o.fx(), 320, 1e-9);
  Eigen::Matrix3d K;
  K << 320, 0, 319.5, 0, 320, 239.5, 0, 0, 1;
  EXPECT_TRUE(o.K().isApprox(K, 1e-12));
  o.hfov_deg = 60;
  EXPECT_NEAR(o.fx(), 320 / std::tan(M_PI / 6), 1e-9);

  CameraOptions c;
  const Eigen::Isometry3d T0 = c.T_body_camera();
  EXPECT_TRUE(T0.translation().isApprox(Eigen::Vector3d(0, 0, -0.05)));
  // Nadir: optical axis down, image right = body −y, image down = body −x.
  EXPECT_TRUE((T0.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_TRUE((T0.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE((T0.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d(-1, 0, 0)));
  EXPECT_NEAR(T0.linear().determinant(), 1, 1e-12);
  c.tilt_deg = 30;
  const Eigen::Vector3d axis = c.T_body_camera().linear() * Eigen::Vector3d::UnitZ();
  EXPECT_TRUE(axis.isApprox(Eigen::Vector3d(0.5, 0, -std::sqrt(3) / 2), 1e-12)) << axis.transpose();
  EXPECT_TRUE((c.T_body_camera().linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d(0, -1, 0)));
}

TEST(RenderCamera, RefusesUnknownDictionaryAndIdsOutside) {
  Scenario s = render_scenario();
  s.marker.dictionary = "5X5_42";
  EXPECT_THROW(Renderer(s, CameraOptions{}), touchdown::InvalidArgument);
  s = render_scenario();
  s.marker.id = 50;
  EXPECT_THROW(Renderer(s, CameraOptions{}), touchdown::InvalidArgument);
  s = render_scenario();
  s.distractors.emplace_back().id = 99;
  EXPECT_THROW(Renderer(s, CameraOptions{}), touchdown::InvalidArgument);
  // A state with the wrong number of dynamic poses is misuse.
  s = render_scenario();
  s.dynamic_objects.emplace_back();
  Renderer r(s, CameraOptions{});
  CameraFrame f;
  EXPECT_THROW(r.render(render_state({0, 0, 10}), f), touchdown::InvalidArgument);
}

TEST(RenderMask, MarkerAreaByHandStraightDown) {
  // 4X4: 6 cells of black border + one white cell each side → 8/6 of size.
  const Scenario s = render_scenario();
  CameraOptions cam;
  Renderer r(s, cam);
  CameraFrame f;
  for (double h : {3.0, 6.0, 10.0, 20.0}) {
    r.render(render_state({0, 0, h}), f);
    const double side = cam.fx() * (8.0 / 6.0) / (h - 0.05);  // camera 5 cm under the body
    EXPECT_NEAR(f.marker_area_truth_px, side * side, 1e-6 * side * side) << h;
    EXPECT_NEAR(f.marker_area_visible_px, f.marker_area_truth_px, 0.02 * f.marker_area_truth_px + 2 * side) << h;
  }
  // From 0.5 m the quad (950 px) is larger than the image: truth is clipped to it.
  r.render(render_state({0, 0, 0.5}), f);
  EXPECT_NEAR(f.marker_area_truth_px, 640.0 * 480.0, 1e-6);
  EXPECT_EQ(f.marker_area_visible_px, 640.0 * 480.0);
}

TEST(RenderMask, VisibleAgreesWithTruthAtAltitudesTiltsYaws) {
  Scenario s = render_scenario();
  s.marker.yaw_deg = 20;
  for (double tilt : {0.0, 30.0, 60.0}) {
    CameraOptions cam;
    cam.tilt_deg = tilt;
    Renderer r(s, cam);
    CameraFrame f;
    for (double h : {2.0, 5.0, 12.0}) {
      for (double yaw : {0.0, 45.0, 130.0}) {
        // Stand back so that the tilted axis meets the marker.
        const double back = h * std::tan(tilt * M_PI / 180);
        const Eigen::Vector3d p(-back * std::cos(yaw * M_PI / 180) + 0.3, -back * std::sin(yaw * M_PI / 180), h);
        r.render(render_state(p, yaw), f);
        ASSERT_GT(f.marker_area_truth_px, 20) << tilt << " " << h << " " << yaw;
        const auto quad = render_true_corners(s, cam, render_state(p, yaw), 8.0 / 6.0);
        EXPECT_NEAR(f.marker_area_visible_px, f.marker_area_truth_px,
                    0.03 * f.marker_area_truth_px + 0.5 * render_perimeter(quad))
            << tilt << " " << h << " " << yaw;
      }
    }
  }
}

TEST(RenderDetection, ArucoFindsTheMarkerInClearWeatherOnBothMaps) {
  for (auto map : {touchdown::scenario::MapKind::Ground, touchdown::scenario::MapKind::Lawn}) {
    const Scenario s = render_scenario(map);
    const CameraOptions cam;
    Renderer r(s, cam);
    CameraFrame f;
    for (const Eigen::Vector3d& p :
         {Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(3, -2, 10), Eigen::Vector3d(-4, 1, 10)}) {
      for (double yaw : {0.0, 70.0}) {
        const SceneState st = render_state(p, yaw);
        r.render(st, f);
        const RenderDetection d = render_detect(f, cv::aruco::DICT_4X4_50);
        ASSERT_EQ(d.ids.size(), 1u) << p.transpose() << " yaw " << yaw;
        EXPECT_EQ(d.ids[0], s.marker.id);
        const auto truth = render_true_corners(s, cam, st, s.marker.size);
        for (std::size_t i = 0; i < 4; ++i) {
          const Eigen::Vector2d got(d.corners[0][i].x, d.corners[0][i].y);
          EXPECT_LT((got - truth[i]).norm(), 1.5) << "corner " << i << " at " << p.transpose();
        }
      }
    }
  }
}

TEST(RenderDetection, DenseFogHidesTheMarkerMonotonically) {
  Scenario s = render_scenario();
  const CameraOptions cam;
  CameraFrame f;
  bool failed = false;
  std::vector<int> found;
  for (int i = 0; i <= 8; ++i) {
    s.weather.fog = 0.05 * i;
    Renderer r(s, cam);
    r.render(render_state({0, 0, 10}), f);
    const RenderDetection d = render_detect(f, cv::aruco::DICT_4X4_50);
    const bool ok = d.ids.size() == 1 && d.ids[0] == s.marker.id;
    found.push_back(ok);
    if (i == 0) {
      EXPECT_TRUE(ok);
    }
    if (failed) {
      EXPECT_FALSE(ok) << "found again at fog " << s.weather.fog;
    }
    failed = failed || !ok;
  }
  EXPECT_FALSE(found.back()) << "still found at fog 0.4 (visibility 10 m)";
}

TEST(RenderDepth, GroundIsTheAnalyticPlane) {
  CameraOptions cam;
  cam.tilt_deg = 30;
  Renderer r(render_scenario(), cam);
  CameraFrame f;
  const SceneState st = render_state({1, 2, 7}, 35);
  r.render(st, f);
  const Eigen::Isometry3d T_wc = st.T_world_body * cam.T_body_camera();
  const Eigen::Matrix3d Kinv = cam.K().inverse();
  for (int y = 0; y < f.height; y += 37) {
    for (int x = 0; x < f.width; x += 41) {
      const Eigen::Vector3d ray = T_wc.linear() * (Kinv * Eigen::Vector3d(x, y, 1));  // unit optical-axis component
      const double expected = T_wc.translation().z() / -ray.z();
      EXPECT_NEAR(f.depth[static_cast<std::size_t>(y * f.width + x)], expected, 1e-4 * expected) << x << "," << y;
    }
  }
  // Tilted 80° and pitched up: the top of the image is sky.
  cam.tilt_deg = 80;
  Renderer sky(render_scenario(), cam);
  sky.render(render_state({0, 0, 5}), f);
  EXPECT_EQ(f.mask[10], mask_value(Label::Sky));
  EXPECT_TRUE(std::isinf(f.depth[10]));
  EXPECT_EQ(f.mask[f.mask.size() - 10], mask_value(Label::Ground));
}

TEST(RenderDepth, TopFaceOfABoxAndTheZBuffer) {
  Scenario s = render_scenario();
  s.marker.position = Eigen::Vector2d(20, 20);
  auto& box = s.static_objects.emplace_back();
  box.position = Eigen::Vector2d(0, 0);
  box.size = Eigen::Vector3d(1, 1, 2);
  CameraOptions cam;
  cam.offset_body.setZero();
  {
    Renderer r(s, cam);
    CameraFrame f;
    r.render(render_state({0, 0, 10}), f);
    const std::size_t centre = 240 * 640 + 320;
    EXPECT_EQ(f.mask[centre], mask_value(Label::StaticObject));
    EXPECT_NEAR(f.depth[centre], 8.0, 1e-4);
    EXPECT_EQ(f.mask[10 * 640 + 10], mask_value(Label::Ground));
  }
  // Camera looking east and down at 45° from (−6, 0, 4): along the axis, a
  // 3 m box at x = −4 stands in front of a person at x = −2.5.
  cam.tilt_deg = 45;
  s.static_objects[0].position = Eigen::Vector2d(-4, 0);
  s.static_objects[0].size = Eigen::Vector3d(1, 1, 3);
  auto& person = s.dynamic_objects.emplace_back();
  person.position = Eigen::Vector2d(-2.5, 0);
  SceneState st = render_state({-6, 0, 4}, 0, 1);
  st.T_world_dynamic[0] = Eigen::Translation3d(-2.5, 0, 0) * Eigen::Isometry3d::Identity();
  CameraFrame f;
  const std::size_t centre = 240 * 640 + 320;
  Renderer both(s, cam);
  both.render(st, f);
  EXPECT_EQ(f.mask[centre], mask_value(Label::StaticObject));
  EXPECT_NEAR(f.depth[centre], 1.5 * std::sqrt(2.0), 2e-2);  // the box's west face at x = −4.5
  s.static_objects.clear();
  Renderer alone(s, cam);
  alone.render(st, f);
  EXPECT_EQ(f.mask[centre], mask_value(Label::DynamicObject));
}

TEST(RenderDeterminism, SameStateSameBytesRainChangesPerFrameMaskDoesNot) {
  Scenario s = render_scenario();
  s.weather.rain = 0.8;
  s.weather.snow = 0.3;
  s.weather.ambient = 0.4;
  Renderer r(s, CameraOptions{});
  CameraFrame a, b;
  SceneState st = render_state({0.5, 0.2, 9}, 10);
  r.render(st, a);
  r.render(st, b);
  EXPECT_EQ(a.image.pixels, b.image.pixels);
  EXPECT_EQ(a.mask, b.mask);
  Renderer again(s, CameraOptions{});
  again.render(st, b);
  EXPECT_EQ(a.image.pixels, b.image.pixels);
  st.frame_index = 1;
  r.render(st, b);
  EXPECT_NE(a.image.pixels, b.image.pixels);
  EXPECT_EQ(a.mask, b.mask);
  EXPECT_EQ(a.depth, b.depth);
}

/// The share of the central `side` × `side` pixels that rain, snow or
/// leaves changed by more than 30 grey levels, over `frames` frames:
/// `weather` against the same scene without it.
double particle_cover(Scenario s, const CameraOptions& cam, const touchdown::scenario::Weather& weather, int frames,
                      int side) {
  Renderer clear_renderer(s, cam);
  s.weather = weather;
  Renderer wet_renderer(s, cam);
  CameraFrame clear, wet;
  std::size_t changed = 0, pixels = 0;
  const int x0 = (cam.width - side) / 2, y0 = (cam.height - side) / 2;
  for (int k = 0; k < frames; ++k) {
    SceneState st = render_state({0, 0, 10});
    st.frame_index = k;
    st.t = 0.1 * k;
    clear_renderer.render(st, clear);
    wet_renderer.render(st, wet);
    for (int y = y0; y < y0 + side; ++y) {
      for (int x = x0; x < x0 + side; ++x) {
        const std::size_t i = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(cam.width) + x);
        int d = 0;
        for (std::size_t c = 0; c < 3; ++c)
          d = std::max(d, std::abs(wet.image.pixels[i + c] - clear.image.pixels[i + c]));
        changed += d > 30;
        ++pixels;
      }
    }
  }
  return static_cast<double>(changed) / static_cast<double>(pixels);
}

// Particles fill the air at a fixed density, not the image at a fixed
// count: a 128 × 128 view at the default camera's focal length (the
// oracle's probe) is as covered by snow, rain or leaves as the same
// pixels of the 640 × 480 view around it. Before, each frame drew the same count, so the probe held
// 18.75 × the flakes per pixel and read falling snow as a covered target.
TEST(RenderWeather, ParticlesFillTheAirNotTheImage) {
  const CameraOptions wide;
  CameraOptions narrow = wide;
  narrow.width = narrow.height = 128;
  narrow.hfov_deg = 2 * std::atan(0.5 * 128 / wide.fx()) * 180 / M_PI;
  ASSERT_NEAR(narrow.fx(), wide.fx(), 1e-9 * wide.fx());
  const auto w0 = touchdown::scenario::particle_window(wide);
  EXPECT_EQ(w0.scale, 1.0);
  EXPECT_EQ(w0.u_lo, -0.1 * 640);  // the default camera's window as it always was
  EXPECT_EQ(w0.u_hi, 1.1 * 640);
  EXPECT_EQ(w0.v_hi, 1.1 * 480);
  // The narrow view: the same angular margin (64 and 48 px at this focal length).
  const auto w1 = touchdown::scenario::particle_window(narrow);
  EXPECT_NEAR(w1.u_lo, -64, 1e-9);
  EXPECT_NEAR(w1.v_hi, 128 + 48, 1e-9);
  EXPECT_NEAR(w1.scale, (256.0 * 224) / (768 * 576), 1e-9);
  for (const char* kind : {"snow", "rain", "leaves"}) {
    touchdown::scenario::Weather w;
    if (std::string(kind) == "snow") w.snow = 0.8;
    if (std::string(kind) == "rain") w.rain = 0.8;
    if (std::string(kind) == "leaves") w.leaves = 1.0;
    // Many frames: 128 × 128 pixels hold few particles (a leaf in 3 frames).
    const double a = particle_cover(render_scenario(), wide, w, 60, 128);
    const double b = particle_cover(render_scenario(), narrow, w, 60, 128);
    EXPECT_GT(a, 0) << kind;
    EXPECT_GT(b, 0.6 * a) << kind << ": wide " << a << ", narrow " << b;
    EXPECT_LT(b, 1.6 * a) << kind << ": wide " << a << ", narrow " << b;
  }
}

TEST(RenderOcclusion, ABoxOverTheMarkerHidesPartOfIt) {
  Scenario s = render_scenario();
  Renderer clear(s, CameraOptions{});
  auto& box = s.static_objects.emplace_back();
  box.position = Eigen::Vector2d(0.4, 0);
  box.size = Eigen::Vector3d(0.6, 0.6, 0.5);
  Renderer covered(s, CameraOptions{});
  CameraFrame a, b;
  clear.render(render_state({0, 0, 8}), a);
  covered.render(render_state({0, 0, 8}), b);
  EXPECT_DOUBLE_EQ(a.marker_area_truth_px, b.marker_area_truth_px);
  EXPECT_LT(b.marker_area_visible_px, 0.85 * a.marker_area_visible_px);
  EXPECT_GT(b.marker_area_visible_px, 0.5 * a.marker_area_visible_px);
}

/// Standard deviation of I(x + lag) − I(x) along the rows of a grey image.
double render_lag_sd(const cv::Mat& grey, int lag) {
  double sum = 0, sum2 = 0;
  long n = 0;
  for (int y = 0; y < grey.rows; ++y) {
    const std::uint8_t* p = grey.ptr<std::uint8_t>(y);
    for (int x = 0; x + lag < grey.cols; ++x) {
      const double d = static_cast<double>(p[x + lag]) - static_cast<double>(p[x]);
      sum += d, sum2 += d * d, ++n;
    }
  }
  const double mean = sum / static_cast<double>(n);
  return std::sqrt(sum2 / static_cast<double>(n) - mean * mean);
}

// A camera resolves nothing much finer than its pixels: the sensor averages
// each pixel's area and the lens blurs by about another pixel. Texture
// detail at the pixel scale (concrete grain, grass blades, single leaves)
// must therefore reach the image smoothed: neighbouring pixels differ much
// less than pixels three apart. For white noise both are √2·σ (ratio 1).
// At 10 m (the reference systems' search altitude) the ratio is 0.50–0.61
// over both maps with and without leaf litter; textures sampled at the
// mip level of one footprint (no optics) gave 0.71–0.90.
TEST(RenderOptics, TextureDetailFinerThanTheOpticsDoesNotReachTheImage) {
  for (const auto map : {touchdown::scenario::MapKind::Ground, touchdown::scenario::MapKind::Lawn}) {
    for (const double leaves : {0.0, 0.9}) {
      Scenario s = render_scenario(map);
      s.weather.ground_leaves = leaves;
      Renderer r(s, CameraOptions{});
      CameraFrame f;
      r.render(render_state({30, 20, 10}), f);  // 10 m up; the marker is out of view
      cv::Mat grey;
      cv::cvtColor(render_mat(f), grey, cv::COLOR_BGR2GRAY);
      const double ratio = render_lag_sd(grey, 1) / render_lag_sd(grey, 3);
      EXPECT_LT(ratio, 0.68) << to_string(map) << ", ground leaves " << leaves;
      EXPECT_GT(render_lag_sd(grey, 3), 2.0) << "no texture at all";
    }
  }
}

/// Weather that touches every cached and per-frame piece: ground cover and
/// wetness (the cached texture), low light (the cached noise), particles.
Scenario render_busy_scenario(std::uint64_t seed) {
  Scenario s = render_scenario(touchdown::scenario::MapKind::Lawn);
  s.seed = seed;
  s.weather.ground_snow = 0.3, s.weather.ground_leaves = 0.4, s.weather.ground_wetness = 0.6;
  s.weather.rain = 0.5, s.weather.snow = 0.4, s.weather.leaves = 0.5, s.weather.fog = 0.02, s.weather.ambient = 0.5;
  s.weather.sun_elevation_deg = 65;
  auto& box = s.static_objects.emplace_back();
  box.position = Eigen::Vector2d(1.5, 1), box.size = Eigen::Vector3d(0.8, 0.6, 0.7);
  s.distractors.push_back({touchdown::scenario::DistractorKind::Lookalike, 1, 2, 0.8, Eigen::Vector2d(-2.5, 3), 30});
  return s;
}

std::vector<CameraFrame> render_frames(Renderer& r, int frames) {
  std::vector<CameraFrame> out(static_cast<std::size_t>(frames));
  for (int i = 0; i < frames; ++i) {
    SceneState st = render_state({0.4 * i - 1.0, 0.3, 9 - 0.5 * i}, 15.0 * i);
    st.frame_index = i;
    st.v_world = Eigen::Vector3d(2, 0.5, -0.5);
    r.render(st, out[static_cast<std::size_t>(i)]);
  }
  return out;
}

void expect_same_frames(const std::vector<CameraFrame>& a, const std::vector<CameraFrame>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].image.pixels, b[i].image.pixels) << "frame " << i;
    EXPECT_EQ(a[i].mask, b[i].mask) << "frame " << i;
    EXPECT_EQ(a[i].depth, b[i].depth) << "frame " << i;
  }
}

TEST(RenderCache, ASecondRendererSharesTheTextureAndRendersTheSameBytes) {
  namespace detail = touchdown::scenario::detail;
  const Scenario s = render_busy_scenario(11);
  detail::clear_render_caches();
  std::vector<CameraFrame> cold;
  {
    Renderer r(s, CameraOptions{});
    EXPECT_EQ(detail::cached_map_textures(), 1u);
    cold = render_frames(r, 3);
  }
  // The renderer is gone; the cache still holds its texture.
  EXPECT_EQ(detail::cached_map_textures(), 1u);
  Renderer cached(s, CameraOptions{});
  EXPECT_EQ(detail::cached_map_textures(), 1u);
  expect_same_frames(cold, render_frames(cached, 3));
  // Another texture between two uses of the first changes nothing either.
  Scenario other = s;
  other.weather.ground_snow = 0;
  Renderer r_other(other, CameraOptions{});
  EXPECT_EQ(detail::cached_map_textures(), 2u);
  Renderer again(s, CameraOptions{});
  expect_same_frames(cold, render_frames(again, 3));
}

TEST(RenderCache, HoldsAHandfulOfTexturesAndRenderersOutliveTheirEntries) {
  namespace detail = touchdown::scenario::detail;
  detail::clear_render_caches();
  Scenario s = render_scenario();
  Renderer first(s, CameraOptions{});
  CameraFrame before, after;
  first.render(render_state({0, 0, 6}), before);
  for (std::uint64_t seed = 100; seed < 100 + detail::kMapTextureCacheCapacity + 2; ++seed) {
    s.seed = seed;
    Renderer r(s, CameraOptions{});
    EXPECT_LE(detail::cached_map_textures(), detail::kMapTextureCacheCapacity);
  }
  detail::clear_render_caches();
  EXPECT_EQ(detail::cached_map_textures(), 0u);
  first.render(render_state({0, 0, 6}), after);  // its texture was evicted from the cache, not freed
  EXPECT_EQ(before.image.pixels, after.image.pixels);
}

TEST(RenderMap, DryScenesShareTheMapsGroundAndWetGroundIsDarkerByItsWaterFilm) {
  namespace detail = touchdown::scenario::detail;
  detail::clear_render_caches();
  const Scenario a = render_scenario();
  Scenario b = a;
  b.seed = 8;
  const SceneState st = render_state({3, 2, 8});
  CameraFrame fa, fb, fw;
  Renderer(a, CameraOptions{}).render(st, fa);
  Renderer(b, CameraOptions{}).render(st, fb);
  // One texture for every dry scene of a map; the seed puts the scene at
  // another place on it.
  EXPECT_EQ(detail::cached_map_textures(), 1u);
  EXPECT_NE(fa.image.pixels, fb.image.pixels);
  // Wet without cover: the ground is the same place, darkened by the film
  // (1 − 0.35 at full wetness); the sun is low, so its glare is out of view.
  Scenario wet = a;
  wet.weather.ground_wetness = 1;
  wet.weather.sun_elevation_deg = 15;
  Renderer(wet, CameraOptions{}).render(st, fw);
  double dry_sum = 0, wet_sum = 0;
  std::size_t ground = 0;
  for (std::size_t i = 0; i < fa.mask.size(); ++i) {
    if (fa.mask[i] != mask_value(Label::Ground)) continue;
    ++ground;
    for (std::size_t c = 0; c < 3; ++c) {
      dry_sum += fa.image.pixels[3 * i + c];
      wet_sum += fw.image.pixels[3 * i + c];
    }
  }
  ASSERT_GT(ground, fa.mask.size() / 2);
  EXPECT_NEAR(wet_sum / dry_sum, 0.65, 0.02);
  detail::clear_render_caches();
}

TEST(RenderThreads, TwoThreadsRenderTheSameBytesAsOneThread) {
  namespace detail = touchdown::scenario::detail;
  const Scenario s = render_busy_scenario(23);
  detail::clear_render_caches();
  std::vector<CameraFrame> single;
  {
    Renderer r(s, CameraOptions{});
    single = render_frames(r, 4);
  }
  // Both threads construct at once on an empty cache (one builds, the other
  // waits for it), then render concurrently with their own renderers.
  detail::clear_render_caches();
  std::array<std::vector<CameraFrame>, 2> parallel;
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < parallel.size(); ++i) {
    threads.emplace_back([&, i] {
      Renderer r(s, CameraOptions{});
      parallel[i] = render_frames(r, 4);
    });
  }
  for (auto& t : threads) t.join();
  expect_same_frames(single, parallel[0]);
  expect_same_frames(single, parallel[1]);
}

// Example frames to look at (not a check): run with
//   scenario_tests --gtest_also_run_disabled_tests --gtest_filter='*RenderExamples*'
TEST(RenderExamples, DISABLED_WritePngs) {
  struct Example {
    const char* name;
    touchdown::scenario::MapKind map;
    void (*weather)(touchdown::scenario::Weather&);
  };
  using touchdown::scenario::MapKind;
  using touchdown::scenario::Weather;
  const std::vector<Example> examples{
      {"clear_ground", MapKind::Ground, [](Weather&) {}},
      {"clear_lawn", MapKind::Lawn, [](Weather&) {}},
      {"fog", MapKind::Ground, [](Weather& w) { w.fog = 0.08; }},
      {"rain", MapKind::Ground, [](Weather& w) { w.rain = 1, w.ground_wetness = 0.5, w.ambient = 0.6; }},
      {"snow", MapKind::Lawn, [](Weather& w) { w.snow = 1, w.ground_snow = 0.6, w.ambient = 0.8; }},
      {"leaves", MapKind::Lawn, [](Weather& w) { w.leaves = 1, w.ground_leaves = 0.5; }},
      {"dust", MapKind::Ground, [](Weather& w) { w.dust = 1; }},
      {"wet_glare", MapKind::Ground,
       [](Weather& w) { w.ground_wetness = 1, w.sun_elevation_deg = 70, w.sun_azimuth_deg = 190; }},
      {"low_light", MapKind::Ground, [](Weather& w) { w.ambient = 0.08; }},
  };
  for (const auto& e : examples) {
    Scenario s = render_scenario(e.map);
    e.weather(s.weather);
    auto& box = s.static_objects.emplace_back();
    box.position = Eigen::Vector2d(3, 2.5), box.size = Eigen::Vector3d(1.2, 0.8, 1.0), box.yaw_deg = 20;
    auto& tree = s.static_objects.emplace_back();
    tree.kind = touchdown::scenario::StaticKind::Tree;
    tree.position = Eigen::Vector2d(-4, -3), tree.size = Eigen::Vector3d(3, 0.3, 5);
    auto& pole = s.static_objects.emplace_back();
    pole.kind = touchdown::scenario::StaticKind::Pole;
    pole.position = Eigen::Vector2d(2, -4), pole.size = Eigen::Vector3d(0.2, 0.2, 4);
    s.dynamic_objects.emplace_back().kind = touchdown::scenario::DynamicKind::Person;
    s.distractors.push_back({touchdown::scenario::DistractorKind::Lookalike, 1, 2, 0.8, Eigen::Vector2d(-2.5, 3), 30});
    for (double tilt : {0.0, 50.0}) {
      CameraOptions cam;
      cam.tilt_deg = tilt;
      Renderer r(s, cam);
      SceneState st = render_state({tilt > 0 ? -9.0 : -0.5, 0.3, 10}, 0, 1);
      st.T_world_dynamic[0] = Eigen::Translation3d(1.5, -1.5, 0) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ());
      CameraFrame f;
      r.render(st, f);
      const std::string path = std::string("/tmp/render_") + e.name + (tilt > 0 ? "_tilt" : "") + ".png";
      cv::imwrite(path, render_mat(f));
    }
  }
}
