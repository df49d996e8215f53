#include "touchdown/pose/sim/sequence.hpp"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/se3.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

namespace tp = touchdown::pose;
using touchdown::test::TempDir;

namespace {

using touchdown::pose_test::d435;
using touchdown::pose_test::f450;

tp::CameraModel small_camera() {
  tp::CameraModel c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 300;
  c.cx = 159.5;
  c.cy = 119.5;
  c.distortion = {-0.05, 0.01, 0, 0, 0};
  return c;
}

using touchdown::test::error_of;

void write_image(const std::filesystem::path& p, const cv::Mat& m) { ASSERT_TRUE(cv::imwrite(p.string(), m)); }

}  // namespace

TEST(Sequence, WriteListReadRoundTrip) {
  TempDir dir;
  const tp::CameraModel cam = small_camera();
  const tp::Constellation k = f450();
  tp::TrajectoryOptions topt;
  topt.min_distance = 1.0;
  topt.max_distance = 1.2;
  // The first frames of a smooth trajectory: each frame blurred from the previous one.
  const auto all = tp::make_trajectory(tp::TrajectoryKind::Moving, 60, 3, cam, k, topt);
  const std::vector<tp::TrajectorySample> traj(all.begin(), all.begin() + 5);
  const tp::RenderOptions ropt;
  const auto out = dir / "seq";
  tp::write_sequence(out, cam, k, traj, ropt, 17);

  // Nothing else left next to the sequence (no staging directory).
  EXPECT_EQ(dir.files(), std::vector<std::string>{"seq"});
  const auto frames = tp::list_sequence(out);
  ASSERT_EQ(frames.size(), 5u);
  const tp::SyntheticCamera renderer(cam, k, ropt);
  tp::RenderedFrame expected;
  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].name, std::string("00000") + std::to_string(i));
    ASSERT_TRUE(frames[i].depth.has_value());
    tp::read_frame(frames[i], colour, &depth);
    renderer.render(traj[i].T_camera_body, traj[i > 0 ? i - 1 : 0].T_camera_body, 17, i, expected);
    EXPECT_EQ(colour.width, cam.width);
    EXPECT_EQ(colour.height, cam.height);
    EXPECT_EQ(colour.pixels, expected.colour.pixels) << "frame " << i;
    EXPECT_EQ(depth.pixels, expected.depth.pixels) << "frame " << i;
  }

  const auto gt = tp::read_ground_truth(out / "ground_truth.jsonl");
  ASSERT_EQ(gt.size(), traj.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    EXPECT_EQ(gt[i].frame, frames[i].name);
    EXPECT_EQ(gt[i].t_s, traj[i].t);
    EXPECT_LE((gt[i].T_camera_body.matrix() - traj[i].T_camera_body.matrix()).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(gt[i].leds_visible.size(), k.leds.size());
  }
  const tp::CameraModel cam2 = tp::load_camera(out / "camera.yaml");
  EXPECT_EQ(cam2.fx, cam.fx);
  EXPECT_EQ(cam2.distortion, cam.distortion);
  EXPECT_EQ(tp::load_constellation(out / "constellation.yaml").leds.size(), k.leds.size());

  // Writing again over an existing sequence replaces it: the old frames
  // beyond the new count go too (issue 31: they stayed, mixing the two),
  // a file the writer does not write stays.
  touchdown::test::write_text(out / "notes.txt", "mine");
  tp::write_sequence(out, cam, k, std::span(traj).first(2), ropt, 18);
  EXPECT_EQ(tp::read_ground_truth(out / "ground_truth.jsonl").size(), 2u);
  EXPECT_EQ(tp::list_sequence(out).size(), 2u);
  EXPECT_FALSE(std::filesystem::exists(out / "000002.depth.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "notes.txt"));
  EXPECT_EQ(dir.files(), std::vector<std::string>{"seq"});
}

TEST(Sequence, WriteFailsCleanly) {
  TempDir dir;
  const tp::CameraModel cam = small_camera();
  const tp::Constellation k = f450();
  const std::vector<tp::TrajectorySample> one{{0.0, Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1))}};
  touchdown::test::write_text(dir / "file", "x");
  EXPECT_NE(error_of([&] { tp::write_sequence(dir / "file", cam, k, one, {}, 1); }).find("file"), std::string::npos);
  tp::RenderOptions bad;
  bad.noise_sigma = -1;
  EXPECT_THROW(tp::write_sequence(dir / "seq", cam, k, one, bad, 1), touchdown::InvalidArgument);
  EXPECT_THROW(tp::write_sequence(dir / "seq", cam, k, {}, {}, 1), touchdown::InvalidArgument);
  // The sequence directory is created, never its parent (issue 31).
  EXPECT_NE(error_of([&] {
              tp::write_sequence(dir / "missing" / "seq", cam, k, one, {}, 1);
            }).find("output directory '" + (dir / "missing").string() + "' does not exist"),
            std::string::npos);
  EXPECT_EQ(dir.files(), std::vector<std::string>{"file"});
}

TEST(Sequence, ListsOnlyFrameFilesSorted) {
  TempDir dir;
  const cv::Mat img(4, 6, CV_8UC3, cv::Scalar(1, 2, 3));
  write_image(dir / "000002.png", img);
  write_image(dir / "000001.png", img);
  write_image(dir / "000001.depth.png", cv::Mat(4, 6, CV_16UC1, cv::Scalar(1000)));
  touchdown::test::write_text(dir / "notes.txt", "x");
  touchdown::test::write_text(dir / "000003.txt", "x");  // numbered, not an image
  const auto frames = tp::list_sequence(dir.path());
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].name, "000001");
  EXPECT_TRUE(frames[0].depth.has_value());
  EXPECT_EQ(frames[1].name, "000002");
  EXPECT_FALSE(frames[1].depth.has_value());
  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  tp::read_frame(frames[0], colour, &depth);
  EXPECT_EQ(depth.width, 6);
  EXPECT_EQ(depth.pixels[0], 1000);
  tp::read_frame(frames[1], colour, &depth);
  EXPECT_TRUE(depth.empty());
  EXPECT_EQ(colour.pixels[0], 1);
  EXPECT_EQ(colour.pixels[2], 3);
}

// Issue 58 item 5: a camera's own names (frame_0001.jpg) and JPEG frames
// are a sequence too, in the order of their numbers; two numberings in one
// directory, or two files of one frame, are refused naming them.
TEST(Sequence, AnyNumberedImagesInTheOrderOfTheirNumbers) {
  TempDir dir;
  const cv::Mat img(4, 6, CV_8UC3, cv::Scalar(40, 80, 120));
  write_image(dir / "frame_10.jpg", img);
  write_image(dir / "frame_9.jpg", img);
  write_image(dir / "frame_11.PNG", img);
  write_image(dir / "frame_9.depth.png", cv::Mat(4, 6, CV_16UC1, cv::Scalar(1000)));
  const auto frames = tp::list_sequence(dir.path());
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].name, "frame_9");  // 9 < 10 < 11, not "frame_10" < "frame_9"
  EXPECT_EQ(frames[1].name, "frame_10");
  EXPECT_EQ(frames[2].name, "frame_11");
  EXPECT_TRUE(frames[0].depth.has_value());
  touchdown::BgrImage colour;
  tp::read_frame(frames[1], colour, nullptr);  // a JPEG decodes (lossy: near the colour written)
  EXPECT_EQ(colour.width, 6);
  EXPECT_NEAR(colour.pixels[2], 120, 6);

  write_image(dir / "cover1.jpg", img);
  std::string m = error_of([&] { tp::list_sequence(dir.path()); });
  EXPECT_NE(m.find("frames of two numberings (cover1.jpg and frame_9.jpg)"), std::string::npos) << m;
  std::filesystem::remove(dir / "cover1.jpg");
  write_image(dir / "frame_0010.png", img);
  m = error_of([&] { tp::list_sequence(dir.path()); });
  EXPECT_NE(m.find("two files for frame 10 (frame_0010.png and frame_10.jpg)"), std::string::npos) << m;
}

TEST(Sequence, AcceptsGreyAndBgra) {
  TempDir dir;
  write_image(dir / "000000.png", cv::Mat(3, 5, CV_8UC1, cv::Scalar(77)));
  write_image(dir / "000001.png", cv::Mat(3, 5, CV_8UC4, cv::Scalar(10, 20, 30, 255)));
  const auto frames = tp::list_sequence(dir.path());
  touchdown::BgrImage colour;
  tp::read_frame(frames[0], colour, nullptr);
  EXPECT_EQ(colour.width, 5);
  EXPECT_EQ(colour.height, 3);
  EXPECT_EQ(colour.pixels, std::vector<std::uint8_t>(45, 77));
  tp::read_frame(frames[1], colour, nullptr);
  EXPECT_EQ(colour.pixels[0], 10);
  EXPECT_EQ(colour.pixels[1], 20);
  EXPECT_EQ(colour.pixels[2], 30);
  EXPECT_EQ(colour.pixels.size(), 45u);
}

TEST(SequenceBadInput, EachCaseNamesTheFile) {
  TempDir dir;
  const auto missing = dir / "nope";
  std::string m = error_of([&] { tp::list_sequence(missing); });
  EXPECT_NE(m.find(missing.string()), std::string::npos) << m;
  EXPECT_THROW(tp::list_sequence(missing), touchdown::IoError);

  touchdown::test::write_text(dir / "plain", "x");
  EXPECT_THROW(tp::list_sequence(dir / "plain"), touchdown::IoError);

  std::filesystem::create_directories(dir / "empty");
  m = error_of([&] { tp::list_sequence(dir / "empty"); });
  EXPECT_NE(m.find((dir / "empty").string()), std::string::npos) << m;
  EXPECT_NE(m.find("(it is empty; expected numbered images"), std::string::npos) << m;
  touchdown::test::write_text(dir / "empty/a.bmp", "x");
  touchdown::test::write_text(dir / "empty/frame.png", "x");  // no number
  m = error_of([&] { tp::list_sequence(dir / "empty"); });
  EXPECT_NE(m.find("(found a.bmp, frame.png; expected numbered images"), std::string::npos) << m;
  std::filesystem::remove(dir / "empty/a.bmp");
  std::filesystem::remove(dir / "empty/frame.png");
  EXPECT_THROW(tp::list_sequence(dir / "empty"), touchdown::ParseError);

  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  auto frame_error = [&](const tp::SequenceFrame& f, touchdown::DepthImage* d) {
    return error_of([&] { tp::read_frame(f, colour, d); });
  };

  // Corrupt PNG.
  touchdown::test::write_text(dir / "000000.png", "\x89PNG\r\n\x1a\nnot really");
  tp::SequenceFrame f{"000000", dir / "000000.png", std::nullopt};
  m = frame_error(f, nullptr);
  EXPECT_NE(m.find("000000.png"), std::string::npos) << m;
  EXPECT_THROW(tp::read_frame(f, colour, nullptr), touchdown::ParseError);

  // Missing file.
  f.colour = dir / "000009.png";
  m = frame_error(f, nullptr);
  EXPECT_NE(m.find("000009.png"), std::string::npos) << m;
  EXPECT_THROW(tp::read_frame(f, colour, nullptr), touchdown::IoError);

  // 16-bit colour.
  write_image(dir / "000001.png", cv::Mat(4, 6, CV_16UC3, cv::Scalar(1000, 2000, 3000)));
  f.colour = dir / "000001.png";
  m = frame_error(f, nullptr);
  EXPECT_NE(m.find("000001.png"), std::string::npos) << m;
  EXPECT_NE(m.find("16-bit"), std::string::npos) << m;

  // Depth of another size.
  write_image(dir / "000002.png", cv::Mat(4, 6, CV_8UC3, cv::Scalar(0)));
  write_image(dir / "000002.depth.png", cv::Mat(5, 6, CV_16UC1, cv::Scalar(0)));
  f = {"000002", dir / "000002.png", dir / "000002.depth.png"};
  m = frame_error(f, &depth);
  EXPECT_NE(m.find((dir / "000002.depth.png").string() + ": depth is 6x5 but colour is 6x4"), std::string::npos) << m;
  EXPECT_NO_THROW(tp::read_frame(f, colour, nullptr));  // depth ignored

  // 8-bit depth.
  write_image(dir / "000002.depth.png", cv::Mat(4, 6, CV_8UC1, cv::Scalar(0)));
  m = frame_error(f, &depth);
  EXPECT_NE(m.find("000002.depth.png"), std::string::npos) << m;
  EXPECT_THROW(tp::read_frame(f, colour, &depth), touchdown::ParseError);

  // Ground truth: missing file.
  m = error_of([&] { tp::read_ground_truth(dir / "ground_truth.jsonl"); });
  EXPECT_NE(m.find("ground_truth.jsonl"), std::string::npos) << m;
  EXPECT_THROW(tp::read_ground_truth(dir / "ground_truth.jsonl"), touchdown::IoError);
}

TEST(GroundTruth, ToJsonAndBack) {
  tp::GroundTruthSample s;
  s.frame = "000042";
  s.t_s = 1.0 / 3.0;
  s.T_camera_body = tp::se3_exp((tp::Vector6d() << 0.1, -0.2, 1.3, 0.3, -2.9, 0.7).finished());
  s.leds_visible = {true, false, true};
  s.marker_visible = true;
  const std::string line = tp::ground_truth_to_json(s);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  EXPECT_EQ(line.rfind("{\"frame\":\"000042\",\"t_s\":", 0), 0u) << line;
  const auto back = tp::parse_ground_truth(line + "\n\n" + line, "gt.jsonl");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].frame, s.frame);
  EXPECT_EQ(back[0].t_s, s.t_s);
  EXPECT_LE((back[0].T_camera_body.matrix() - s.T_camera_body.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(back[0].leds_visible, s.leds_visible);
  EXPECT_TRUE(back[0].marker_visible);
}

TEST(GroundTruth, OptionalAndUnknownKeys) {
  const auto gt = tp::parse_ground_truth(
      R"({ "q" : [1, 0, 0, 0], "t": [1e-3, -2.5E+1, 0], "t_s": 0, "frame": "a\"b\u00e9\ud83d\ude00", )"
      R"("extra": {"nested": [1, null, "x", {"y": false}]}, "leds_visible": []})",
      "gt");
  ASSERT_EQ(gt.size(), 1u);
  EXPECT_EQ(gt[0].frame, "a\"b\xc3\xa9\xf0\x9f\x98\x80");
  EXPECT_EQ(gt[0].T_camera_body.translation().y(), -25.0);
  EXPECT_TRUE(gt[0].leds_visible.empty());
  EXPECT_FALSE(gt[0].marker_visible);
}

TEST(GroundTruth, MalformedLinesNameFileAndLine) {
  const std::string good = R"({"frame":"000000","t_s":0,"t":[0,0,1],"q":[1,0,0,0]})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json", "expected a JSON object"},
      {R"({"frame":"000000","t_s":0,"t":[0,0,1]})", "missing key \"q\""},
      {R"({"frame":"000000","t_s":0,"t":[0,0],"q":[1,0,0,0]})", "t: expected 3 numbers"},
      {R"({"frame":"000000","t_s":0,"t":[0,0,1],"q":[2,0,0,0]})", "not a unit quaternion"},
      {R"({"frame":"000000","frame":"1","t_s":0,"t":[0,0,1],"q":[1,0,0,0]})", "duplicate key"},
      {R"({"frame":"000000","t_s":0,"t":[0,0,1],"q":[1,0,0,0]} x)", "unexpected text"},
      {R"({"frame":"000000","t_s":1e999,"t":[0,0,1],"q":[1,0,0,0]})", "t_s: number out of range"},
      {R"({"frame":"000000","t_s":01,"t":[0,0,1],"q":[1,0,0,0]})", "expected ',' or '}'"},
      {R"({"frame":"000000","t_s":0,"t":[0,0,1],"q":[1,0,0,0],"leds_visible":[1]})", "leds_visible"},
      {R"({"frame":7,"t_s":0,"t":[0,0,1],"q":[1,0,0,0]})", "frame: expected a string"},
      {R"({"frame":"\ud800","t_s":0,"t":[0,0,1],"q":[1,0,0,0]})", "surrogate"},
      {R"({"frame":"000000","t_s":0,"t":[0,0,1],"q":[1,0,0,0],"x":[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]]})",
       "nested too deeply"},
      {R"({"frame":"000)", "unterminated string"},
  };
  for (const auto& [line, what] : cases) {
    // Not captured itself: a lambda capturing a structured binding is C++20
    // that clang 14 (scripts/tidy.sh) cannot parse.
    const std::string text = good + "\n\n" + line + "\n";
    const std::string m = error_of([&] { tp::parse_ground_truth(text, "seq/gt.jsonl"); });
    EXPECT_NE(m.find("seq/gt.jsonl:3: "), std::string::npos) << line << " -> " << m;
    EXPECT_NE(m.find(what), std::string::npos) << line << " -> " << m;
  }
}

// The attitude file (issue 33, item 3): the independent renderer's lines
// read back as unit vectors; every malformed line is named with its line.
TEST(Attitude, ReadsTheIndependentRenderersLines) {
  const std::string text =
      R"({"frame": "000000", "t_s": 0.0, "g_camera": [-0.0067389199406155805, 0.9252667810796028, -0.3792571301750625], "g_body": [0.3757554322684758, -0.07720579602642995, -0.9234972226166446], "sigma_deg": 1.0})"
      "\n\n"
      R"({"frame": "000001", "t_s": 0.033333, "g_camera": [0, 1, 0], "g_body": [0, 0, -1], "sigma_deg": 0.5, "extra": [1, {"a": 2}]})"
      "\n";
  const auto s = tp::parse_attitude(text, "att.jsonl");
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].frame, "000000");
  EXPECT_EQ(s[0].line, 1u);
  EXPECT_EQ(s[1].line, 3u);
  EXPECT_NEAR(s[0].g_camera.norm(), 1.0, 1e-15);
  EXPECT_NEAR(s[0].g_body.z(), -0.9234972226166446, 1e-9);
  EXPECT_DOUBLE_EQ(s[1].sigma_deg, 0.5);
  EXPECT_DOUBLE_EQ(s[1].t_s, 0.033333);
}

TEST(Attitude, MalformedLinesNameFileAndLine) {
  const std::string good = R"({"frame":"000000","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,-1],"sigma_deg":1})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"not json", "expected a JSON object"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"sigma_deg":1})", "missing key \"g_body\""},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,-1]})", "missing key \"sigma_deg\""},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,0.9,0],"g_body":[0,0,-1],"sigma_deg":1})",
       "g_camera: not a unit vector (norm 0.9)"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,0],"sigma_deg":1})",
       "g_body: not a unit vector (norm 0)"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,NaN],"sigma_deg":1})", "g_body"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,1e999],"sigma_deg":1})", "out of range"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,-1],"sigma_deg":0})",
       "sigma_deg: must be in (0, 90] (got 0)"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,-1],"sigma_deg":-1})", "sigma_deg: must be in"},
      {R"({"frame":"000001","t_s":0,"g_camera":[0,1],"g_body":[0,0,-1],"sigma_deg":1})",
       "g_camera: expected 3 numbers"},
      {R"({"frame":"000000","t_s":0,"g_camera":[0,1,0],"g_body":[0,0,-1],"sigma_deg":1})",
       "frame \"000000\" again (first on line 1)"},
  };
  for (const auto& [line, what] : cases) {
    const std::string text = good + "\n\n" + line + "\n";
    const std::string m = error_of([&] { tp::parse_attitude(text, "seq/att.jsonl"); });
    EXPECT_NE(m.find("seq/att.jsonl:3: "), std::string::npos) << line << " -> " << m;
    EXPECT_NE(m.find(what), std::string::npos) << line << " -> " << m;
  }
}
