// Camera and constellation YAML (camera.hpp, constellation.hpp): round trips,
// the bundled files, one test per malformed input (ParseError naming the
// key), and the distortion model against OpenCV.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"

namespace tp = touchdown::pose;
namespace fs = std::filesystem;

namespace {

fs::path source_path(const std::string& rel) { return fs::path(TOUCHDOWN_SOURCE_DIR) / rel; }

// The ParseError message of parsing `yaml` as "cfg.yaml" (fails the test when it parses).
template <typename Parse>
std::string parse_error(Parse parse, const std::string& yaml) {
  return touchdown::test::parse_error_of(parse, yaml, "cfg.yaml");
}

std::string camera_error(const std::string& yaml) { return parse_error(tp::parse_camera, yaml); }
std::string constellation_error(const std::string& yaml) { return parse_error(tp::parse_constellation, yaml); }

const std::string kCameraYaml =
    "width: 848\nheight: 480\nfx: 615.0\nfy: 616.0\ncx: 423.5\ncy: 239.5\n"
    "distortion: [0.1, -0.2, 0.001, 0.002, 0.03]\ndepth_scale: 0.001\n";

// kCameraYaml with the line of `key` replaced by `line` (or removed when empty).
std::string camera_with(const std::string& key, const std::string& line) {
  return touchdown::test::replace_key_line(kCameraYaml, key, line);
}

// "cfg.yaml:N: invalid YAML..." with lo <= N <= hi.
bool syntax_error_on_line(const std::string& m, int lo, int hi) {
  if (m.rfind("cfg.yaml:", 0) != 0) return false;
  const int line = std::atoi(m.c_str() + 9);
  const auto colon = m.find(':', 9);
  return line >= lo && line <= hi && colon != std::string::npos && m.compare(colon, 14, ": invalid YAML") == 0;
}

std::string leds_yaml(const std::vector<std::string>& xyz) {
  std::string y = "leds:\n";
  const char* colours[] = {"red", "green", "blue", "white"};
  for (std::size_t i = 0; i < xyz.size(); ++i) y += "  - {xyz: [" + xyz[i] + "], color: " + colours[i % 4] + "}\n";
  return y;
}

const std::vector<std::string> kFourLeds = {"0.1, 0.1, 0", "0.1, -0.1, 0", "-0.1, -0.1, 0", "0, 0, -0.1"};

// A built-in constellation equals its bundled file, LED by LED (exactly).
void expect_same_leds(const tp::Constellation& file, const tp::Constellation& builtin) {
  ASSERT_EQ(file.leds.size(), builtin.leds.size());
  for (std::size_t i = 0; i < file.leds.size(); ++i) {
    EXPECT_EQ(file.leds[i].p_body, builtin.leds[i].p_body) << i;
    EXPECT_EQ(file.leds[i].color, builtin.leds[i].color) << i;
    EXPECT_EQ(file.leds[i].normal, builtin.leds[i].normal) << i;
    EXPECT_EQ(file.leds[i].half_angle_deg, builtin.leds[i].half_angle_deg) << i;
  }
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

}  // namespace

// ---- camera ---------------------------------------------------------------------------

// `fx` twice in a camera file was taken (the first value won).
TEST(CameraYaml, RepeatedKeyIsAnError) {
  touchdown::test::TempDir dir;
  const auto f = touchdown::test::with_repeated_key(source_path("data/cameras/d435_848x480.yaml"), dir / "cam.yaml",
                                                    "fx", "600.0");
  EXPECT_EQ(touchdown::test::error_of([&] { (void)tp::load_camera(f.path); }), f.expected);
  EXPECT_THROW((void)tp::load_camera(f.path), touchdown::ParseError);
}

TEST(ConstellationYaml, RepeatedKeyIsAnError) {
  touchdown::test::TempDir dir;
  const auto f = touchdown::test::with_repeated_key(source_path("data/constellations/f450_leds.yaml"),
                                                    dir / "leds.yaml", "name", "other");
  EXPECT_EQ(touchdown::test::error_of([&] { (void)tp::load_constellation(f.path); }), f.expected);
  EXPECT_THROW((void)tp::load_constellation(f.path), touchdown::ParseError);
}

TEST(CameraYaml, RoundTripIsExact) {
  tp::CameraModel c;
  c.width = 1281;
  c.height = 719;
  c.fx = 912.3456789012345;
  c.fy = 911.0000000000001;
  c.cx = 640.123456789;
  c.cy = 358.98765432101234;
  c.distortion = {-0.28123456789, 0.0712345, 1.2345678901234e-4, -2.5e-4, -0.0123456789};
  c.depth_scale = 0.000125;
  const std::string yaml = tp::camera_to_yaml(c);
  const tp::CameraModel d = tp::parse_camera(yaml, "roundtrip");
  EXPECT_EQ(d.width, c.width);
  EXPECT_EQ(d.height, c.height);
  EXPECT_EQ(d.fx, c.fx);
  EXPECT_EQ(d.fy, c.fy);
  EXPECT_EQ(d.cx, c.cx);
  EXPECT_EQ(d.cy, c.cy);
  EXPECT_EQ(d.distortion, c.distortion);
  EXPECT_EQ(d.depth_scale, c.depth_scale);
  EXPECT_EQ(tp::camera_to_yaml(d), yaml);
}

TEST(CameraYaml, DefaultRoundTripsAndFourDistortionCoefficients) {
  const tp::CameraModel c;
  const auto d = tp::parse_camera(tp::camera_to_yaml(c), "default");
  EXPECT_EQ(tp::camera_to_yaml(d), tp::camera_to_yaml(c));
  EXPECT_FALSE(d.has_distortion());
  const auto e = tp::parse_camera(camera_with("distortion", "distortion: [0.1, -0.2, 0.001, 0.002]"), "four");
  EXPECT_EQ(e.distortion, (std::array<double, 5>{0.1, -0.2, 0.001, 0.002, 0.0}));
  const auto f = tp::parse_camera(camera_with("depth_scale", ""), "no depth scale");
  EXPECT_EQ(f.depth_scale, tp::CameraModel{}.depth_scale);
}

TEST(CameraYaml, BundledD435Loads) {
  const auto c = tp::load_camera(source_path("data/cameras/d435_848x480.yaml"));
  EXPECT_EQ(c.width, 848);
  EXPECT_EQ(c.height, 480);
  EXPECT_EQ(c.fx, 615.0);
  EXPECT_EQ(c.fy, 615.0);
  EXPECT_EQ(c.cx, 423.5);
  EXPECT_EQ(c.cy, 239.5);
  EXPECT_FALSE(c.has_distortion());
  EXPECT_EQ(c.depth_scale, 0.001);
}

// One case per malformed camera file: one ParseError naming the file, the
// line where it is known, and the key.
class CameraYamlBadInput : public ::testing::TestWithParam<touchdown::test::BadInput> {};

TEST_P(CameraYamlBadInput, OneErrorNamingTheKey) {
  touchdown::test::expect_one_line_naming(camera_error(GetParam().text), GetParam());
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CameraYamlBadInput,
    ::testing::ValuesIn(std::vector<touchdown::test::BadInput>{
        {"UnknownKey", kCameraYaml + "fz: 600\n", {"cfg.yaml:9: fz: unknown key"}},
        {"MissingFx", camera_with("fx", ""), {"cfg.yaml", "fx: missing"}},
        {"ZeroFx", camera_with("fx", "fx: 0"), {"cfg.yaml", "fx:"}},
        {"NonNumericFx", camera_with("fx", "fx: six hundred"), {"cfg.yaml:3: fx: expected a number"}},
        {"DistortionWithThreeNumbers",
         camera_with("distortion", "distortion: [0.1, 0.2, 0.3]"),
         {"cfg.yaml:7: distortion:", "3 numbers"}},
        {"ZeroDepthScale", camera_with("depth_scale", "depth_scale: 0"), {"cfg.yaml", "depth_scale:"}},
        {"ZeroWidth", camera_with("width", "width: 0"), {"cfg.yaml", "width:"}},
        {"FractionalHeight", camera_with("height", "height: 480.5"), {"cfg.yaml:2: height: expected an integer"}},
        {"NotAMapping", "- 1\n- 2\n", {"cfg.yaml"}},
        {"Empty", "", {"cfg.yaml"}},
    }),
    touchdown::test::bad_input_name);

TEST(CameraYamlBadInput, InvalidSyntaxNamesTheLine) {
  const auto m = camera_error("width: 848\nheight: 480\nfx: [615, 616\nfy: 615\ncx: {\n");
  EXPECT_TRUE(syntax_error_on_line(m, 3, 6)) << m;
}

TEST(CameraYamlBadInput, LoadNamesTheFile) {
  EXPECT_THROW((void)tp::load_camera("/nonexistent/dir/camera.yaml"), touchdown::IoError);
}

// ---- constellation ------------------------------------------------------------------------

TEST(ConstellationYaml, RoundTripIsExact) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  tp::Constellation k;
  const tp::LedColor colours[] = {tp::LedColor::Red, tp::LedColor::Green, tp::LedColor::Blue, tp::LedColor::White};
  for (int i = 0; i < 7; ++i) k.leds.push_back({{u(rng), u(rng), u(rng)}, colours[i % 4]});
  k.T_body_marker = Eigen::Translation3d(0.0123456789, -0.0234567891, -0.0456789123) *
                    Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, -0.5, 0.8).normalized());
  const std::string yaml = tp::constellation_to_yaml(k);
  const auto d = tp::parse_constellation(yaml, "roundtrip");
  ASSERT_EQ(d.leds.size(), k.leds.size());
  for (std::size_t i = 0; i < k.leds.size(); ++i) {
    EXPECT_EQ(d.leds[i].p_body, k.leds[i].p_body) << i;
    EXPECT_EQ(d.leds[i].color, k.leds[i].color) << i;
  }
  EXPECT_EQ(d.T_body_marker.translation(), k.T_body_marker.translation());
  // The rotation travels as roll/pitch/yaw in degrees: exact up to the
  // radian → degree → radian rounding.
  EXPECT_LT((d.T_body_marker.linear() - k.T_body_marker.linear()).cwiseAbs().maxCoeff(), 1e-14)
      << d.T_body_marker.linear() << "\nvs\n"
      << k.T_body_marker.linear();
  // Written again, the text is stable.
  const auto e = tp::parse_constellation(tp::constellation_to_yaml(d), "again");
  EXPECT_EQ(e.T_body_marker.translation(), k.T_body_marker.translation());
  EXPECT_LT((e.T_body_marker.linear() - k.T_body_marker.linear()).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(ConstellationYaml, DefaultMarkerPoseRoundTripsExactly) {
  tp::Constellation k = tp::default_constellation();
  const auto d = tp::parse_constellation(tp::constellation_to_yaml(k), "default");
  EXPECT_EQ(d.T_body_marker.matrix(), k.T_body_marker.matrix());
}

TEST(ConstellationYaml, BuiltInEqualsBundledFile) {
  const auto file = tp::load_constellation(source_path("data/constellations/f450_leds.yaml"));
  const auto builtin = tp::default_constellation();
  expect_same_leds(file, builtin);
  EXPECT_EQ(file.T_body_marker.matrix(), builtin.T_body_marker.matrix());
}

TEST(ConstellationYaml, BundledBoardLoads) {
  const auto k = tp::load_constellation(source_path("data/constellations/f450_board.yaml"));
  EXPECT_EQ(k.leds.size(), 6u);
  EXPECT_EQ(k.leds[4].color, tp::LedColor::Blue);
  EXPECT_FALSE(k.planar(1e-3));  // 5 mm relief
  EXPECT_TRUE(k.planar(5e-3));
  std::string why;
  EXPECT_TRUE(k.validate(&why)) << why;
}

TEST(ConstellationYaml, EmissionConesReadNormaliseAndRoundTrip) {
  const auto k = tp::parse_constellation(
      "leds:\n"
      "  - {xyz: [0.1, 0.1, 0], normal: [2, 0, 0], half_angle_deg: 60}\n"  // any length: normalised
      "  - {xyz: [0.1, -0.1, 0], normal: [0, 3, 4]}\n"                     // half-angle defaults to 90
      "  - {xyz: [-0.1, -0.1, 0]}\n"                                       // no normal: omnidirectional
      "  - {xyz: [0, 0, -0.1], normal: [0, 0, -1], half_angle_deg: 179.5}\n",
      "cones");
  EXPECT_EQ(k.leds[0].normal, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(k.leds[0].half_angle_deg, 60);
  EXPECT_TRUE(k.leds[1].normal.isApprox(Eigen::Vector3d(0, 0.6, 0.8), 1e-15));
  EXPECT_EQ(k.leds[1].half_angle_deg, 90);
  EXPECT_FALSE(k.leds[2].has_normal());
  const auto again = tp::parse_constellation(tp::constellation_to_yaml(k), "again");
  for (std::size_t i = 0; i < k.leds.size(); ++i) {
    EXPECT_EQ(again.leds[i].normal, k.leds[i].normal) << i;
    EXPECT_EQ(again.leds[i].half_angle_deg, k.leds[i].half_angle_deg) << i;
  }
  // facing(): the normalised sum of the normals (zero without any).
  EXPECT_TRUE(k.facing().isApprox(Eigen::Vector3d(1, 0.6, -0.2).normalized(), 1e-15));
  EXPECT_EQ(tp::parse_constellation(leds_yaml(kFourLeds), "none").facing(), Eigen::Vector3d::Zero());
}

TEST(ConstellationYaml, BundledFrontBoardFacesForward) {
  const auto k = tp::load_constellation(source_path("data/constellations/front_board.yaml"));
  const auto builtin = tp::front_board_constellation();
  expect_same_leds(k, builtin);
  EXPECT_LT((k.T_body_marker.matrix() - builtin.T_body_marker.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  ASSERT_EQ(k.leds.size(), 6u);
  int red = 0, green = 0;
  for (const auto& l : k.leds) {
    red += l.color == tp::LedColor::Red;
    green += l.color == tp::LedColor::Green;
    EXPECT_EQ(l.normal, Eigen::Vector3d(1, 0, 0));
  }
  EXPECT_EQ(red, 3);
  EXPECT_EQ(green, 3);
  EXPECT_EQ(k.facing(), Eigen::Vector3d(1, 0, 0));
  EXPECT_FALSE(k.planar(5e-3));  // quasi-planar: 2 cm of relief
  EXPECT_TRUE(k.planar(2e-2));
  // The marker faces forward too.
  EXPECT_TRUE((k.T_body_marker.linear() * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  std::string why;
  EXPECT_TRUE(k.validate(&why)) << why;
  // The library's check is the parser's: a half-angle in radians is refused.
  auto narrow = k;
  narrow.leds[2].half_angle_deg = std::numbers::pi / 3;
  EXPECT_FALSE(narrow.validate(&why));
  EXPECT_NE(why.find("leds[2].half_angle_deg: is 1.04"), std::string::npos) << why;
  EXPECT_NE(why.find("radians? (1.04"), std::string::npos) << why;
  narrow.leds[2].half_angle_deg = 3.5;  // narrow, but degrees
  EXPECT_TRUE(narrow.validate(&why)) << why;
}

TEST(ConstellationYaml, MarkerDefaultsAndColourDefault) {
  const auto k = tp::parse_constellation(
      "leds:\n  - {xyz: [0.1, 0.1, 0]}\n  - {xyz: [0.1, -0.1, 0]}\n"
      "  - {xyz: [-0.1, -0.1, 0]}\n  - {xyz: [0, 0, -0.1]}\n",
      "no marker");
  EXPECT_EQ(k.leds[0].color, tp::LedColor::White);
  EXPECT_EQ(k.T_body_marker.matrix(), tp::Constellation::default_marker_pose().matrix());
  const auto m = tp::parse_constellation(leds_yaml(kFourLeds) + "marker: {xyz: [0, 0, -0.05]}\n", "marker xyz only");
  EXPECT_EQ(m.T_body_marker.linear(), tp::Constellation::default_marker_pose().linear());
  EXPECT_EQ(m.T_body_marker.translation(), Eigen::Vector3d(0, 0, -0.05));
}

// One case per malformed constellation file.
class ConstellationYamlBadInput : public ::testing::TestWithParam<touchdown::test::BadInput> {};

TEST_P(ConstellationYamlBadInput, OneErrorNamingTheKey) {
  touchdown::test::expect_one_line_naming(constellation_error(GetParam().text), GetParam());
}

namespace {

std::vector<touchdown::test::BadInput> constellation_cases() {
  std::string purple = leds_yaml(kFourLeds);
  purple.replace(purple.find("red"), 3, "purple");
  std::vector<std::string> seventeen;
  for (int i = 0; i < 17; ++i) {
    seventeen.push_back(std::to_string(0.1 * std::cos(0.37 * i)) + ", " + std::to_string(0.1 * std::sin(0.37 * i)) +
                        ", " + std::to_string(0.01 * i));
  }
  return {
      {"UnknownKey", leds_yaml(kFourLeds) + "lights: 3\n", {"cfg.yaml:6: lights: unknown key"}},
      {"UnknownLedKey", "leds:\n  - {xyz: [0, 0, 0], colour: red}\n", {"cfg.yaml:2: leds[0].colour: unknown key"}},
      {"UnknownMarkerKey",
       leds_yaml(kFourLeds) + "marker: {xyz: [0, 0, 0], rpy: [0, 0, 0]}\n",
       {"marker.rpy: unknown key"}},
      {"PurpleLed", purple, {"cfg.yaml:2: leds[0].color: 'purple' is not red, green, blue or white"}},
      // Unknown is what the detector calls a blob of no class, never an LED's colour.
      {"UnknownColourLed",
       touchdown::test::replace(leds_yaml(kFourLeds), "red", "unknown"),
       {"cfg.yaml:2: leds[0].color: 'unknown' is not red, green, blue or white"}},
      {"XyzWithTwoNumbers",
       leds_yaml({"0.1, 0.1, 0", "0.1, -0.1", "-0.1, -0.1, 0", "0, 0, -0.1"}),
       {"cfg.yaml:3: leds[1].xyz: expected 3 numbers"}},
      {"MarkerXyzWithTwoNumbers", leds_yaml(kFourLeds) + "marker: {xyz: [0, 0]}\n", {"marker.xyz"}},
      {"MarkerRpyWithFourNumbers", leds_yaml(kFourLeds) + "marker: {rpy_deg: [0, 0, 0, 1]}\n", {"marker.rpy_deg"}},
      {"MissingLeds", "name: nothing\n", {"leds: missing"}},
      {"LedsNotASequence", "leds: 3\n", {"leds:"}},
      {"DuplicateLeds",
       leds_yaml({"0.1, 0.1, 0", "0.1, -0.1, 0", "-0.1, -0.1, 0", "0.1, -0.1, 0.0005", "0, 0, -0.1"}),
       {"cfg.yaml", "leds[3]: duplicates leds[1]"}},
      {"CollinearLeds",
       leds_yaml({"0, 0, 0", "0.1, 0.1, 0.1", "0.2, 0.2, 0.2", "-0.3, -0.3, -0.3"}),
       {"cfg.yaml", "leds:", "collinear"}},
      {"TooFewLeds", leds_yaml({"0.1, 0.1, 0", "0.1, -0.1, 0", "-0.1, -0.1, 0"}), {"leds:", "at least 4"}},
      {"TooManyLeds", leds_yaml(seventeen), {"leds:", "at most 16"}},
      {"ZeroLengthNormal",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, 0]}\n",
       {"cfg.yaml:2: leds[0].normal: zero length"}},
      {"NormalWithTwoNumbers", "leds:\n  - {xyz: [0, 0, 0], normal: [0, 1]}\n", {"cfg.yaml:2: leds[0].normal:"}},
      {"HalfAngleZero",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, -1], half_angle_deg: 0}\n",
       {"cfg.yaml:2: leds[0].half_angle_deg: must be in (0, 180)"}},
      {"HalfAngle180",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, -1], half_angle_deg: 180}\n",
       {"leds[0].half_angle_deg: must be in (0, 180)"}},
      {"HalfAngleInRadians",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, -1], half_angle_deg: 0.7854}\n",
       {"cfg.yaml:2: leds[0].half_angle_deg: is 0.7854 degrees", "radians? (0.7854 rad = 45 degrees)"}},
      {"HalfAngleNegative",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, -1], half_angle_deg: -30}\n",
       {"leds[0].half_angle_deg: must be in (0, 180)"}},
      {"HalfAngleNotANumber",
       "leds:\n  - {xyz: [0, 0, 0], normal: [0, 0, -1], half_angle_deg: wide}\n",
       {"leds[0].half_angle_deg: expected a number"}},
      {"HalfAngleWithoutNormal",
       "leds:\n  - {xyz: [0, 0, 0], half_angle_deg: 60}\n",
       {"cfg.yaml:2: leds[0].half_angle_deg: needs a normal"}},
      {"NormalNotFinite", "leds:\n  - {xyz: [0, 0, 0], normal: [.inf, 0, 0]}\n", {"leds[0].normal"}},
  };
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cases, ConstellationYamlBadInput, ::testing::ValuesIn(constellation_cases()),
                         touchdown::test::bad_input_name);

TEST(ConstellationYaml, SixteenLedsAreTheLimitNotAnError) {
  std::vector<std::string> xyz;
  for (int i = 0; i < 16; ++i) {
    xyz.push_back(std::to_string(0.1 * std::cos(0.37 * i)) + ", " + std::to_string(0.1 * std::sin(0.37 * i)) + ", " +
                  std::to_string(0.01 * i));
  }
  EXPECT_EQ(tp::parse_constellation(leds_yaml(xyz), "sixteen").leds.size(), 16u);
}

TEST(ConstellationYamlBadInput, InvalidSyntaxNamesTheLine) {
  const auto m = constellation_error("leds:\n  - {xyz: [0, 0, 0], color: red}\n  - {xyz: [0, 0, 0, color: red}\n");
  EXPECT_TRUE(syntax_error_on_line(m, 2, 4)) << m;
}

// ---- distortion ---------------------------------------------------------------------------

namespace {

struct Lens {
  const char* name;
  std::array<double, 5> k;
};

// A near-pinhole depth camera, a typical webcam, and a wide lens with strong barrel distortion.
const Lens kLenses[] = {{"mild", {-0.05, 0.06, 0.001, -0.0007, -0.02}},
                        {"webcam", {-0.28, 0.09, 0.0012, -0.0009, -0.015}},
                        {"wide", {-0.38, 0.17, -0.002, 0.0015, -0.04}}};

}  // namespace

TEST(CameraDistortion, UndistortInvertsProjectAndAgreesWithOpenCv) {
  for (const auto& lens : kLenses) {
    SCOPED_TRACE(lens.name);
    tp::CameraModel cam;
    cam.distortion = lens.k;
    ASSERT_TRUE(cam.has_distortion());
    const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
    const std::vector<double> D(lens.k.begin(), lens.k.end());
    std::mt19937 rng(11);
    // Points whose pinhole image lies in the frame (normalised |x| ≤ 0.69, |y| ≤ 0.39).
    std::uniform_real_distribution<double> ux(-0.68, 0.68), uy(-0.38, 0.38), uz(0.3, 6.0);
    std::vector<cv::Point3d> object;
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 500; ++i) {
      const double z = uz(rng);
      const double y = uy(rng) * z;  // drawn y first, as recorded
      points.emplace_back(ux(rng) * z, y, z);
      object.emplace_back(points.back().x(), points.back().y(), z);
    }
    std::vector<cv::Point2d> projected;
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, projected);
    std::vector<cv::Point2d> distorted;
    for (const auto& p : points) {
      const Eigen::Vector2d uv = cam.project(p);
      distorted.emplace_back(uv.x(), uv.y());
    }
    std::vector<cv::Point2d> undistorted;
    cv::undistortPoints(distorted, undistorted, K, D, cv::noArray(), K,
                        cv::TermCriteria(cv::TermCriteria::COUNT, 200, 0));
    double worst_project = 0, worst_inverse = 0, worst_opencv = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d uv = cam.project(points[i]);
      worst_project = std::max(worst_project, (uv - Eigen::Vector2d(projected[i].x, projected[i].y)).norm());
      const Eigen::Vector2d back = cam.undistort(uv);
      worst_inverse = std::max(worst_inverse, (back - cam.pinhole().project(points[i])).norm());
      worst_opencv = std::max(worst_opencv, (back - Eigen::Vector2d(undistorted[i].x, undistorted[i].y)).norm());
    }
    EXPECT_LT(worst_project, 1e-6) << "project vs cv::projectPoints [px]";
    EXPECT_LT(worst_inverse, 1e-6) << "undistort(project(p)) vs the pinhole pixel [px]";
    EXPECT_LT(worst_opencv, 1e-6) << "undistort vs cv::undistortPoints [px]";
  }
}

TEST(CameraDistortion, NoDistortionIsTheIdentity) {
  const tp::CameraModel cam;
  const Eigen::Vector2d uv(123.25, 456.5);
  EXPECT_EQ(cam.undistort(uv), uv);
  const Eigen::Vector3d p(0.1, -0.2, 1.5);
  EXPECT_EQ(cam.project(p), cam.pinhole().project(p));
}
