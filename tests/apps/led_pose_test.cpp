// led_pose end to end: render → track against the rendered ground truth
// (LED with and without depth, ArUco), determinism, the benchmark table,
// OpenCV and ROS camera files, and one test per bad-input case (exit 2, one
// line on stderr, nothing on stdout).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/pose/camera.hpp"

namespace td = touchdown;
namespace fs = std::filesystem;
using td::test::AppRun;
using td::test::TempDir;

namespace {

AppRun run(const std::string& args, const TempDir& dir) { return td::test::run_app(LED_POSE_EXE, args, dir); }

// Renders the 12-frame sequence of the tests into dir/name.
fs::path render(const TempDir& dir, const std::string& name = "seq", const std::string& extra = "") {
  const fs::path out = dir / name;
  const AppRun r = run("render " + out.string() + " --frames 12 --seed 3 " + extra, dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  return out;
}

// The same sequence, rendered once per ctest run by the fixture test
// led_pose_render_fixture (tests/apps/CMakeLists.txt) and copied here, so a
// test may damage its copy. Rendered afresh when the fixture is missing or
// older than the app (the test binary run by hand).
fs::path rendered_sequence(const TempDir& dir) {
  const fs::path fixture = LED_POSE_FIXTURE;
  std::error_code ec;
  const auto fixture_time = fs::last_write_time(fixture / "ground_truth.jsonl", ec);
  if (ec || fixture_time < fs::last_write_time(LED_POSE_EXE)) return render(dir);
  const fs::path out = dir / "seq";
  fs::copy(fixture, out, fs::copy_options::recursive);
  return out;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(line);
  }
  return out;
}

struct Truth {
  Eigen::Vector3d t;
  Eigen::Quaterniond q;
};

std::map<std::string, Truth> read_truth(const fs::path& seq) {
  std::map<std::string, Truth> out;
  for (const auto& line : lines_of(td::test::read_text(seq / "ground_truth.jsonl"))) {
    const auto j = nlohmann::json::parse(line);
    Truth tr;
    tr.t = {j["t"][0].get<double>(), j["t"][1].get<double>(), j["t"][2].get<double>()};
    tr.q = Eigen::Quaterniond(j["q"][0].get<double>(), j["q"][1].get<double>(), j["q"][2].get<double>(),
                              j["q"][3].get<double>());
    out[j["frame"].get<std::string>()] = tr;
  }
  return out;
}

// Checks the JSON Lines of a tracking run against the ground truth; returns the frames with a pose.
int check_jsonl(const std::string& out, const fs::path& seq, bool compare_truth) {
  const auto truth = read_truth(seq);
  EXPECT_EQ(truth.size(), 12u);
  const auto lines = lines_of(out);
  EXPECT_EQ(lines.size(), 12u) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 12);
  int ok = 0;
  for (const auto& line : lines) {
    const auto j = nlohmann::json::parse(line);
    if (!j.is_object()) {
      ADD_FAILURE() << "not an object: " << line;
      continue;
    }
    for (const char* key : {"frame", "ok", "ms"}) EXPECT_TRUE(j.contains(key)) << key << " in " << line;
    EXPECT_GE(j["ms"].get<double>(), 0.0);
    if (!j["ok"].get<bool>()) {
      EXPECT_TRUE(j.contains("reason")) << line;
      EXPECT_TRUE(j["reason"].is_string()) << line;
      continue;
    }
    ++ok;
    for (const char* key : {"t", "q", "reproj_px", "leds"}) EXPECT_TRUE(j.contains(key)) << key << " in " << line;
    if (j["t"].size() != 3u || j["q"].size() != 4u) {
      ADD_FAILURE() << "t/q sizes in " << line;
      continue;
    }
    EXPECT_GE(j["reproj_px"].get<double>(), 0.0);
    EXPECT_GE(j["leds"].get<int>(), 4);
    if (!compare_truth) continue;
    const auto it = truth.find(j["frame"].get<std::string>());
    if (it == truth.end()) {
      ADD_FAILURE() << "no ground truth for " << line;
      continue;
    }
    const Eigen::Vector3d t(j["t"][0].get<double>(), j["t"][1].get<double>(), j["t"][2].get<double>());
    const Eigen::Quaterniond q(j["q"][0].get<double>(), j["q"][1].get<double>(), j["q"][2].get<double>(),
                               j["q"][3].get<double>());  // [w, x, y, z]
    EXPECT_NEAR(q.norm(), 1.0, 1e-5) << line;
    EXPECT_LT((t - it->second.t).norm(), 0.02) << line;
    EXPECT_LT(q.normalized().angularDistance(it->second.q.normalized()), 0.02) << line;
  }
  return ok;
}

// The output of a --jsonl run with the timing field removed.
std::vector<nlohmann::json> without_ms(const std::string& out) {
  std::vector<nlohmann::json> v;
  for (const auto& line : lines_of(out)) {
    auto j = nlohmann::json::parse(line);
    EXPECT_TRUE(j.contains("ms"));
    j.erase("ms");
    v.push_back(std::move(j));
  }
  return v;
}

// A bad-input run: exit 2, exactly one line on stderr containing `needle`, nothing on stdout.
void expect_bad_input(const AppRun& r, const std::string& needle) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(r.out.empty()) << "stdout: " << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << "stderr lacks '" << needle << "': " << r.err;
}

std::string file_bytes(const fs::path& p) { return td::test::read_text(p); }

// Command lines, each of which must be refused naming `needle`.
struct RefusedArgs {
  std::string args, needle;
};
void expect_each_refused(const std::vector<RefusedArgs>& cases, const TempDir& dir) {
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    expect_bad_input(run(c.args, dir), c.needle);
  }
}

}  // namespace

// ---- tracking a rendered sequence -------------------------------------------------

TEST(LedPoseApp, RenderWritesASequence) {
  TempDir dir;
  const auto seq = render(dir);
  for (const char* f : {"camera.yaml", "constellation.yaml", "sequence.yaml", "ground_truth.jsonl", "000000.png",
                        "000011.png", "000000.depth.png", "000011.depth.png"}) {
    EXPECT_TRUE(fs::exists(seq / f)) << f;
  }
  EXPECT_FALSE(fs::exists(seq / "000012.png"));
}

TEST(LedPoseApp, LedJsonlMatchesGroundTruth) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string() + " --jsonl", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(check_jsonl(r.out, seq, true), 11);
}

TEST(LedPoseApp, LedWithoutDepthMatchesGroundTruth) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string() + " --jsonl --no-depth", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(check_jsonl(r.out, seq, true), 11);
}

// An attitude file made from the ground truth (gravity 20° off the camera's
// y axis, as a camera tilted up sees it): the poses still match the truth,
// and every ok line carries the full covariance, symmetric and positive.
std::string attitude_from_truth(const fs::path& seq, const std::string& sigma_deg = "1.0") {
  const Eigen::Vector3d g_camera = Eigen::Vector3d(0, std::cos(0.349), -std::sin(0.349));
  std::ostringstream out;
  out << std::setprecision(17);
  for (const auto& [frame, truth] : read_truth(seq)) {
    const Eigen::Vector3d g_body = truth.q.normalized().toRotationMatrix().transpose() * g_camera;
    out << "{\"frame\": \"" << frame << "\", \"t_s\": 0, \"g_camera\": [" << g_camera.x() << ", " << g_camera.y()
        << ", " << g_camera.z() << "], \"g_body\": [" << g_body.x() << ", " << g_body.y() << ", " << g_body.z()
        << "], \"sigma_deg\": " << sigma_deg << "}\n";
  }
  return out.str();
}

TEST(LedPoseApp, AttitudePriorKeepsThePosesAndCovarianceIsPrinted) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  td::test::write_text(dir / "att.jsonl", attitude_from_truth(seq));
  const AppRun r = run(seq.string() + " --jsonl --attitude " + (dir / "att.jsonl").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(check_jsonl(r.out, seq, true), 11);
  for (const auto& line : lines_of(r.out)) {
    const auto j = nlohmann::json::parse(line);
    if (!j["ok"].get<bool>()) continue;
    ASSERT_TRUE(j.contains("covariance")) << line;
    ASSERT_EQ(j["covariance"].size(), 36u) << line;
    Eigen::Matrix<double, 6, 6> c;
    for (int i = 0; i < 36; ++i) c(i / 6, i % 6) = j["covariance"][static_cast<std::size_t>(i)].get<double>();
    EXPECT_LT((c - c.transpose()).norm(), 1e-6 * c.norm()) << line;
    EXPECT_GT(c.diagonal().minCoeff(), 0.0) << line;
    // The sigma pair is the root of the traces (rotation: the lower block).
    EXPECT_NEAR(j["sigma"][1].get<double>(), std::sqrt(c.bottomRightCorner<3, 3>().trace()), 2e-6) << line;
  }
}

// --max-sigma: a tight limit holds frames back as `too uncertain` with the
// figures that failed; the option before the directory leaves it to the
// positional; one value, zero, NaN or --method aruco are refused.
TEST(LedPoseApp, MaxSigmaHoldsBackFramesAndIsChecked) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun loose = run(seq.string() + " --jsonl", dir);
  ASSERT_EQ(loose.code, 0) << loose.err;
  const AppRun tight = run("--max-sigma 0.0001,0.0001 " + seq.string() + " --jsonl", dir);
  ASSERT_EQ(tight.code, 0) << tight.err;
  int ok_loose = 0, ok_tight = 0, held = 0;
  for (const auto& line : lines_of(loose.out)) ok_loose += nlohmann::json::parse(line)["ok"].get<bool>();
  for (const auto& line : lines_of(tight.out)) {
    const auto j = nlohmann::json::parse(line);
    if (j["ok"].get<bool>()) {
      ++ok_tight;
      continue;
    }
    if (j.value("reason", "") != "too uncertain") continue;
    ++held;
    EXPECT_TRUE(j["sigma"][0].get<double>() > 0.0001 || j["sigma"][1].get<double>() > 0.0001) << line;
  }
  EXPECT_GE(ok_loose, 11);
  EXPECT_EQ(ok_tight, 0);
  EXPECT_GE(held, ok_loose - 1);  // the first frame of a track may be unconfirmed either way
  expect_each_refused(
      {
          {seq.string() + " --max-sigma 0.05", "--max-sigma"},
          {seq.string() + " --max-sigma 0,0.05", "--max-sigma"},
          {seq.string() + " --max-sigma nan,0.05", "--max-sigma"},
          {seq.string() + " --method aruco --max-sigma 0.05,0.05", "--max-sigma: only the LED method"},
      },
      dir);
}

TEST(LedPoseApp, ArucoRuns) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string() + " --jsonl --method aruco", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  check_jsonl(r.out, seq, false);
}

TEST(LedPoseApp, HumanSummaryReportsGroundTruthErrors) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("pose found"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ground truth"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("position error"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("orientation"), std::string::npos) << r.out;
}

// Wrong poses reported ok are not hidden behind the means (issue 31 item 8):
// the ground truth of two frames the tracker gets right is moved on purpose
// (0.5 m along x; 0.3 rad about z), so exactly those two are wrong but ok and
// the maxima are the perturbations.
TEST(LedPoseApp, SummaryReportsMaxErrorsAndWrongButOkFrames) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun jsonl = run(seq.string() + " --jsonl", dir);
  ASSERT_EQ(jsonl.code, 0) << jsonl.err;
  std::vector<std::string> ok_frames;
  for (const auto& line : lines_of(jsonl.out)) {
    const auto j = nlohmann::json::parse(line);
    if (j["ok"].get<bool>()) ok_frames.push_back(j["frame"].get<std::string>());
  }
  ASSERT_GE(ok_frames.size(), 3u);
  const std::string moved = ok_frames[1], turned = ok_frames[2];
  std::string truth;
  for (const auto& line : lines_of(td::test::read_text(seq / "ground_truth.jsonl"))) {
    auto j = nlohmann::json::parse(line);
    if (j["frame"] == moved) j["t"][0] = j["t"][0].get<double>() + 0.5;
    if (j["frame"] == turned) {
      const Eigen::Quaterniond q(j["q"][0].get<double>(), j["q"][1].get<double>(), j["q"][2].get<double>(),
                                 j["q"][3].get<double>());
      const Eigen::Quaterniond r = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * q).normalized();
      j["q"] = {r.w(), r.x(), r.y(), r.z()};
    }
    truth += j.dump() + "\n";
  }
  td::test::write_text(seq / "ground_truth.jsonl", truth);
  const AppRun r = run(seq.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto field = [&](const std::string& after, std::size_t from = 0) {
    const auto at = r.out.find(after, from);
    EXPECT_NE(at, std::string::npos) << "no '" << after << "' in " << r.out;
    return at == std::string::npos ? -1.0 : std::stod(r.out.substr(at + after.size()));
  };
  EXPECT_NEAR(field("max  position error "), 0.5, 0.01) << r.out;
  EXPECT_NEAR(field("m, orientation ", r.out.find("max  position")), 0.3, 0.01) << r.out;
  EXPECT_NE(r.out.find("wrong but ok    2 frames (> 0.1 m or 0.1 rad): " + moved + ", " + turned + "\n"),
            std::string::npos)
      << r.out;
}

// The marker a sequence was rendered with is recorded in sequence.yaml and
// used by --method aruco (issue 31 item 12): with a 0.2 m marker the
// defaults (0.1 m) put every pose at half the distance.
TEST(LedPoseApp, ArucoUsesTheMarkerTheSequenceRecords) {
  TempDir dir;
  const auto seq = render(dir, "big", "--aruco-size 0.2 --aruco-id 7 --aruco-dict 5X5_100");
  const std::string info = td::test::read_text(seq / "sequence.yaml");
  EXPECT_NE(info.find("seed: 3"), std::string::npos) << info;
  EXPECT_NE(info.find("aruco: {dictionary: 5X5_100, id: 7, size: 0.2}"), std::string::npos) << info;
  const auto truth = read_truth(seq);
  for (const std::string extra : {"", " --aruco-size 0.2 --aruco-id 7 --aruco-dict dict_5x5_100"}) {
    SCOPED_TRACE(extra);
    const AppRun r = run(seq.string() + " --jsonl --method aruco" + extra, dir);
    ASSERT_EQ(r.code, 0) << r.err;
    // A wrong marker size scales every distance by the size ratio (0.5 with
    // the defaults); the baseline's own noise at 2-3 m is a few percent.
    std::vector<double> ratios;
    for (const auto& line : lines_of(r.out)) {
      const auto j = nlohmann::json::parse(line);
      if (!j["ok"].get<bool>()) continue;
      const Eigen::Vector3d t(j["t"][0].get<double>(), j["t"][1].get<double>(), j["t"][2].get<double>());
      ratios.push_back(t.norm() / truth.at(j["frame"].get<std::string>()).t.norm());
    }
    ASSERT_GE(ratios.size(), 6u) << r.out;
    std::sort(ratios.begin(), ratios.end());
    EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.05) << r.out;
  }
  // An explicit value that contradicts the record is refused, naming the
  // option, the file and both values.
  expect_each_refused({{seq.string() + " --method aruco --aruco-size 0.1", "--aruco-size 0.1 contradicts"},
                       {seq.string() + " --method aruco --aruco-id 3", "aruco.id 7"},
                       {seq.string() + " --method aruco --aruco-dict 4X4_50", "aruco.dictionary 5X5_100"}},
                      dir);
  const AppRun r = run(seq.string() + " --method aruco --aruco-size 0.1", dir);
  EXPECT_NE(r.err.find("sequence.yaml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("aruco.size 0.2"), std::string::npos) << r.err;
}

// A sequence without sequence.yaml (rendered before it existed, or recorded)
// takes the options' defaults; a malformed one is refused naming its line.
TEST(LedPoseApp, SequenceWithoutInfoFileUsesTheDefaults) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  fs::remove(seq / "sequence.yaml");
  const AppRun r = run(seq.string() + " --jsonl --method aruco --aruco-size 0.1", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  check_jsonl(r.out, seq, false);
  td::test::write_text(seq / "sequence.yaml", "seed: 3\naruco: {dictionary: 4X4_50, id: 3, size: -1}\n");
  expect_bad_input(run(seq.string() + " --method aruco", dir), "sequence.yaml:2: aruco");
  td::test::write_text(seq / "sequence.yaml", "seed: 3\nseed: 4\n");
  expect_bad_input(run(seq.string() + " --method aruco", dir), "sequence.yaml:2: seed: duplicate key");
}

// On a terminal, render shows a progress bar on stderr (issue 31 item 11);
// script(1) gives the app a terminal. Without one (every other test) stderr
// stays as it was.
TEST(LedPoseApp, RenderShowsProgressOnATerminal) {
  if (!fs::exists("/usr/bin/script")) GTEST_SKIP() << "no script(1) to give the app a terminal";
  TempDir dir;
  const fs::path out = dir / "tty";
  const AppRun r = td::test::run_app("/usr/bin/script",
                                     "-qec \"env -u TOUCHDOWN_PROGRESS " + std::string(LED_POSE_EXE) + " render " +
                                         out.string() + " --frames 12\" /dev/null",
                                     dir);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("] 12/12"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("led_pose: wrote 12 frames"), std::string::npos) << r.out;
  const AppRun plain = run("render " + (dir / "plain").string() + " --frames 2", dir);
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(plain.err.find("2/2"), std::string::npos) << plain.err;
}

TEST(LedPoseApp, RenderAndTrackingAreDeterministic) {
  TempDir dir;
  // The fixture was rendered by another process with the same arguments.
  const auto a = rendered_sequence(dir);
  const auto b = render(dir, "b");
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const auto name = e.path().filename();
    ASSERT_TRUE(fs::exists(b / name)) << name;
    if (name.extension() == ".png") ++pngs;
    EXPECT_TRUE(file_bytes(e.path()) == file_bytes(b / name)) << name << " differs";
  }
  EXPECT_EQ(pngs, 24);
  const AppRun r1 = run(a.string() + " --jsonl", dir);
  const AppRun r2 = run(a.string() + " --jsonl", dir);
  ASSERT_EQ(r1.code, 0) << r1.err;
  ASSERT_EQ(r2.code, 0) << r2.err;
  const auto j1 = without_ms(r1.out), j2 = without_ms(r2.out);
  ASSERT_EQ(j1.size(), 12u);
  EXPECT_EQ(j1, j2);
}

TEST(LedPoseApp, BenchmarkJson) {
  TempDir dir;
  const AppRun r = run("benchmark --frames 20 --json", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  td::test::expect_one_json_line(r.out);
  const auto j = nlohmann::json::parse(r.out);  // exactly one JSON object
  ASSERT_TRUE(j.is_object());
  ASSERT_EQ(j["rows"].size(), 12u);  // 3 scenarios x 2 sequences x 2 methods
  EXPECT_EQ(j["status"], "ok");
  std::set<std::string> seen;
  for (const auto& row : j["rows"]) {
    const auto scenario = row["scenario"].get<std::string>(), profile = row["profile"].get<std::string>();
    const auto method = row["method"].get<std::string>(), sequence = row["sequence"].get<std::string>();
    seen.insert(scenario + "/" + profile + "/" + method + "/" + sequence);
    EXPECT_EQ(row["frames"].get<int>(), 20);
    if (method == "led") {
      // Far frames of the paper's small board may be "too uncertain"; a
      // pose the tracker reports is never wrong.
      EXPECT_GE(row["success_rate"].get<double>(), scenario == "f450 below" ? 0.95
                                                   : profile == "clean"     ? 0.7
                                                                            : 0.4)
          << row.dump();
      EXPECT_EQ(row["wrong_ok"].get<int>(), 0) << row.dump();
      EXPECT_LE(row["position_mean_m"].get<double>(), 0.02) << row.dump();
    }
  }
  EXPECT_EQ(seen.size(), 12u);
  EXPECT_TRUE(seen.count("paper chase/harsh/led/moving") && seen.count("paper chase/clean/led/moving") &&
              seen.count("f450 below/clean/aruco/static"))
      << seen.size();
}

// ---- bad input --------------------------------------------------------------------------

TEST(LedPoseAppBadInput, MissingSequenceDirectory) {
  TempDir dir;
  expect_bad_input(run((dir / "nope").string() + " --jsonl", dir), "nope");
}

TEST(LedPoseAppBadInput, EmptyDirectory) {
  TempDir dir;
  fs::create_directories(dir / "empty");
  expect_bad_input(run((dir / "empty").string() + " --jsonl", dir), "no frames");
}

TEST(LedPoseAppBadInput, CorruptFrameLeavesNoPartialOutput) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  static const char kGarbage[] = "\x13\x37 this is not a PNG \x00\xff garbage";
  td::test::write_text(seq / "000001.png", std::string(kGarbage, sizeof kGarbage - 1));
  expect_bad_input(run(seq.string() + " --jsonl", dir), "000001.png");
  // Frame 000000 was fine, but its line must not have been printed either.
  expect_bad_input(run(seq.string(), dir), "000001.png");
}

// A bad attitude file: exit 2 naming the file and line (or the frame it
// lacks), nothing on stdout, before any frame is tracked.
TEST(LedPoseAppBadInput, BadAttitudeFilesNameTheLine) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string good = attitude_from_truth(seq);
  const auto lines = lines_of(good);
  ASSERT_EQ(lines.size(), 12u);
  auto with_line = [&](std::size_t index, const std::string& replacement) {
    std::string text;
    for (std::size_t i = 0; i < lines.size(); ++i) text += (i == index ? replacement : lines[i]) + "\n";
    return text;
  };
  const std::string frame2 = R"({"frame": "000002", "t_s": 0, )";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with_line(5, ""), "no line for frame \"000005\" of the sequence"},
      {with_line(2, frame2 + R"("g_camera": [0, 0.5, 0], "g_body": [0, 0, -1], "sigma_deg": 1})"),
       "att.jsonl:3: g_camera: not a unit vector (norm 0.5)"},
      {with_line(2, frame2 + R"("g_camera": [0, 1, 0], "g_body": [0, 0, NaN], "sigma_deg": 1})"), "att.jsonl:3: "},
      {with_line(2, frame2 + R"("g_camera": [0, 1, 0], "g_body": [0, 0, -1], "sigma_deg": 0})"),
       "att.jsonl:3: sigma_deg: must be in (0, 90]"},
      {with_line(2, frame2 + R"("g_camera": [0, 1, 0], "g_body": [0, 0, -1], "sigma_deg": -2})"),
       "att.jsonl:3: sigma_deg: must be in (0, 90]"},
      {with_line(2, frame2 + R"("g_camera": [0, 1, 0], "sigma_deg": 1})"), "att.jsonl:3: missing key \"g_body\""},
  };
  for (const auto& [text, needle] : cases) {
    SCOPED_TRACE(needle);
    td::test::write_text(dir / "att.jsonl", text);
    expect_bad_input(run(seq.string() + " --jsonl --attitude " + (dir / "att.jsonl").string(), dir), needle);
  }
  expect_bad_input(run(seq.string() + " --attitude " + (dir / "none.jsonl").string(), dir), "none.jsonl");
  td::test::write_text(dir / "att.jsonl", good);
  expect_bad_input(run(seq.string() + " --method aruco --attitude " + (dir / "att.jsonl").string(), dir),
                   "--attitude: only the LED method");
}

TEST(LedPoseAppBadInput, DepthOfAnotherSize) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  ASSERT_TRUE(cv::imwrite((seq / "000002.depth.png").string(), cv::Mat(100, 120, CV_16UC1, cv::Scalar(1000))));
  expect_bad_input(run(seq.string() + " --jsonl", dir), "000002.depth.png");
  // Without depth the sequence is fine.
  const AppRun r = run(seq.string() + " --jsonl --no-depth", dir);
  EXPECT_EQ(r.code, 0) << r.err;
}

TEST(LedPoseAppBadInput, CameraWithNegativeFocalLength) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string yaml = td::test::replace_key_line(td::test::read_text(seq / "camera.yaml"), "fx", "fx: -1");
  ASSERT_NE(yaml.find("fx: -1"), std::string::npos);
  td::test::write_text(dir / "cam.yaml", yaml);
  const AppRun r = run(seq.string() + " --jsonl --camera " + (dir / "cam.yaml").string(), dir);
  expect_bad_input(r, "cam.yaml");
  EXPECT_NE(r.err.find("fx"), std::string::npos) << r.err;
}

namespace {

std::string constellation_yaml(const std::vector<std::string>& xyz) {
  std::string y = "leds:\n";
  const char* colours[] = {"red", "red", "green", "green", "blue", "white"};
  for (std::size_t i = 0; i < xyz.size(); ++i) y += "  - {xyz: [" + xyz[i] + "], color: " + colours[i % 6] + "}\n";
  return y;
}

AppRun run_with_constellation(const TempDir& dir, const fs::path& seq, const std::string& yaml) {
  td::test::write_text(dir / "k.yaml", yaml);
  return run(seq.string() + " --jsonl --constellation " + (dir / "k.yaml").string(), dir);
}

}  // namespace

TEST(LedPoseAppBadInput, ConstellationWithDuplicateLeds) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run_with_constellation(
      dir, seq, constellation_yaml({"0.1, 0.1, 0", "0.1, -0.1, 0", "-0.1, -0.1, 0", "0.1, -0.1, 0", "0, 0, -0.1"}));
  expect_bad_input(r, "k.yaml");
  EXPECT_NE(r.err.find("leds[3]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("duplicate"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("leds[1]"), std::string::npos) << r.err;
}

TEST(LedPoseAppBadInput, CollinearConstellation) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r =
      run_with_constellation(dir, seq, constellation_yaml({"0, 0, 0", "0.1, 0, 0", "0.2, 0, 0", "0.3, 0, 0"}));
  expect_bad_input(r, "k.yaml");
  EXPECT_NE(r.err.find("collinear"), std::string::npos) << r.err;
}

TEST(LedPoseAppBadInput, ConstellationWithThreeLeds) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run_with_constellation(dir, seq, constellation_yaml({"0, 0, 0", "0.1, 0, 0", "0, 0.1, 0"}));
  expect_bad_input(r, "k.yaml");
  EXPECT_NE(r.err.find("leds"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("at least 4"), std::string::npos) << r.err;
}

// Issue 9: the emission-cone keys, through the app: exit 2, one line
// naming the file, line and key.
TEST(LedPoseAppBadInput, ConstellationConeKeys) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string four = "  - {xyz: [0.1, -0.1, 0]}\n  - {xyz: [-0.1, -0.1, 0]}\n  - {xyz: [0, 0, -0.1]}\n";
  const struct {
    std::string led0, needle;
  } cases[] = {
      {"  - {xyz: [0.1, 0.1, 0], normal: [0, 0, 0]}\n", "k.yaml:2: leds[0].normal: zero length"},
      {"  - {xyz: [0.1, 0.1, 0], normal: [0, 0, -1], half_angle_deg: 180}\n",
       "k.yaml:2: leds[0].half_angle_deg: must be in (0, 180)"},
      {"  - {xyz: [0.1, 0.1, 0], normal: [0, 0, -1], half_angle_deg: 0}\n",
       "k.yaml:2: leds[0].half_angle_deg: must be in (0, 180)"},
      {"  - {xyz: [0.1, 0.1, 0], normal: [0, 0, -1], cone: 60}\n", "k.yaml:2: leds[0].cone: unknown key"},
  };
  for (const auto& c : cases) {
    const AppRun r = run_with_constellation(dir, seq, "leds:\n" + c.led0 + four);
    expect_bad_input(r, c.needle);
  }
}

TEST(LedPoseAppBadInput, RenderErrorsNameTheFlagNotTheField) {
  // Issue 11: `--noise -1` was reported as `noise_sigma: ...`.
  TempDir dir;
  const AppRun noise = run("render " + (dir / "a").string() + " --frames 2 --noise -1", dir);
  expect_bad_input(noise, "--noise: -1 is outside [0, 100]");
  EXPECT_EQ(noise.err.find("noise_sigma"), std::string::npos) << noise.err;
  const AppRun dropout = run("render " + (dir / "b").string() + " --frames 2 --dropout 2", dir);
  expect_bad_input(dropout, "--dropout: 2 is outside [0, 1]");
  const AppRun distance = run("render " + (dir / "c").string() + " --frames 2 --min-distance 5 --max-distance 1", dir);
  expect_bad_input(distance, "--min-distance, --max-distance");
  EXPECT_EQ(distance.err.find("make_trajectory"), std::string::npos) << distance.err;
}

// Issue 31 item 3: `render /nonexist/x` exited 0 having created the whole
// tree, where every other app refuses a missing output directory.
TEST(LedPoseAppBadInput, RenderRefusesAMissingParentDirectory) {
  TempDir dir;
  const fs::path out = dir / "nonexist" / "x";
  const AppRun r = run("render " + out.string() + " --frames 2", dir);
  expect_bad_input(r, out.string() + ": output directory '" + (dir / "nonexist").string() + "' does not exist");
  EXPECT_FALSE(fs::exists(dir / "nonexist"));
  EXPECT_TRUE(dir.files().empty());
}

// Issue 31 item 3: rendering into a directory that held a sequence mixed
// the two (the old frames beyond the new count stayed). Refused without
// --overwrite; with it the old sequence's files go, other files stay.
TEST(LedPoseApp, RenderIntoANonEmptyDirectoryNeedsOverwrite) {
  TempDir dir;
  const fs::path seq = dir / "seq";
  ASSERT_EQ(run("render " + seq.string() + " --frames 3 --seed 1", dir).code, 0);
  td::test::write_text(seq / "notes.txt", "mine");
  const std::string first_truth = file_bytes(seq / "ground_truth.jsonl");
  const AppRun refused = run("render " + seq.string() + " --frames 2 --seed 2", dir);
  expect_bad_input(refused, seq.string() + ": exists and is not empty; give --overwrite");
  EXPECT_EQ(file_bytes(seq / "ground_truth.jsonl"), first_truth);  // untouched
  EXPECT_TRUE(fs::exists(seq / "000002.png"));

  const AppRun r = run("render " + seq.string() + " --frames 2 --seed 2 --overwrite", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(seq)) files.push_back(e.path().filename().string());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files,
            (std::vector<std::string>{"000000.depth.png", "000000.png", "000001.depth.png", "000001.png", "camera.yaml",
                                      "constellation.yaml", "ground_truth.jsonl", "notes.txt", "sequence.yaml"}));
  EXPECT_EQ(read_truth(seq).size(), 2u);
  EXPECT_NE(file_bytes(seq / "ground_truth.jsonl"), first_truth);
  EXPECT_EQ(file_bytes(seq / "notes.txt"), "mine");
  EXPECT_EQ(dir.files(), std::vector<std::string>{"seq"});  // no staging directory left

  // An existing empty directory is fine without --overwrite.
  fs::create_directory(dir / "empty");
  ASSERT_EQ(run("render " + (dir / "empty").string() + " --frames 1", dir).code, 0);
  EXPECT_TRUE(fs::exists(dir / "empty" / "000000.png"));
}

// Issue 11: every count and size option has a range, shown by --help and
// checked before anything is read or allocated. Before: --frames 100000000
// ended in std::bad_alloc (exit 3); --seed -1 wrapped to 2^64 - 1;
// --max-distance 1e9 rendered a drone 1e9 m away with every LED "visible";
// benchmark --camera-tilt 1e9 and --aruco-size 1e300 were accepted.
TEST(LedPoseAppBadInput, CountsAndSizesHaveRanges) {
  TempDir dir;
  const std::string out = (dir / "out").string();
  expect_each_refused(
      {
          {"render " + out + " --frames 100000000", "--frames: 100000000 is outside [1, 100000]"},
          {"render " + out + " --frames 0", "--frames: 0 is outside [1, 100000]"},
          {"render " + out + " --frames 1e9", "--frames: 1e9 is outside [1, 100000]"},
          {"render " + out + " --seed -1", "--seed: must be >= 0, got -1"},
          {"render " + out + " --max-distance 1e9", "--max-distance: 1e9 is outside (0, 100]"},
          {"render " + out + " --min-distance nan", "--min-distance: nan is outside (0, 100]"},
          {"render " + out + " --camera-tilt 90", "--camera-tilt: 90 is outside [0, 80]"},
          {"render " + out + " --distractors 1e9", "--distractors: 1e9 is outside [0, 100]"},
          {"render " + out + " --dropout 2", "--dropout: 2 is outside [0, 1]"},
          {"render " + out + " --noise -1", "--noise: -1 is outside [0, 100]"},
          {"render " + out + " --aruco-id 1e9", "--aruco-id: 1e9 is outside [0, 1023]"},
          {"render " + out + " --aruco-size 0", "--aruco-size: 0 is outside (0, 10]"},
          {"benchmark --frames 0", "--frames: 0 is outside [1, 100000]"},
          {"benchmark --seed -1", "--seed: must be >= 0, got -1"},
          {"benchmark --camera-tilt 1e9", "--camera-tilt: 1e9 is outside [0, 80]"},
          {out + " --method aruco --aruco-size 1e300", "--aruco-size: 1e300 is outside (0, 10]"},
      },
      dir);
  EXPECT_FALSE(fs::exists(dir / "out"));
  // --help shows the ranges.
  const AppRun help = run("render --help", dir);
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("[1, 100000]"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("(0, 100]"), std::string::npos) << help.out;
}

// Issue 11: options that would be silently ignored are errors. Before,
// benchmark --camera-tilt, --geometry and --profile did nothing without
// --constellation, and --camera-tilt nothing without --geometry chase.
TEST(LedPoseAppBadInput, OptionsThatDoNotApplyAreRefused) {
  TempDir dir;
  const std::string out = (dir / "out").string();
  const std::string board = std::string(TOUCHDOWN_SOURCE_DIR) + "/data/constellations/front_board.yaml";
  expect_each_refused(
      {
          {"benchmark --camera-tilt 20", "--camera-tilt: applies only with --constellation"},
          {"benchmark --geometry chase", "--geometry: applies only with --constellation"},
          {"benchmark --profile harsh", "--profile: applies only with --constellation"},
          {"benchmark --constellation " + board + " --camera-tilt 20",
           "--camera-tilt: applies only with --geometry chase"},
          {"render " + out + " --camera-tilt 20", "--camera-tilt: applies only with --geometry chase"},
      },
      dir);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(LedPoseAppBadInput, ANameNotInTheListIsRefusedListingTheNames) {
  TempDir dir;
  const std::string out = (dir / "out").string();
  expect_each_refused(
      {
          {"render " + out + " --trajectory still", "--trajectory: expected one of static, moving; got 'still'"},
          {"render " + out + " --geometry behind", "--geometry: expected one of facing, chase; got 'behind'"},
          {"render " + out + " --profile dirty", "--profile: expected one of clean, harsh; got 'dirty'"},
      },
      dir);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// Issue 11: the apps estimate what a request costs before starting. Before:
// --frames 100000 started an hour of rendering into ~106 GB of PNGs; a
// 32768 x 32768 camera file ended in std::bad_alloc (exit 3) after trying to
// allocate ~31 GB; benchmark --frames 100000 ran for hours.
TEST(LedPoseAppBadInput, RequestsTooLargeAreRefusedWithAnEstimate) {
  TempDir dir;
  const AppRun frames = run("render " + (dir / "a").string() + " --frames 100000", dir);
  expect_bad_input(frames,
                   "--frames 100000 at 848x480: 4.07e10 pixels to render, ~106 GB of PNGs and ~61 min; the "
                   "limit is 1e10 pixels (24567 frames at 848x480)");
  td::test::write_text(dir / "big.yaml",
                       "width: 32768\nheight: 32768\nfx: 20000\nfy: 20000\ncx: 16383.5\ncy: 16383.5\n");
  const std::string big = (dir / "big.yaml").string();
  const AppRun camera = run("render " + (dir / "b").string() + " --frames 1 --camera " + big, dir);
  expect_bad_input(camera, "--camera " + big +
                               ": 32768 x 32768 = 1073741824 pixels needs ~31 GB a frame to render; "
                               "the limit is 16777216 pixels (4096 x 4096, ~0.49 GB)");
  const AppRun bench_camera = run("benchmark --frames 1 --camera " + big, dir);
  expect_bad_input(bench_camera, "--camera " + big + ": 32768 x 32768");
  const AppRun bench = run("benchmark --frames 100000", dir);
  expect_bad_input(bench,
                   "--frames 100000: 6 sequences of 848x480 frames, 2.44e11 pixels to render and track, ~3.1 "
                   "h; the limit is 1e11 pixels (40946 frames per sequence here)");
  // Nothing was written, not even a staging directory.
  EXPECT_EQ(dir.files(), std::vector<std::string>{"big.yaml"});
}

// The ArUco baseline's errors name the flags too (was "ArUco options:
// marker_id: ...").
TEST(LedPoseAppBadInput, ArucoErrorsNameTheFlag) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string() + " --method aruco --aruco-id 60", dir);
  expect_bad_input(r, "--aruco-id: 60 is not in dictionary 4X4_50 (ids 0..49)");
  EXPECT_EQ(r.err.find("marker_id"), std::string::npos) << r.err;
}

TEST(LedPoseAppBadInput, UnknownArucoDictionary) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const AppRun r = run(seq.string() + " --jsonl --method aruco --aruco-dict 9X9_7", dir);
  expect_bad_input(r, "9X9_7");
  EXPECT_NE(r.err.find("dictionary"), std::string::npos) << r.err;
}

TEST(LedPoseAppBadInput, FramesOfAnotherSizeThanTheCamera) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string yaml = td::test::replace_key_line(td::test::read_text(seq / "camera.yaml"), "width", "width: 640");
  ASSERT_NE(yaml.find("width: 640"), std::string::npos);
  td::test::write_text(dir / "cam640.yaml", yaml);
  const AppRun r = run(seq.string() + " --jsonl --camera " + (dir / "cam640.yaml").string(), dir);
  expect_bad_input(r, "000000.png");
  EXPECT_NE(r.err.find("848x480"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("640x480"), std::string::npos) << r.err;
}

// A PNG whose signature is intact but whose data is cut short, or damaged
// inside: read_frame checks the chunks and CRCs first, so libpng never gets
// to print its own message: one line on stderr.
TEST(LedPoseAppBadInput, TruncatedPngFrame) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string png = td::test::read_text(seq / "000001.png");
  td::test::write_text(seq / "000001.png", png.substr(0, png.size() / 3));
  expect_bad_input(run(seq.string() + " --jsonl", dir), "000001.png");
  std::string damaged = png;
  damaged[damaged.size() / 2] = static_cast<char>(damaged[damaged.size() / 2] ^ 0x5A);
  td::test::write_text(seq / "000001.png", damaged);
  const AppRun r = run(seq.string() + " --jsonl", dir);
  expect_bad_input(r, "000001.png");
  EXPECT_NE(r.err.find("CRC"), std::string::npos) << r.err;
}

// A 0-byte colour or depth frame: one line naming the file, not OpenCV's
// assertion text on two lines (issue 31 item 9).
TEST(LedPoseAppBadInput, EmptyFrameFile) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string colour = td::test::read_text(seq / "000002.png");
  td::test::write_text(seq / "000002.png", "");
  AppRun r = run(seq.string() + " --jsonl", dir);
  expect_bad_input(r, "000002.png: empty file (0 bytes)");
  EXPECT_EQ(r.err.find("OpenCV"), std::string::npos) << r.err;
  td::test::write_text(seq / "000002.png", colour);
  td::test::write_text(seq / "000004.depth.png", "");
  r = run(seq.string(), dir);
  expect_bad_input(r, "000004.depth.png: empty file (0 bytes)");
  // Without depth the depth PNGs are not read: the run succeeds.
  EXPECT_EQ(run(seq.string() + " --no-depth", dir).code, 0);
}

// ---- camera files users already have (issue 11) --------------------------------------

namespace {

// The sequence's camera as OpenCV's calibration sample saves it, written
// by cv::FileStorage itself.
void write_opencv_camera(const fs::path& file, const touchdown::pose::CameraModel& c, bool with_size = true) {
  cv::FileStorage out(file.string(), cv::FileStorage::WRITE);
  out << "calibration_time"
      << "Thu Jan 30 14:43:57 2020";
  if (with_size) out << "image_width" << c.width << "image_height" << c.height;
  out << "camera_matrix" << cv::Mat(cv::Matx33d(c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1));
  out << "distortion_coefficients" << cv::Mat(cv::Matx<double, 1, 5>(c.distortion.data()));
  out << "avg_reprojection_error" << 0.21;
}

// The sequence's camera as camera_calibration_parsers writes a ROS
// camera_info YAML (http://wiki.ros.org/camera_calibration_parsers).
std::string ros_camera_yaml(const touchdown::pose::CameraModel& c, const std::string& model = "plumb_bob") {
  std::ostringstream os;
  os << std::setprecision(17);
  os << "image_width: " << c.width << "\nimage_height: " << c.height << "\ncamera_name: ground_camera\n"
     << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [" << c.fx << ", 0, " << c.cx << ", 0, " << c.fy << ", " << c.cy
     << ", 0, 0, 1]\n"
     << "distortion_model: " << model << "\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [";
  for (std::size_t i = 0; i < 5; ++i) os << (i ? ", " : "") << c.distortion[i];
  os << "]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
     << "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [" << c.fx * 0.98 << ", 0, " << c.cx << ", 0, 0, "
     << c.fy * 0.98 << ", " << c.cy << ", 0, 0, 0, 1, 0]\n";
  return os.str();
}

}  // namespace

// The same intrinsics in an OpenCV or ROS file give the very same poses.
TEST(LedPoseApp, OpenCvAndRosCameraFilesGiveTheSamePoses) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const auto camera = touchdown::pose::load_camera(seq / "camera.yaml");
  write_opencv_camera(dir / "calib.yml", camera);
  ASSERT_EQ(td::test::read_text(dir / "calib.yml").rfind("%YAML:1.0", 0), 0u);
  td::test::write_text(dir / "ost.yaml", ros_camera_yaml(camera));
  const AppRun own = run(seq.string() + " --jsonl", dir);
  const AppRun opencv = run(seq.string() + " --jsonl --camera " + (dir / "calib.yml").string(), dir);
  const AppRun ros = run(seq.string() + " --jsonl --camera " + (dir / "ost.yaml").string(), dir);
  ASSERT_EQ(own.code, 0) << own.err;
  ASSERT_EQ(opencv.code, 0) << opencv.err;
  ASSERT_EQ(ros.code, 0) << ros.err;
  EXPECT_GE(check_jsonl(opencv.out, seq, true), 11);
  EXPECT_EQ(without_ms(opencv.out), without_ms(own.out));
  EXPECT_EQ(without_ms(ros.out), without_ms(own.out));
}

TEST(LedPoseAppBadInput, OpenCvCameraWithoutImageSize) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  write_opencv_camera(dir / "calib.yml", touchdown::pose::load_camera(seq / "camera.yaml"), false);
  const AppRun r = run(seq.string() + " --jsonl --camera " + (dir / "calib.yml").string(), dir);
  expect_bad_input(r, "calib.yml");
  EXPECT_NE(r.err.find("image_width: missing"), std::string::npos) << r.err;
}

TEST(LedPoseAppBadInput, RosCameraWithFisheyeModel) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  td::test::write_text(dir / "ost.yaml",
                       ros_camera_yaml(touchdown::pose::load_camera(seq / "camera.yaml"), "equidistant"));
  const AppRun r = run(seq.string() + " --jsonl --camera " + (dir / "ost.yaml").string(), dir);
  expect_bad_input(r, "ost.yaml:");
  EXPECT_NE(r.err.find("distortion_model: equidistant (fisheye) is not supported"), std::string::npos) << r.err;
}

// A depth_scale in the wrong unit would let the depth gate drop every LED
// in silence: reported at the first depth frame, naming the camera file.
TEST(LedPoseAppBadInput, ImplausibleDepthScale) {
  TempDir dir;
  const auto seq = rendered_sequence(dir);
  const std::string yaml = td::test::read_text(seq / "camera.yaml");
  const struct {
    std::string scale, needle;
  } cases[] = {{"1", "depth_scale: 1 m per unit puts the median depth at"},
               {"0.000001", "depth_scale: 1e-06 m per unit puts the median depth at"}};
  for (const auto& c : cases) {
    td::test::write_text(dir / "cam.yaml", td::test::replace_key_line(yaml, "depth_scale", "depth_scale: " + c.scale));
    const AppRun r = run(seq.string() + " --jsonl --camera " + (dir / "cam.yaml").string(), dir);
    expect_bad_input(r, (dir / "cam.yaml").string() + ": " + c.needle);
    EXPECT_NE(r.err.find("millimetres needs depth_scale: 0.001"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("000000.depth.png"), std::string::npos) << r.err;
    // Without depth images the scale is never used.
    const AppRun no_depth = run(seq.string() + " --jsonl --no-depth --camera " + (dir / "cam.yaml").string(), dir);
    EXPECT_EQ(no_depth.code, 0) << no_depth.err;
  }
  // The sequence's own camera.yaml is named when it is the one at fault.
  td::test::write_text(seq / "camera.yaml", td::test::replace_key_line(yaml, "depth_scale", "depth_scale: 1"));
  expect_bad_input(run(seq.string(), dir), (seq / "camera.yaml").string() + ": depth_scale: 1 m per unit");
}

// Issue 58 item 1: Ctrl-C while rendering used to leave the staging
// directory (64 MB, 122 files); now the signal's thread removes it and the
// process ends by SIGINT.
TEST(LedPoseApp, AnInterruptedRenderLeavesNothing) {
  TempDir dir;
  const AppRun r = td::test::interrupt_app(LED_POSE_EXE, "render " + (dir / "intseq").string() + " --frames 3000", dir,
                                           ".intseq.partial-", "INT");
  EXPECT_EQ(r.code, 128 + 2) << r.err;  // ended by SIGINT
  EXPECT_NE(r.err.find("led_pose: interrupted (SIGINT): removed 1 unfinished output(s)"), std::string::npos) << r.err;
  EXPECT_TRUE(dir.files().empty()) << dir.files().front();
}

// Issue 58 item 5: grey frames gave "pose found 0 / 12" and no reason
// outside --jsonl; JPEG frames under a camera's own names were refused.
TEST(LedPoseApp, GreyFramesSayWhyAndCameraNamedJpegsAreASequence) {
  TempDir dir;
  const fs::path seq = rendered_sequence(dir);
  const fs::path grey = dir / "grey", jpeg = dir / "jpeg";
  fs::create_directories(grey);
  fs::create_directories(jpeg);
  for (const auto& name : {"camera.yaml", "constellation.yaml"}) {
    fs::copy_file(seq / name, grey / name);
    fs::copy_file(seq / name, jpeg / name);
  }
  for (int i = 0; i < 12; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "%06d", i);
    const cv::Mat colour = cv::imread((seq / (std::string(name) + ".png")).string(), cv::IMREAD_COLOR);
    ASSERT_FALSE(colour.empty());
    cv::Mat g;
    cv::extractChannel(colour, g, 1);
    ASSERT_TRUE(cv::imwrite((grey / (std::string(name) + ".png")).string(), g));
    ASSERT_TRUE(cv::imwrite((jpeg / ("frame_" + std::to_string(i + 1) + ".jpg")).string(), colour,
                            {cv::IMWRITE_JPEG_QUALITY, 95}));
  }
  const AppRun g = run(grey.string() + " --no-depth", dir);
  ASSERT_EQ(g.code, 0) << g.err;
  EXPECT_NE(g.out.find("pose found      0 / 12"), std::string::npos) << g.out;
  EXPECT_NE(g.out.find("  no pose         12 no consistent correspondence\n"), std::string::npos) << g.out;
  EXPECT_NE(g.out.find("12 frames without colour (grey): the LED method finds the LEDs by their colour"),
            std::string::npos)
      << g.out;
  // The colour frames as JPEGs named by a camera: read in number order
  // (frame_2 before frame_10) and most of them get a pose.
  const AppRun j = run(jpeg.string() + " --no-depth --jsonl", dir);
  ASSERT_EQ(j.code, 0) << j.err;
  const auto lines = lines_of(j.out);
  ASSERT_EQ(lines.size(), 12U);
  EXPECT_NE(lines[1].find("\"frame\": \"frame_2\""), std::string::npos) << lines[1];
  EXPECT_NE(lines[9].find("\"frame\": \"frame_10\""), std::string::npos) << lines[9];
  const AppRun png = run(seq.string() + " --no-depth", dir), jpg = run(jpeg.string() + " --no-depth", dir);
  EXPECT_EQ(png.out.substr(png.out.find("pose found"), 30), jpg.out.substr(jpg.out.find("pose found"), 30))
      << png.out << jpg.out;
}
