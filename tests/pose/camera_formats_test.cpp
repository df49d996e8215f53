// Camera files users already have (camera.hpp, issue 11): OpenCV
// calibration files written by cv::FileStorage itself and ROS camera_info
// YAML read back with every intrinsic and coefficient equal, one test per
// malformed or unsupported file (ParseError naming the key), and the
// depth_scale plausibility check.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/camera.hpp"

namespace tp = touchdown::pose;

namespace {

// What a calibration gives: K and D as OpenCV returns them.
struct Calibration {
  int width = 1280, height = 720;
  double fx = 912.3456789012345, fy = 911.0000000000001, cx = 640.123456789, cy = 358.98765432101234;
  std::vector<double> d = {-0.28123456789, 0.0712345, 1.2345678901234e-4, -2.5e-4, -0.0123456789};
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
};

// The text cv::FileStorage writes for the fields of OpenCV's calibration
// sample (samples/cpp/calibration.cpp and the "Camera calibration With
// OpenCV" tutorial write these names), with D of the given shape.
std::string filestorage_yaml(const Calibration& c, int d_rows, int d_cols, int depth = CV_64F) {
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "calibration_time"
     << "Thu Jan 30 14:43:57 2020";
  fs << "nr_of_frames" << 25;
  fs << "image_width" << c.width << "image_height" << c.height;
  fs << "board_width" << 9 << "board_height" << 6 << "square_size" << 0.025;
  fs << "flags" << 0 << "fisheye_model" << 0;
  cv::Mat K(c.K()), D(d_rows, d_cols, CV_64F);
  for (int i = 0; i < d_rows * d_cols; ++i) D.at<double>(i) = c.d[static_cast<std::size_t>(i)];
  if (depth != CV_64F) {
    K.convertTo(K, depth);
    D.convertTo(D, depth);
  }
  fs << "camera_matrix" << K << "distortion_coefficients" << D;
  fs << "avg_reprojection_error" << 0.2134;
  fs << "per_view_reprojection_errors" << cv::Mat(3, 1, CV_32F, cv::Scalar(0.2f));
  fs << "extrinsic_parameters" << cv::Mat(3, 6, CV_64F, cv::Scalar(0.1));
  return fs.releaseAndGetString();
}

// A ROS camera_info YAML as camera_calibration_parsers writes it
// (writeCalibrationYml; format: http://wiki.ros.org/camera_calibration_parsers
// and sensor_msgs/CameraInfo): P is the rectified camera, not K.
const std::string kRosYaml =
    "image_width: 640\n"
    "image_height: 480\n"
    "camera_name: narrow_stereo\n"
    "camera_matrix:\n"
    "  rows: 3\n"
    "  cols: 3\n"
    "  data: [526.6908296825479, 0, 312.3333507245396, 0, 525.7542623070541, 246.2279496394374, 0, 0, 1]\n"
    "distortion_model: plumb_bob\n"
    "distortion_coefficients:\n"
    "  rows: 1\n"
    "  cols: 5\n"
    "  data: [0.01864117263397289, -0.0807953154457166, 0.0006701578887838996, -0.001800282263098739, 0]\n"
    "rectification_matrix:\n"
    "  rows: 3\n"
    "  cols: 3\n"
    "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
    "projection_matrix:\n"
    "  rows: 3\n"
    "  cols: 4\n"
    "  data: [516.2001953125, 0, 310.3634868958034, 0, 0, 514.0494995117188, 246.8852026000968, 0, 0, 0, 1, 0]\n";

// FileStorage's text of a small calibration, written out here so that a
// case can change one line (the first test checks the real writer).
const std::string kOpenCvYaml =
    "%YAML:1.0\n"
    "---\n"
    "image_width: 640\n"
    "image_height: 480\n"
    "camera_matrix: !!opencv-matrix\n"
    "   rows: 3\n"
    "   cols: 3\n"
    "   dt: d\n"
    "   data: [ 6.1234567890123446e+02, 0., 3.2110000000000002e+02, 0.,\n"
    "       6.1300000000000102e+02, 2.3990000000000001e+02, 0., 0., 1. ]\n"
    "distortion_coefficients: !!opencv-matrix\n"
    "   rows: 5\n"
    "   cols: 1\n"
    "   dt: d\n"
    "   data: [ -2.8000000000000003e-01, 7.1234567890123404e-02,\n"
    "       1.0000000000000000e-04, -2.5000000000000001e-04, 0. ]\n";

// `text` with its one occurrence of `from` replaced by `to`.
std::string with(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at == std::string::npos) return text;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "twice: " << from;
  return text.substr(0, at) + to + text.substr(at + from.size());
}

void expect_intrinsics(const tp::CameraModel& m, const Calibration& c) {
  EXPECT_EQ(m.width, c.width);
  EXPECT_EQ(m.height, c.height);
  EXPECT_EQ(m.fx, c.fx);
  EXPECT_EQ(m.fy, c.fy);
  EXPECT_EQ(m.cx, c.cx);
  EXPECT_EQ(m.cy, c.cy);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(m.distortion[i], i < c.d.size() ? c.d[i] : 0.0) << "k[" << i << "]";
}

std::string camera_file_error(const std::string& yaml) {
  return touchdown::test::parse_error_of(tp::parse_camera, yaml, "cam.yaml");
}

}  // namespace

// ---- OpenCV ----------------------------------------------------------------------------

// Every shape of D that OpenCV's calibrateCamera returns or a user saves:
// written by cv::FileStorage, read back bit for bit.
TEST(CameraOpenCvFile, FileStorageRoundTripIsExact) {
  struct Shape {
    int rows, cols;
  };
  for (const Shape s : {Shape{1, 5}, Shape{5, 1}, Shape{1, 4}, Shape{4, 1}}) {
    Calibration c;
    c.d.resize(static_cast<std::size_t>(s.rows * s.cols));
    const std::string yaml = filestorage_yaml(c, s.rows, s.cols);
    ASSERT_EQ(yaml.rfind("%YAML:1.0", 0), 0u) << yaml;
    SCOPED_TRACE(std::to_string(s.rows) + "x" + std::to_string(s.cols));
    const tp::CameraModel m = tp::parse_camera(yaml, "calib.yaml");
    expect_intrinsics(m, c);
    EXPECT_EQ(m.depth_scale, tp::CameraModel{}.depth_scale);
  }
}

// CALIB_RATIONAL_MODEL's 8 coefficients (or 12, 14) with k4.. zero are
// exactly the 5-coefficient model: read; non-zero ones are refused.
TEST(CameraOpenCvFile, EightCoefficientsWithZeroRationalTermsAreRead) {
  Calibration c;
  c.d.resize(8, 0.0);
  const tp::CameraModel m = tp::parse_camera(filestorage_yaml(c, 1, 8), "calib.yaml");
  expect_intrinsics(m, c);
  c.d[6] = 0.01;  // k5
  const std::string msg = camera_file_error(filestorage_yaml(c, 1, 8));
  EXPECT_NE(msg.find("distortion_coefficients: k5 = 0.01"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rational"), std::string::npos) << msg;
}

// dt: f (a float calibration): every value is the float FileStorage wrote.
TEST(CameraOpenCvFile, FloatMatricesReadAsTheirFloats) {
  Calibration c;
  const tp::CameraModel m = tp::parse_camera(filestorage_yaml(c, 1, 5, CV_32F), "calib.yaml");
  EXPECT_EQ(static_cast<float>(m.fx), static_cast<float>(c.fx));
  EXPECT_EQ(static_cast<float>(m.fy), static_cast<float>(c.fy));
  EXPECT_EQ(static_cast<float>(m.cx), static_cast<float>(c.cx));
  EXPECT_EQ(static_cast<float>(m.cy), static_cast<float>(c.cy));
  for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(static_cast<float>(m.distortion[i]), static_cast<float>(c.d[i]));
}

// cv::FileStorage's own documentation example names them cameraMatrix and
// distCoeffs; a std::vector<double> D is written as a plain list.
TEST(CameraOpenCvFile, CameraMatrixAndDistCoeffsNamesAndPlainLists) {
  const Calibration c;
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "image_width" << c.width << "image_height" << c.height;
  fs << "cameraMatrix" << cv::Mat(c.K()) << "distCoeffs" << c.d;
  const tp::CameraModel m = tp::parse_camera(fs.releaseAndGetString(), "calib.yaml");
  expect_intrinsics(m, c);
}

// The model read from the file projects as OpenCV does with the K and D it
// was written from (the coefficients land in OpenCV's order).
TEST(CameraOpenCvFile, ProjectsAsOpenCvWithTheWrittenCalibration) {
  Calibration c;
  c.d = {-0.21, 0.043, 0.0012, -0.0009, -0.004};
  const tp::CameraModel m = tp::parse_camera(filestorage_yaml(c, 1, 5), "calib.yaml");
  std::vector<cv::Point3d> object;
  for (double x = -0.6; x <= 0.6; x += 0.3) {
    for (double y = -0.4; y <= 0.4; y += 0.2) object.emplace_back(x, y, 1.0 + 0.2 * x);
  }
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), c.K(), c.d, image);
  for (std::size_t i = 0; i < object.size(); ++i) {
    const Eigen::Vector2d uv = m.project({object[i].x, object[i].y, object[i].z});
    EXPECT_NEAR(uv.x(), image[i].x, 1e-9);
    EXPECT_NEAR(uv.y(), image[i].y, 1e-9);
  }
}

TEST(CameraOpenCvFile, DepthScaleMayBeAdded) {
  const auto m = tp::parse_camera(kOpenCvYaml + "depth_scale: 0.0001\n", "calib.yaml");
  EXPECT_EQ(m.depth_scale, 0.0001);
  EXPECT_EQ(m.fx, 6.1234567890123446e+02);
}

TEST(CameraOpenCvFile, LoadReadsAFileWrittenByFileStorage) {
  touchdown::test::TempDir dir;
  const Calibration c;
  {
    cv::FileStorage fs((dir / "calib.yml").string(), cv::FileStorage::WRITE);
    const cv::Mat D = cv::Mat(c.d).t();
    fs << "image_width" << c.width << "image_height" << c.height;
    fs << "camera_matrix" << cv::Mat(c.K()) << "distortion_coefficients" << D;
  }
  expect_intrinsics(tp::load_camera(dir / "calib.yml"), c);
}

// ---- ROS ------------------------------------------------------------------------------------

TEST(CameraRosFile, CameraInfoYamlGivesKAndD) {
  const tp::CameraModel m = tp::parse_camera(kRosYaml, "ost.yaml");
  Calibration c;
  c.width = 640;
  c.height = 480;
  c.fx = 526.6908296825479;
  c.fy = 525.7542623070541;
  c.cx = 312.3333507245396;
  c.cy = 246.2279496394374;
  c.d = {0.01864117263397289, -0.0807953154457166, 0.0006701578887838996, -0.001800282263098739, 0};
  expect_intrinsics(m, c);  // K, not P
  EXPECT_EQ(m.depth_scale, tp::CameraModel{}.depth_scale);
}

TEST(CameraRosFile, RationalPolynomialWithZeroRationalTermsIsRead) {
  const std::string yaml = with(with(with(kRosYaml, "plumb_bob", "rational_polynomial"), "cols: 5", "cols: 8"),
                                "-0.001800282263098739, 0]", "-0.001800282263098739, 0, 0, 0, 0]");
  const auto m = tp::parse_camera(yaml, "ost.yaml");
  EXPECT_EQ(m.distortion[3], -0.001800282263098739);
}

TEST(CameraRosFile, EmptyDistortionAndFullImageRoiAreNone) {
  std::string yaml = with(kRosYaml, "cols: 5", "cols: 0");
  yaml =
      with(yaml, "[0.01864117263397289, -0.0807953154457166, 0.0006701578887838996, -0.001800282263098739, 0]", "[]");
  yaml += "binning_x: 0\nbinning_y: 1\nroi: {x_offset: 0, y_offset: 0, height: 480, width: 640, do_rectify: false}\n";
  const auto m = tp::parse_camera(yaml, "ost.yaml");
  EXPECT_FALSE(m.has_distortion());
  EXPECT_EQ(m.fx, 526.6908296825479);
}

// ---- bad and unsupported files --------------------------------------------------------------

class CameraFileBadInput : public ::testing::TestWithParam<touchdown::test::BadInput> {};

TEST_P(CameraFileBadInput, OneErrorNamingTheKey) {
  touchdown::test::expect_one_line_naming(camera_file_error(GetParam().text), GetParam());
}

namespace {
const std::string kRosD = "[0.01864117263397289, -0.0807953154457166, 0.0006701578887838996, -0.001800282263098739, 0]";
const std::string kCvK =
    "   rows: 3\n   cols: 3\n   dt: d\n   data: [ 6.1234567890123446e+02, 0., 3.2110000000000002e+02, 0.,\n"
    "       6.1300000000000102e+02, 2.3990000000000001e+02, 0., 0., 1. ]\n";
std::string cv_k(const std::string& data_line) {
  return with(kOpenCvYaml, kCvK, "   rows: 3\n   cols: 3\n   dt: d\n   data: " + data_line + "\n");
}
}  // namespace

INSTANTIATE_TEST_SUITE_P(
    Cases, CameraFileBadInput,
    ::testing::ValuesIn(std::vector<touchdown::test::BadInput>{
        // OpenCV
        {"OpenCvMissingCameraMatrix",
         "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n",
         {"cam.yaml:", "camera_matrix: missing"}},
        {"OpenCvMissingImageSize", with(kOpenCvYaml, "image_width: 640\n", ""), {"cam.yaml:", "image_width: missing"}},
        {"OpenCvDataSizeDiffersFromRowsTimesCols",
         with(kOpenCvYaml, " 0., 0., 1. ]", " 0., 1. ]"),
         {"cam.yaml:9: camera_matrix.data:", "3x3 needs 9 numbers, got 8"}},
        {"OpenCvCameraMatrixNot3x3",
         with(with(kOpenCvYaml, "   cols: 3\n", "   cols: 4\n"), " 0., 0., 1. ]", " 0., 0., 1., 0., 0., 0. ]"),
         {"cam.yaml:5: camera_matrix: expected a 3x3 matrix, got 3x4"}},
        {"OpenCvNanInCameraMatrix",
         cv_k("[ .Nan, 0., 320., 0., 612., 240., 0., 0., 1. ]"),
         {"cam.yaml:9: camera_matrix.data: expected a number, got '.Nan'"}},
        {"OpenCvNanInDistortion",
         with(kOpenCvYaml, "-2.5000000000000001e-04, 0. ]", "-2.5000000000000001e-04, .Nan ]"),
         {"cam.yaml:", "distortion_coefficients.data: expected a number"}},
        {"OpenCvSkew", cv_k("[ 612., 0.5, 320., 0., 612., 240., 0., 0., 1. ]"), {"cam.yaml:5: camera_matrix: skew"}},
        {"OpenCvNotACameraMatrix",
         cv_k("[ 612., 0., 320., 0., 612., 240., 0., 0., 2. ]"),
         {"cam.yaml:5: camera_matrix: expected [fx, 0, cx; 0, fy, cy; 0, 0, 1]"}},
        {"OpenCvNegativeFocalLength",
         cv_k("[ -612., 0., 320., 0., 612., 240., 0., 0., 1. ]"),
         {"cam.yaml:5: camera_matrix: fx = K[0][0] must be positive"}},
        {"OpenCvMissingRows", with(kOpenCvYaml, "   rows: 3\n", ""), {"camera_matrix.rows: missing"}},
        {"OpenCvThreeCoefficients",
         with(with(kOpenCvYaml, "   rows: 5\n", "   rows: 3\n"), ", -2.5000000000000001e-04, 0. ]", " ]"),
         {"cam.yaml:11: distortion_coefficients: expected 4, 5, 8, 12 or 14 coefficients", "got 3"}},
        {"OpenCvDistortionMatrix2x2",
         with(with(with(kOpenCvYaml, "   rows: 5\n", "   rows: 2\n"), "   cols: 1\n", "   cols: 2\n"),
              "-2.5000000000000001e-04, 0. ]", "-2.5000000000000001e-04 ]"),
         {"distortion_coefficients: expected a 1xN or Nx1 vector, got 2x2"}},
        {"OpenCvFisheyeModel", kOpenCvYaml + "fisheye_model: 1\n", {"cam.yaml:17: fisheye_model:", "fisheye"}},
        {"OpenCvWithOurOwnKeys", kOpenCvYaml + "fx: 600\n", {"cam.yaml:17: fx:", "use one format"}},
        {"OpenCvBothNames",
         kOpenCvYaml + "cameraMatrix: [612, 0, 320, 0, 612, 240, 0, 0, 1]\n",
         {"cam.yaml:17: cameraMatrix: given together with camera_matrix"}},
        {"OpenCvZeroWidth", with(kOpenCvYaml, "image_width: 640", "image_width: 0"), {"cam.yaml:3: image_width:"}},
        // ROS
        {"RosMissingCameraMatrix",
         "image_width: 640\nimage_height: 480\ncamera_name: c\ndistortion_model: plumb_bob\n",
         {"cam.yaml:1: camera_matrix: missing"}},
        {"RosEquidistant",
         with(kRosYaml, "plumb_bob", "equidistant"),
         {"cam.yaml:8: distortion_model: equidistant (fisheye) is not supported"}},
        {"RosUnknownModel", with(kRosYaml, "plumb_bob", "pinhole"), {"cam.yaml:8: distortion_model: unknown model"}},
        {"RosRationalPolynomial",
         with(with(with(kRosYaml, "plumb_bob", "rational_polynomial"), "cols: 5", "cols: 8"),
              "-0.001800282263098739, 0]", "-0.001800282263098739, 0, 0.5, 0, 0]"),
         {"distortion_coefficients: k4 = 0.5", "rational"}},
        {"RosRationalPolynomialWithFiveCoefficients",
         with(kRosYaml, "plumb_bob", "rational_polynomial"),
         {"distortion_coefficients: rational_polynomial has 8 coefficients"}},
        {"RosPlumbBobWithEight",
         with(with(kRosYaml, "cols: 5", "cols: 8"), "-0.001800282263098739, 0]", "-0.001800282263098739, 0, 0, 0, 0]"),
         {"distortion_coefficients: plumb_bob has 5 coefficients"}},
        {"RosMissingDistortion",
         with(kRosYaml, "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: " + kRosD + "\n", ""),
         {"distortion_coefficients: missing"}},
        {"RosDataSizeDiffersFromRowsTimesCols",
         with(kRosYaml, "cols: 5", "cols: 6"),
         {"cam.yaml:12: distortion_coefficients.data: rows x cols = 1x6 needs 6 numbers, got 5"}},
        {"RosNan",
         with(kRosYaml, "[526.6908296825479,", "[nan,"),
         {"cam.yaml:7: camera_matrix.data: expected a number"}},
        {"RosBinning", kRosYaml + "binning_x: 2\n", {"cam.yaml:21: binning_x:", "binned"}},
        {"RosRoi",
         kRosYaml + "roi: {x_offset: 10, y_offset: 0, height: 400, width: 600, do_rectify: true}\n",
         {"cam.yaml:21: roi:", "region of interest"}},
    }),
    touchdown::test::bad_input_name);

// Our own format is read as before: a file with none of the calibration
// files' keys still reports its own missing keys; one that mixes the two
// formats names the key that does not belong.
TEST(CameraFileFormat, OwnFormatErrorsAreUnchangedAndMixedFilesRefused) {
  EXPECT_NE(camera_file_error("width: 640\nheight: 480\nfx: 600\nfy: 600\ncx: 320\n").find("cam.yaml:1: cy: missing"),
            std::string::npos);
  const auto mixed = camera_file_error("width: 640\nimage_height: 480\n");
  EXPECT_NE(mixed.find("cam.yaml:1: width: a key of touchdown's camera YAML"), std::string::npos) << mixed;
}

// ---- depth_scale plausibility -----------------------------------------------------------------

namespace {
touchdown::DepthImage depth_image(int w, int h, std::uint16_t value) {
  touchdown::DepthImage d;
  d.resize(w, h);
  std::fill(d.pixels.begin(), d.pixels.end(), value);
  return d;
}
}  // namespace

TEST(DepthScaleCheck, MillimetresWithTheDefaultScaleArePlausible) {
  const auto d = depth_image(848, 480, 1500);
  const auto c = tp::check_depth_scale(d.view(), 0.001);
  EXPECT_TRUE(c.conclusive);
  EXPECT_TRUE(c.plausible);
  EXPECT_EQ(c.median_raw, 1500);
  EXPECT_NEAR(c.median_m, 1.5, 1e-12);
  EXPECT_GE(c.samples, 3000);
  EXPECT_LE(c.samples, 64 * 64);
  EXPECT_TRUE(c.message.empty());
}

TEST(DepthScaleCheck, MillimetresReadAsMetresAreReported) {
  const auto d = depth_image(640, 480, 2000);
  const auto c = tp::check_depth_scale(d.view(), 1.0);
  EXPECT_TRUE(c.conclusive);
  EXPECT_FALSE(c.plausible);
  EXPECT_EQ(c.median_m, 2000);
  EXPECT_NE(c.message.find("depth_scale: 1 m per unit"), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("median depth at 2000 m"), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("millimetres needs depth_scale: 0.001"), std::string::npos) << c.message;
  EXPECT_EQ(c.message.find('\n'), std::string::npos);
}

TEST(DepthScaleCheck, EveryDepthBelowFiveCentimetresIsReported) {
  const auto d = depth_image(640, 480, 3000);
  const auto c = tp::check_depth_scale(d.view(), 1e-5);
  EXPECT_FALSE(c.plausible);
  EXPECT_NEAR(c.median_m, 0.03, 1e-12);
  EXPECT_NE(c.message.find("depth_scale: 0.001"), std::string::npos) << c.message;
  // A scene 30 cm away in centimetres, read with the millimetre default: 3 cm.
  const auto cm = tp::check_depth_scale(depth_image(640, 480, 30).view(), 0.001);
  EXPECT_FALSE(cm.plausible);
  EXPECT_NE(cm.message.find("centimetres needs depth_scale: 0.01"), std::string::npos) << cm.message;
}

// The median of the nonzero pixels, not the mean: 40 % of the image at
// 1 m, 60 % at 3 m, invalid pixels (0) ignored.
TEST(DepthScaleCheck, MedianOfTheValidPixels) {
  touchdown::DepthImage d = depth_image(640, 480, 0);
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      if (x % 3 == 0) continue;  // invalid
      d.row(y)[x] = y < 192 ? 1000 : 3000;
    }
  }
  const auto c = tp::check_depth_scale(d.view(), 0.001);
  EXPECT_EQ(c.median_raw, 3000);
  EXPECT_TRUE(c.plausible);
}

TEST(DepthScaleCheck, TooFewMeasurementsAreNotConclusive) {
  touchdown::DepthImage d = depth_image(640, 480, 0);
  EXPECT_FALSE(tp::check_depth_scale(d.view(), 1.0).conclusive);
  d.row(244)[325] = 60000;  // one pixel on the sampling grid (steps 10 x 8 from 5, 4)
  const auto c = tp::check_depth_scale(d.view(), 1.0);
  EXPECT_FALSE(c.conclusive);
  EXPECT_TRUE(c.plausible);
  EXPECT_FALSE(tp::check_depth_scale(touchdown::DepthImageView{}, 1.0).conclusive);
}
