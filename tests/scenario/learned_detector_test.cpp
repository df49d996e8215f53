// The learned marker detector (learned_detector.hpp): its decoding and
// non-maximum suppression on hand-made network outputs, the letterbox, the
// manifest's and the model file's errors, C++ (OpenCV DNN) against the
// PyTorch outputs stored when the shipped model was trained, and
// determinism across threads.
#include "scenario/learned_detector.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <thread>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/scenario/marker_detector.hpp"

namespace touchdown::scenario {
namespace {

namespace fs = std::filesystem;
using detail::ModelManifest;

const fs::path kModel = fs::path(TOUCHDOWN_SOURCE_DIR) / "data/models/marker-4x4_50-0.onnx";
const fs::path kVectors = fs::path(TOUCHDOWN_SOURCE_DIR) / "tests/data/detector";

ModelManifest manifest(int stride = 8, double corner_scale = 64) {
  ModelManifest m;
  m.dictionary = "4X4_50";
  m.width = 64;
  m.height = 48;
  m.stride = stride;
  m.channels = 11;
  m.corner_scale = corner_scale;
  return m;
}

/// A hand-made output of 11 x rows x cols, all zero.
struct Output {
  int rows, cols;
  std::vector<float> v;
  Output(int r, int c) : rows(r), cols(c), v(static_cast<std::size_t>(11 * r * c), 0.0f) {}
  float& at(int ch, int r, int c) { return v[static_cast<std::size_t>((ch * rows + r) * cols + c)]; }
  /// A peak at cell (r, c): heat, centre offset, and a square of half side
  /// `half` [input px] about the centre (corners clockwise from top-left).
  void peak(int r, int c, float heat, float ox, float oy, float half, float scale = 64) {
    at(0, r, c) = heat;
    at(1, r, c) = ox;
    at(2, r, c) = oy;
    const float d[4][2] = {{-half, -half}, {half, -half}, {half, half}, {-half, half}};
    for (int k = 0; k < 4; ++k) {
      at(3 + 2 * k, r, c) = d[k][0] / scale;
      at(4 + 2 * k, r, c) = d[k][1] / scale;
    }
  }
};

TEST(LearnedDecode, APeakGivesItsCentreCornersAndConfidence) {
  Output o(6, 8);
  o.peak(2, 3, 0.9f, 0.5f, 0.25f, 16);
  o.at(0, 2, 4) = 0.8f;  // a neighbour below the peak: not a detection
  const auto d = detail::decode_heatmap(o.v.data(), 6, 8, manifest(), detail::letterbox(64, 48, 64, 48), 0.3, 0.45, 0);
  ASSERT_EQ(d.size(), 1u);
  // Centre ((3 + 0.5) x 8, (2 + 0.25) x 8) = (28, 18); corners ±16 px.
  EXPECT_NEAR(d[0].centre().x(), 28.0, 1e-5);
  EXPECT_NEAR(d[0].centre().y(), 18.0, 1e-5);
  EXPECT_NEAR(d[0].corners[0].x(), 12.0, 1e-5);
  EXPECT_NEAR(d[0].corners[0].y(), 2.0, 1e-5);
  EXPECT_NEAR(d[0].corners[2].x(), 44.0, 1e-5);
  EXPECT_NEAR(d[0].corners[2].y(), 34.0, 1e-5);
  EXPECT_NEAR(d[0].box_max.x() - d[0].box_min.x(), 32.0, 1e-5);
  EXPECT_NEAR(d[0].confidence, 0.9, 1e-6);
  EXPECT_TRUE(d[0].has_corners);
  EXPECT_FALSE(d[0].oriented);
  EXPECT_EQ(d[0].id, 0);
}

TEST(LearnedDecode, ThresholdNaNAndNonMaximumSuppression) {
  Output o(6, 8);
  o.peak(2, 2, 0.9f, 0.5f, 0.5f, 20);   // A: box (0..40, 0..40)
  o.peak(2, 4, 0.7f, 0.5f, 0.5f, 20);   // B: two cells right, box (16..56): IoU with A 0.43 < 0.45: kept
  o.peak(4, 2, 0.75f, 0.0f, 0.5f, 18);  // C: box (-2..34, 18..54): IoU 748 / 2148 = 0.35 with A, kept
  o.peak(0, 7, 0.2f, 0.5f, 0.5f, 4);    // below the threshold
  o.at(0, 5, 7) = std::numeric_limits<float>::quiet_NaN();
  const auto d = detail::decode_heatmap(o.v.data(), 6, 8, manifest(), detail::letterbox(64, 48, 64, 48), 0.3, 0.45, 0);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_NEAR(d[0].confidence, 0.9, 1e-6);  // highest first
  EXPECT_NEAR(d[1].confidence, 0.75, 1e-6);
  EXPECT_NEAR(d[2].confidence, 0.7, 1e-6);
  // A stricter overlap limit drops B (IoU 0.43 with A) and C (0.35).
  const auto strict =
      detail::decode_heatmap(o.v.data(), 6, 8, manifest(), detail::letterbox(64, 48, 64, 48), 0.3, 0.3, 0);
  ASSERT_EQ(strict.size(), 1u);
  EXPECT_NEAR(strict[0].confidence, 0.9, 1e-6);
}

TEST(LearnedDecode, BoxIouIsIntersectionOverUnion) {
  MarkerDetection a, b;
  a.box_min = {0, 0}, a.box_max = {40, 40};
  b.box_min = {16, 0}, b.box_max = {56, 40};
  EXPECT_NEAR(detail::box_iou(a, b), 24.0 * 40 / (2 * 1600 - 24.0 * 40), 1e-12);
  b.box_min = {50, 50}, b.box_max = {60, 60};
  EXPECT_EQ(detail::box_iou(a, b), 0.0);
  EXPECT_NEAR(detail::box_iou(a, a), 1.0, 1e-12);
  MarkerDetection empty;
  EXPECT_EQ(detail::box_iou(empty, empty), 0.0);
}

TEST(LearnedDecode, LetterboxMapsDetectionsBackToTheFrame) {
  // A 1280 x 960 frame into 640 x 480: scale 0.5, no padding.
  auto b = detail::letterbox(1280, 960, 640, 480);
  EXPECT_DOUBLE_EQ(b.scale, 0.5);
  EXPECT_EQ(b.offset, Eigen::Vector2d(0, 0));
  // A square 640 x 640 frame: scale 0.75 to 480 x 480, 80 px bars left and right.
  b = detail::letterbox(640, 640, 640, 480);
  EXPECT_DOUBLE_EQ(b.scale, 0.75);
  EXPECT_EQ(b.width, 480);
  EXPECT_EQ(b.height, 480);
  EXPECT_EQ(b.offset, Eigen::Vector2d(80, 0));
  // A peak at input (28, 18) is frame ((28 - 80) / 0.75, 18 / 0.75) there.
  Output o(6, 8);
  o.peak(2, 3, 0.9f, 0.5f, 0.25f, 16);
  const auto d = detail::decode_heatmap(o.v.data(), 6, 8, manifest(), b, 0.3, 0.45, 0);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_NEAR(d[0].centre().x(), (28.0 - 80) / 0.75, 1e-5);
  EXPECT_NEAR(d[0].centre().y(), 18.0 / 0.75, 1e-5);
}

// ---- the model and its manifest: clear errors naming the file ----

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

class ModelFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() / ("td_model_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                     "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  nlohmann::json shipped_manifest() const {
    std::ifstream in(detail::manifest_path(kModel));
    return nlohmann::json::parse(in);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

TEST_F(ModelFiles, AMissingModelNamesTheFile) {
  const std::string e = error_of([&] { detail::LearnedDetector(dir_ / "none.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find("none.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
  DetectorOptions o;
  o.kind = "learned";
  o.model = dir_ / "none.onnx";
  EXPECT_THROW(make_marker_detector(o), InvalidArgument);
}

TEST_F(ModelFiles, AModelsIdIsItsBytesAndItsManifestsAndNamesAMissingFile) {
  // FNV-1a 64 of "a" then "" (the published test vector: af63dc4c8601ec8c).
  const fs::path model = write("m.onnx", "a");
  write("m.json", "");
  EXPECT_EQ(learned_model_id(model), "fnv1a64:af63dc4c8601ec8c");
  write("m.json", "b");  // "ab": a manifest edit changes the id
  EXPECT_EQ(learned_model_id(model), "fnv1a64:89c4407b545986a");
  EXPECT_NE(learned_model_id(kModel), learned_model_id(model));
  fs::remove(dir_ / "m.json");
  try {
    (void)learned_model_id(model);
    ADD_FAILURE() << "no error for a missing manifest";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("m.json"), std::string::npos) << e.what();
  }
}

TEST_F(ModelFiles, ATruncatedModelNamesTheFile) {
  std::ifstream in(kModel, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 10000u);
  const fs::path model = write("cut.onnx", bytes.substr(0, bytes.size() / 3));
  write("cut.json", shipped_manifest().dump());
  const std::string e = error_of([&] { detail::LearnedDetector(model, 0.3, 0.45); });
  EXPECT_NE(e.find("cut.onnx"), std::string::npos) << e;
}

TEST_F(ModelFiles, AModelOfAnotherShapeThanItsManifestSaysIsRefused) {
  fs::copy_file(kModel, dir_ / "m.onnx");
  nlohmann::json j = shipped_manifest();
  j["output"]["stride"] = 16;  // the network's output is 1/8 of its input
  write("m.json", j.dump());
  const std::string e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find("m.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("output shape"), std::string::npos) << e;
}

TEST_F(ModelFiles, ManifestErrorsNameTheFileAndKey) {
  fs::copy_file(kModel, dir_ / "m.onnx");
  const auto with = [&](const std::function<void(nlohmann::json&)>& change) {
    nlohmann::json j = shipped_manifest();
    change(j);
    write("m.json", j.dump());
    return error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  };
  std::string e = with([](nlohmann::json& j) { j["marker"].erase("id"); });
  EXPECT_NE(e.find("m.json"), std::string::npos) << e;
  EXPECT_NE(e.find("marker.id"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["output"]["channels"] = 12; });
  EXPECT_NE(e.find("output.channels"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["input"]["width"] = "wide"; });
  EXPECT_NE(e.find("input.width"), std::string::npos) << e;
  // Numbers that are not ints: no cast (a double past int's range is
  // undefined behaviour; fuzz_model_manifest found "channels": 1.4e44).
  e = with([](nlohmann::json& j) { j["output"]["channels"] = 1.4e44; });
  EXPECT_NE(e.find("output.channels: expected an integer, got a fraction"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["input"]["width"] = 640.5; });
  EXPECT_NE(e.find("input.width: expected an integer, got a fraction"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["output"]["stride"] = std::uint64_t{1} << 40; });
  EXPECT_NE(e.find("output.stride: integer out of range"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["marker"]["id"] = -(std::int64_t{1} << 40); });
  EXPECT_NE(e.find("marker.id: integer out of range"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["format"] = "yolo"; });
  EXPECT_NE(e.find("format"), std::string::npos) << e;
  // The second stage: its keys, and a file beside the manifest only.
  e = with([](nlohmann::json& j) { j["verifier"].erase("patch"); });
  EXPECT_NE(e.find("verifier.patch"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["verifier"]["file"] = "../elsewhere.onnx"; });
  EXPECT_NE(e.find("verifier.file"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["verifier"]["max_proposals"] = 0; });
  EXPECT_NE(e.find("verifier.max_proposals"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j.erase("verifier"); });
  EXPECT_NE(e.find("verifier.file: missing"), std::string::npos) << e;
  e = with([](nlohmann::json& j) { j["format"] = "touchdown-detector/1"; });
  EXPECT_NE(e.find("verifier: only in format"), std::string::npos) << e;
  write("m.json", "{not json");
  e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find("not JSON"), std::string::npos) << e;
  fs::remove(dir_ / "m.json");
  e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find("m.json"), std::string::npos) << e;
}

TEST_F(ModelFiles, AMissingOrBrokenVerifierNamesItsFile) {
  fs::copy_file(kModel, dir_ / "m.onnx");
  const nlohmann::json j = shipped_manifest();
  write("m.json", j.dump());
  const std::string file = j.at("verifier").at("file");
  std::string e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find(file), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
  write(file, "not onnx at all");
  e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find(file), std::string::npos) << e;
  // The first stage in the verifier's place: it runs on no 32 x 32 patch
  // into one probability.
  fs::remove(dir_ / file);
  fs::copy_file(kModel, dir_ / file);
  e = error_of([&] { detail::LearnedDetector(dir_ / "m.onnx", 0.3, 0.45); });
  EXPECT_NE(e.find(file), std::string::npos) << e;
}

TEST(LearnedDetector, LooksOnlyForTheMarkerItWasTrainedOn) {
  detail::LearnedDetector d(kModel, 0.3, 0.45);
  const ModelManifest& m = d.manifest();
  EXPECT_NO_THROW(d.reset(m.dictionary, m.marker_id));
  const std::string e = error_of([&] { d.reset(m.dictionary, m.marker_id + 1); });
  EXPECT_NE(e.find("marker-4x4_50-0.onnx"), std::string::npos) << e;
  // It says how to go on: the marker to give the scenarios, or training.
  EXPECT_NE(e.find("--marker " + m.dictionary + ":" + std::to_string(m.marker_id)), std::string::npos) << e;
  EXPECT_THROW(d.reset("6X6_50", m.marker_id), InvalidArgument);
}

// ---- C++ = PyTorch on stored frames ----

/// The largest |got - stored| over a float32 Mat and the raw little-endian
/// float32 file PyTorch wrote; infinity when the file holds fewer values.
double worst_difference(const fs::path& stored, const cv::Mat& got) {
  std::ifstream bin(stored, std::ios::binary);
  std::vector<float> expected(got.total());
  bin.read(reinterpret_cast<char*>(expected.data()), static_cast<std::streamsize>(expected.size() * sizeof(float)));
  if (bin.gcount() != static_cast<std::streamsize>(expected.size() * sizeof(float)))
    return std::numeric_limits<double>::infinity();
  const float* values = got.ptr<float>();
  double worst = 0;
  for (std::size_t i = 0; i < expected.size(); ++i)
    worst = std::max(worst, std::abs(static_cast<double>(values[i]) - expected[i]));
  return worst;
}

TEST(LearnedDetector, OpenCvDnnGivesPyTorchsOutputsOnStoredFrames) {
  std::ifstream in(kVectors / "vectors.json");
  ASSERT_TRUE(in) << kVectors / "vectors.json";
  const nlohmann::json index = nlohmann::json::parse(in);
  ASSERT_GE(index.size(), 2u);
  detail::LearnedDetector d(kModel, 0.3, 0.45);
  for (const auto& v : index) {
    const cv::Mat gray = cv::imread((kVectors / v.at("image").get<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty());
    const cv::Mat& out = d.forward(gray);
    EXPECT_LT(worst_difference(kVectors / v.at("output").get<std::string>(), out), 1e-4) << v.at("image");
  }
}

TEST(LearnedDetector, TheSameFrameGivesTheSameDetectionsOnAnyThreadCount) {
  const cv::Mat gray = cv::imread((kVectors / "with_target.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  const DetectorFrame frame{{}, {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
  const auto run = [&](int opencv_threads) {
    cv::setNumThreads(opencv_threads);
    detail::LearnedDetector d(kModel, 0.05, 0.45);
    d.reset("4X4_50", 0);
    std::vector<MarkerDetection> out;
    d.detect(frame, out);
    return out;
  };
  const int before = cv::getNumThreads();
  const auto one = run(1);
  const auto two = run(2);
  cv::setNumThreads(before);
  ASSERT_FALSE(one.empty()) << "the stored frame holds the target";
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].confidence, two[i].confidence);
    EXPECT_EQ(one[i].corners, two[i].corners);
  }
  // Two detectors in two threads at once.
  std::vector<MarkerDetection> a, b;
  std::thread ta([&] {
    detail::LearnedDetector d(kModel, 0.05, 0.45);
    d.detect(frame, a);
  });
  std::thread tb([&] {
    detail::LearnedDetector d(kModel, 0.05, 0.45);
    d.detect(frame, b);
  });
  ta.join();
  tb.join();
  ASSERT_EQ(a.size(), one.size());
  ASSERT_EQ(b.size(), one.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(a[i].corners, one[i].corners);
    EXPECT_EQ(b[i].corners, one[i].corners);
  }
}

// ---- the second stage: the verifier ----

detail::VerifierManifest verifier_manifest() {
  detail::VerifierManifest v;
  v.patch = 32;
  v.margin_cells = 1;
  v.cells = 6;  // 4X4 and its black border
  v.min_range = 8;
  return v;
}

// A grey ramp I = 2x is linear, so bilinear sampling reproduces it exactly
// (at half-pixel positions 2x is an odd integer: no rounding): a 24-px
// square code through its corners lands on the patch's code square
// [3.5, 27.5], so patch column u samples x = u + 96.5 and reads
// 2u + 193, normalised (2u) / 62. The corners rolled by one (the code a
// quarter turn round) put the ramp along the patch's rows, reversed.
TEST(LearnedVerifier, APatchIsTheFrameWarpedThroughTheCorners) {
  cv::Mat ramp(240, 320, CV_8UC1);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::min(255, 2 * x));
  const detail::VerifierManifest v = verifier_manifest();
  const std::array<Eigen::Vector2d, 4> square{Eigen::Vector2d(100, 100), Eigen::Vector2d(124, 100),
                                              Eigen::Vector2d(124, 124), Eigen::Vector2d(100, 124)};
  cv::Mat patch;
  ASSERT_TRUE(detail::extract_patch(ramp, square, v, patch));
  ASSERT_EQ(patch.type(), CV_32FC1);
  ASSERT_EQ(patch.size(), cv::Size(32, 32));
  double worst = 0;
  for (int r = 0; r < 32; ++r)
    for (int u = 0; u < 32; ++u) worst = std::max(worst, std::abs(patch.at<float>(r, u) - 2.0 * u / 62));
  EXPECT_LT(worst, 1e-6);
  const std::array<Eigen::Vector2d, 4> turned{square[1], square[2], square[3], square[0]};
  ASSERT_TRUE(detail::extract_patch(ramp, turned, v, patch));
  worst = 0;
  for (int r = 0; r < 32; ++r)
    for (int u = 0; u < 32; ++u) worst = std::max(worst, std::abs(patch.at<float>(r, u) - (62.0 - 2.0 * r) / 62));
  EXPECT_LT(worst, 1e-6);
  // A flat patch is not stretched to full contrast: (v - min) / 8 = 0.
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(90));
  ASSERT_TRUE(detail::extract_patch(flat, square, v, patch));
  EXPECT_EQ(cv::countNonZero(patch), 0);
  // Wholly outside the frame, or degenerate: nothing to verify.
  std::array<Eigen::Vector2d, 4> away = square;
  for (auto& c : away) c += Eigen::Vector2d(1000, 0);
  EXPECT_FALSE(detail::extract_patch(ramp, away, v, patch));
  const std::array<Eigen::Vector2d, 4> point{square[0], square[0], square[0], square[0]};
  EXPECT_FALSE(detail::extract_patch(ramp, point, v, patch));
  std::array<Eigen::Vector2d, 4> wild = square;
  wild[2] = Eigen::Vector2d(std::numeric_limits<double>::quiet_NaN(), 0);
  EXPECT_FALSE(detail::extract_patch(ramp, wild, v, patch));
}

// A large marker is shrunk by area averaging before the warp: a 4 x 4
// checkerboard of 50-px cells read through its outer corners gives a
// patch whose cell centres are black and white, not aliased grey.
TEST(LearnedVerifier, ALargeCodeIsAveragedNotAliased) {
  cv::Mat board(400, 400, CV_8UC1, cv::Scalar(255));
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if ((i + j) % 2) board(cv::Rect(50 + 50 * j, 50 + 50 * i, 50, 50)).setTo(0);
  const detail::VerifierManifest v = verifier_manifest();
  const std::array<Eigen::Vector2d, 4> square{Eigen::Vector2d(49.5, 49.5), Eigen::Vector2d(349.5, 49.5),
                                              Eigen::Vector2d(349.5, 349.5), Eigen::Vector2d(49.5, 349.5)};
  cv::Mat patch;
  ASSERT_TRUE(detail::extract_patch(board, square, v, patch));
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      const float centre = patch.at<float>(4 + 4 * i + 2, 4 + 4 * j + 2);  // 4 px a cell, one cell of margin
      if ((i + j) % 2)
        EXPECT_LT(centre, 0.1) << i << "," << j;
      else
        EXPECT_GT(centre, 0.9) << i << "," << j;
    }
  }
}

// C++ (extract_patch + OpenCV DNN) against the patch and probability that
// tools/train_verifier.py stored: the same patch from the same frame and
// corners, and the same probability, within 1e-4.
TEST(LearnedVerifier, OpenCvGivesPyTorchsPatchesAndProbabilities) {
  std::ifstream in(kVectors / "verifier_vectors.json");
  ASSERT_TRUE(in) << kVectors / "verifier_vectors.json";
  const nlohmann::json index = nlohmann::json::parse(in);
  ASSERT_GE(index.size(), 2u);
  detail::LearnedDetector d(kModel, 0.3, 0.45);
  ASSERT_TRUE(d.manifest().verifier.has_value()) << "the shipped model has two stages";
  const detail::VerifierManifest& v = *d.manifest().verifier;
  int accepted = 0;
  for (const auto& e : index) {
    const cv::Mat gray = cv::imread((kVectors / e.at("image").get<std::string>()).string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty());
    std::array<Eigen::Vector2d, 4> corners;
    for (std::size_t k = 0; k < 4; ++k) corners[k] = Eigen::Vector2d(e.at("corners")[k][0], e.at("corners")[k][1]);
    cv::Mat patch;
    ASSERT_TRUE(detail::extract_patch(gray, corners, v, patch));
    EXPECT_LT(worst_difference(kVectors / e.at("patch").get<std::string>(), patch), 1e-4) << e.at("image");
    const double p = d.verify_patch(patch);
    EXPECT_NEAR(p, e.at("probability").get<double>(), 1e-4) << e.at("image");
    accepted += p >= 0.7;
  }
  EXPECT_EQ(accepted, 1) << "the stored target is accepted, the stored distractor is not";
}

// The tracking region reads the marker as the whole frame does: a region
// of sides that are multiples of 32 inside the frame, the same box within a
// pixel and nearly the same confidence; the whole frame again every
// full_frame_period-th frame, after reset(), and when tracking stops.
TEST(LearnedDetector, ATrackingRegionFindsWhatTheWholeFrameFinds) {
  const cv::Mat gray = cv::imread((kVectors / "with_target.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  const DetectorFrame frame{{}, {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
  const cv::Rect whole(0, 0, gray.cols, gray.rows);
  detail::LearnedDetector d(kModel, 0.3, 0.45, true, 3);
  d.reset("4X4_50", 0);
  std::vector<MarkerDetection> full, region;
  d.detect(frame, full);
  ASSERT_EQ(d.last_region(), whole) << "nothing tracked yet";
  ASSERT_FALSE(full.empty()) << "the stored frame holds the target";
  d.track(&full.front());
  d.detect(frame, region);
  const cv::Rect r = d.last_region();
  ASSERT_NE(r, whole) << "the tracked frame searches a region";
  EXPECT_EQ(r.width % 32, 0);
  EXPECT_EQ(r.height % 32, 0);
  EXPECT_EQ(r & whole, r) << "inside the frame";
  EXPECT_LE(2 * r.area(), whole.area());
  ASSERT_FALSE(region.empty());
  for (std::size_t k = 0; k < 4; ++k) EXPECT_LT((region.front().corners[k] - full.front().corners[k]).norm(), 1.0) << k;
  EXPECT_NEAR(region.front().confidence, full.front().confidence, 0.02);
  d.track(&region.front());
  d.detect(frame, region);
  EXPECT_NE(d.last_region(), whole);
  d.track(&region.front());
  d.detect(frame, region);
  EXPECT_EQ(d.last_region(), whole) << "every 3rd frame is whole";
  d.track(&region.front());
  d.detect(frame, region);
  EXPECT_NE(d.last_region(), whole);
  d.track(nullptr);
  d.detect(frame, region);
  EXPECT_EQ(d.last_region(), whole) << "tracking stopped";
  d.track(&region.front());
  d.reset("4X4_50", 0);
  d.detect(frame, region);
  EXPECT_EQ(d.last_region(), whole) << "a new run";
  // Without the option, never a region.
  detail::LearnedDetector plain(kModel, 0.3, 0.45);
  plain.reset("4X4_50", 0);
  plain.detect(frame, region);
  plain.track(&region.front());
  plain.detect(frame, region);
  EXPECT_EQ(plain.last_region(), whole);
}

// The region both detectors share (tracking_region.hpp), by hand: a box of
// 20 x 10 px at (100, 200)-(120, 210) in a 640 x 480 frame.
TEST(TrackingRegion, GrowsSnapsClipsAndFallsBackToTheWholeFrame) {
  const Eigen::Vector2d lo(100, 200), hi(120, 210);
  // ArUco's shape: grown by the longer side (20) but at least 32 px.
  detail::TrackingRegion aruco(true, 10, {1.0, 32.0, 1, 16});
  EXPECT_TRUE(aruco.next(640, 480).empty()) << "nothing tracked";
  aruco.track(&lo, &hi);
  EXPECT_EQ(aruco.next(640, 480), cv::Rect(68, 168, 84, 74));
  // The learned detector's: grown by 1.5 x 20 = 30, at least 48, out to the
  // 32-px grid: x 52 -> 32, 168 -> 192; y 152 -> 128, 258 -> 288.
  detail::TrackingRegion learned(true, 10, {1.5, 48.0, 32, 32});
  learned.track(&lo, &hi);
  EXPECT_EQ(learned.next(640, 480), cv::Rect(32, 128, 160, 160));
  // Clipped at the frame's edge: a box at the top-left corner.
  const Eigen::Vector2d corner_lo(0, 0), corner_hi(10, 10);
  learned.track(&corner_lo, &corner_hi);
  EXPECT_EQ(learned.next(640, 480), cv::Rect(0, 0, 64, 64));
  // Over half the frame saves nothing: a box of 300 x 200 px.
  const Eigen::Vector2d big_lo(100, 100), big_hi(400, 300);
  learned.track(&big_lo, &big_hi);
  EXPECT_TRUE(learned.next(640, 480).empty());
  // Every full_frame_period-th frame is whole, counted since the last whole search.
  detail::TrackingRegion periodic(true, 3, {1.0, 32.0, 1, 16});
  periodic.track(&lo, &hi);
  EXPECT_FALSE(periodic.next(640, 480).empty());  // 1
  EXPECT_FALSE(periodic.next(640, 480).empty());  // 2
  EXPECT_TRUE(periodic.next(640, 480).empty());   // 3: whole
  periodic.searched_whole();
  EXPECT_FALSE(periodic.next(640, 480).empty());
  // A lost target, a non-finite box, reset() and a disabled region: whole.
  periodic.track(nullptr, nullptr);
  EXPECT_TRUE(periodic.next(640, 480).empty());
  const Eigen::Vector2d nan(std::numeric_limits<double>::quiet_NaN(), 0);
  periodic.track(&nan, &hi);
  EXPECT_TRUE(periodic.next(640, 480).empty());
  periodic.track(&lo, &hi);
  periodic.reset();
  EXPECT_TRUE(periodic.next(640, 480).empty());
  detail::TrackingRegion off(false, 3, {1.0, 32.0, 1, 16});
  off.track(&lo, &hi);
  EXPECT_TRUE(off.next(640, 480).empty());
}

}  // namespace
}  // namespace touchdown::scenario
