// MM-MLS closed loop: its obstacle map, descent planning and refusals
// against objects near, on and over the marker, and the tilt-aware centring
// of both reference systems. Every run is kept short (time limits just
// above what the landing needs) and shared by several assertions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>

#include "scenario/aruco_detector.hpp"
#include "scenario/clear_scenario.hpp"
#include "touchdown/scenario/run.hpp"

namespace touchdown::scenario {
namespace {

ScenarioResult mm_run(const Scenario& s, std::string_view system, const RunOptions& options = {}) {
  auto sut = make_landing_system(system);
  return run_scenario(s, *sut, options);
}

/// Horizontal distance from p to a box object's footprint (0 inside).
double mm_distance_to_footprint(const Eigen::Vector2d& p, const StaticObject& box) {
  const double yaw = box.yaw_deg * 3.14159265358979323846 / 180.0;
  const Eigen::Vector2d d = p - box.position;
  const Eigen::Vector2d local(std::cos(yaw) * d.x() + std::sin(yaw) * d.y(),
                              -std::sin(yaw) * d.x() + std::cos(yaw) * d.y());
  const Eigen::Vector2d out = (local.cwiseAbs() - 0.5 * box.size.head<2>()).cwiseMax(0.0);
  return out.norm();
}

bool mm_phase_seen(const ScenarioResult& r, std::string_view phase) {
  return std::any_of(r.trajectory.begin(), r.trajectory.end(),
                     [&](const TrajectorySample& x) { return x.phase == phase; });
}

bool mm_phase_never(const ScenarioResult& r, std::string_view phase) { return !mm_phase_seen(r, phase); }

/// A pole or a box as a box footprint (a pole's square hull: conservative).
StaticObject mm_box(Eigen::Vector2d position, Eigen::Vector3d size) {
  StaticObject o;
  o.kind = StaticKind::Box;
  o.position = position;
  o.size = size;
  return o;
}

TEST(MmMls, LandsBesideThePoleThatOpencvMlsHits) {
  // RunScenario's Type III scenario: a 5 cm pole 4 m high at (0.2, 0.2),
  // 0.28 m from the marker centre, which opencv-mls hits on its way down.
  // There is room to land beside it: mm-mls maps the pole, lands at least
  // its radius plus the margin from the pole's cell, within 1.5 m.
  const Scenario s = test::pole_on_marker_scenario(45);
  const StaticObject& pole = s.static_objects[0];
  const ScenarioResult r = mm_run(s, "mm-mls");
  EXPECT_FALSE(r.collided) << r.message;
  EXPECT_EQ(r.status, Violation::None) << r.message;
  EXPECT_TRUE(r.landed);
  EXPECT_LE(r.dtl, 1.5);
  EXPECT_TRUE(r.descent_started);
  // Not over the pole: the rotor disks stay clear of it.
  const Eigen::Vector2d p = r.final_position.head<2>();
  EXPECT_GT((p - pole.position).norm(), twin::Airframe::f450().footprint_radius() + 0.025) << p.transpose();
  EXPECT_TRUE(mm_phase_seen(r, "descend"));
}

TEST(MmMls, KeepsItsMarginFromABoxBesideTheMarker) {
  // A 1 m cube whose near face is 0.5 m from the marker centre (it covers
  // part of the marker's white margin, not its code): opencv-mls lands on
  // the marker with its rotor tips 0.2 m from the box; mm-mls keeps its
  // radius plus margin from every mapped cell.
  Scenario s = test::clear_scenario(35);
  s.static_objects = {mm_box({1.0, 0.0}, {1, 1, 1})};
  const ScenarioResult r = mm_run(s, "mm-mls");
  EXPECT_FALSE(r.collided) << r.message;
  EXPECT_EQ(r.status, Violation::None) << r.message;
  EXPECT_TRUE(r.landed);
  EXPECT_LE(r.dtl, 1.5);
  const double clearance = mm_distance_to_footprint(r.final_position.head<2>(), s.static_objects[0]);
  EXPECT_GE(clearance, twin::Airframe::f450().footprint_radius() + 0.1 + 0.15) << r.final_position.transpose();
}

TEST(MmMls, DoesNotLandOnABoxStandingOnTheMarker) {
  // A 2 m marker with a 0.2 m box 0.5 m high on its centre (a corner of
  // four code cells: the code still reads). opencv-mls descends onto the
  // box; mm-mls lands beside it; told it may not move its landing point
  // more than 0.3 m from the marker, it refuses (Type II) instead of
  // landing on the box.
  Scenario s = test::clear_scenario(35);
  s.marker.size = 2.0;
  s.static_objects = {mm_box({0, 0}, {0.2, 0.2, 0.5})};
  const StaticObject& box = s.static_objects[0];

  const ScenarioResult base = mm_run(s, "opencv-mls");
  EXPECT_EQ(base.status, Violation::TypeIII) << base.message;

  const ScenarioResult r = mm_run(s, "mm-mls");
  EXPECT_FALSE(r.collided) << r.message;
  EXPECT_EQ(r.status, Violation::None) << r.message;
  EXPECT_TRUE(r.landed);
  EXPECT_LE(r.dtl, 1.5);
  EXPECT_GE(mm_distance_to_footprint(r.final_position.head<2>(), box), twin::Airframe::f450().footprint_radius())
      << r.final_position.transpose();

  MlsOptions strict;
  strict.max_landing_offset = 0.3;
  s.time_limit = 25;
  auto sut = make_landing_system("mm-mls", strict);
  const ScenarioResult refused = run_scenario(s, *sut);
  EXPECT_FALSE(refused.collided) << refused.message;
  EXPECT_EQ(refused.status, Violation::TypeII) << refused.message;
  EXPECT_FALSE(refused.landed);
  EXPECT_TRUE(refused.descent_started);
  EXPECT_TRUE(mm_phase_seen(refused, "no-landing-spot"));
  EXPECT_TRUE(mm_phase_never(refused, "land"));
  // It went back up rather than down onto the box.
  EXPECT_GT(refused.final_position.z(), 5.0);
}

TEST(MmMls, ClearGroundLandsAsWellAsOpencvMls) {
  // The bundled scenario (a box 4 m north, a person walking 4 m south):
  // ground pixels and the walking person must not keep mm-mls from the
  // marker.
  Scenario s = load_scenario(std::string(TOUCHDOWN_SOURCE_DIR) + "/data/scenarios/clear_ground.yaml");
  s.time_limit = 30;
  const ScenarioResult a = mm_run(s, "opencv-mls");
  const ScenarioResult b = mm_run(s, "mm-mls");
  EXPECT_EQ(a.status, Violation::None) << a.message;
  EXPECT_EQ(b.status, Violation::None) << b.message;
  EXPECT_LE(a.dtl, 0.3);
  EXPECT_LE(b.dtl, 0.3);
  EXPECT_TRUE(mm_phase_never(b, "no-landing-spot"));
  EXPECT_TRUE(mm_phase_never(b, "replan-climb"));
}

TEST(MmMls, TiltedCameraLandsWithBothSystems) {
  // The camera pitched 30° forward (70° field of view, 16:9): the systems
  // hold the drone behind the marker so that it stays in view through the
  // 5 s gate and the descent; centring over it would lose it (Type II).
  Scenario s = test::clear_scenario(25);
  RunOptions o;
  o.camera.tilt_deg = 30;
  o.camera.hfov_deg = 70;
  o.camera.width = 640;
  o.camera.height = 360;
  for (const char* system : {"opencv-mls", "mm-mls"}) {
    const ScenarioResult r = mm_run(s, system, o);
    EXPECT_EQ(r.status, Violation::None) << system << ": " << r.message;
    EXPECT_TRUE(r.landed) << system;
    EXPECT_LE(r.dtl, 1.5) << system;
    // While tracking at cruise altitude it held about 10·tan 30° = 5.2 m
    // (cruise altitude over the land altitude) behind the marker.
    double x_track = 0;
    for (const auto& x : r.trajectory)
      if (x.phase == "track") x_track = x.position.x();
    EXPECT_NEAR(x_track, -std::tan(30 * 3.14159265358979323846 / 180) * (10 - 1.5), 0.5) << system;
  }
}

/// A 6X6_50 marker at the origin and, at (x, 0.04), a larger look-alike
/// with two code cells inverted, which OpenCV's error correction reads as
/// the target id (after Ground seed 60 of the random campaigns).
Scenario lookalike_beside_marker_scenario(double x) {
  Scenario s = test::clear_scenario(30);
  s.marker.dictionary = "6X6_50";
  s.marker.id = 40;
  s.marker.size = 0.95;
  s.marker.yaw_deg = 40.8;
  Distractor look;
  look.kind = DistractorKind::Lookalike;
  look.flipped_bits = 2;
  look.size = 1.2;
  look.position = {x, 0.04};
  look.yaw_deg = 64.6;
  s.distractors = {look};
  return s;
}

TEST(MmMls, FollowsTheMarkerItTracksNotADecodableLookAlike) {
  // A 6X6_50 marker and, 2.8 m east, a larger look-alike with two code
  // cells inverted, which OpenCV's error correction reads as the target id
  // (after Ground seed 60 of the random campaigns). Coming from the west,
  // both systems see the marker first. opencv-mls follows the largest
  // detection of the moment and lands on the look-alike (Type I); mm-mls
  // follows the detection nearest the marker it tracks and lands on it.
  const Scenario s = lookalike_beside_marker_scenario(2.84);

  const ScenarioResult base = mm_run(s, "opencv-mls");
  EXPECT_TRUE(base.false_detection) << "the look-alike must read as the target: " << base.message;
  EXPECT_EQ(base.status, Violation::TypeI) << base.message;

  const ScenarioResult r = mm_run(s, "mm-mls");
  EXPECT_EQ(r.status, Violation::None) << r.message;
  EXPECT_TRUE(r.landed);
  EXPECT_LE(r.dtl, 0.3) << r.message;
  // Once tracking, the look-alike is never taken for the target.
  int false_after_descent = 0;
  for (const FrameRecord& f : r.frames)
    if (f.t >= r.descent_time) false_after_descent += f.false_accepted;
  EXPECT_EQ(false_after_descent, 0);
  EXPECT_TRUE(mm_phase_never(r, "replan-hold")) << "its landing point swung between the markers";
}

TEST(MmMls, ReacquiresTheMarkerWhenALookAlikeWasSeenFirst) {
  // The scenario above mirrored: the look-alike lies 2.84 m west, so coming
  // from the west both systems see it first. opencv-mls lands on it (Type
  // I). mm-mls reads each sighting's code: its track, built on corrected
  // readings only, gives way to the marker once the marker reads exactly,
  // and it lands on the marker. Without the code check mm-mls keeps the
  // look-alike (its gate) and lands on it too.
  const Scenario s = lookalike_beside_marker_scenario(-2.84);

  const ScenarioResult base = mm_run(s, "opencv-mls");
  EXPECT_EQ(base.status, Violation::TypeI) << base.message;

  const ScenarioResult r = mm_run(s, "mm-mls");
  EXPECT_EQ(r.status, Violation::None) << r.message;
  EXPECT_LE(r.dtl, 0.3) << r.message;
  // A frame where the look-alike alone was the target (the track followed
  // it: the marker was not in view or not read); then the marker, and the
  // look-alike never accepted again.
  const auto only_false = [](const FrameRecord& f) { return f.accepted > 0 && f.accepted == f.false_accepted; };
  std::size_t followed = r.frames.size();
  for (std::size_t i = 0; i < r.frames.size(); ++i)
    if (only_false(r.frames[i])) followed = i;
  ASSERT_LT(followed, r.frames.size()) << "the track must have followed the look-alike";
  std::size_t moved = followed + 1;
  while (moved < r.frames.size() && r.frames[moved].accepted <= r.frames[moved].false_accepted) ++moved;
  ASSERT_LT(moved, r.frames.size()) << "the marker was never taken back";
  for (std::size_t i = moved; i < r.frames.size(); ++i) EXPECT_EQ(r.frames[i].false_accepted, 0) << "frame " << i;
  EXPECT_GT(r.descent_time, r.frames[moved].t);
}

/// A marker drawn by OpenCV on a white sheet, seen through a homography.
cv::Mat code_view(const cv::aruco::Dictionary& dict, int id, const std::vector<cv::Point>& inverted_cells) {
  const int n = dict.markerSize, cell = 24, side = (n + 2) * cell;
  cv::Mat marker;
  cv::aruco::drawMarker(cv::makePtr<cv::aruco::Dictionary>(dict), id, side, marker, 1);
  for (const cv::Point& c : inverted_cells) {
    cv::Mat block = marker(cv::Rect((c.x + 1) * cell, (c.y + 1) * cell, cell, cell));
    cv::bitwise_not(block, block);
  }
  cv::Mat sheet(side + 2 * cell * 2, side + 2 * cell * 2, CV_8UC1, cv::Scalar(255));
  marker.copyTo(sheet(cv::Rect(2 * cell, 2 * cell, side, side)));
  const int w = sheet.cols;
  const cv::Point2f from[4] = {
      {0, 0}, {static_cast<float>(w), 0}, {static_cast<float>(w), static_cast<float>(w)}, {0, static_cast<float>(w)}};
  const cv::Point2f to[4] = {{60, 40}, {330, 70}, {300, 310}, {40, 280}};  // oblique and rotated a little
  cv::Mat view;
  cv::warpPerspective(sheet, view, cv::getPerspectiveTransform(from, to), cv::Size(400, 360), cv::INTER_AREA,
                      cv::BORDER_CONSTANT, cv::Scalar(160));
  return view;
}

TEST(MarkerCode, CountsTheCellsThatDifferFromTheTargetsCode) {
  // Oracle: markers drawn by OpenCV, some with cells inverted; OpenCV's own
  // decoder (error correction) still reads them as the target id, and the
  // code check counts exactly the inverted cells — from ArUco's oriented
  // corners, and from the same corners in another rotation when told they
  // are not oriented (a learned detector's).
  for (const auto& [name, dict_name, id] :
       {std::tuple{cv::aruco::DICT_6X6_50, "6X6_50", 40}, std::tuple{cv::aruco::DICT_5X5_50, "5X5_50", 7}}) {
    const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(name);
    detail::ArucoDetector detector(false, 10);
    detector.reset(dict_name, id);
    detail::CodeReader reader;
    reader.reset(dict_name);
    std::vector<std::vector<cv::Point>> flips = {{}, {{2, 1}}};
    if (dict->maxCorrectionBits >= 4) flips.push_back({{2, 1}, {4, 3}});  // 6X6_50 corrects two at OpenCV's rate
    for (const auto& cells : flips) {
      const cv::Mat view = code_view(*dict, id, cells);
      std::vector<MarkerDetection> found;
      detector.detect({{}, {view.data, view.cols, view.rows, static_cast<std::ptrdiff_t>(view.step)}}, found);
      ASSERT_EQ(found.size(), 1u) << "dictionary " << name << ", " << cells.size() << " cells inverted";
      ASSERT_EQ(found[0].id, id);
      ASSERT_TRUE(found[0].has_corners && found[0].oriented);
      EXPECT_DOUBLE_EQ(found[0].confidence, 1.0);
      const auto& c = found[0].corners;
      EXPECT_EQ(reader.code_errors(view, c, id, true), static_cast<int>(cells.size()))
          << "dictionary " << name << ", " << cells.size() << " cells inverted";
      const std::array<Eigen::Vector2d, 4> turned{c[2], c[3], c[0], c[1]};
      EXPECT_EQ(reader.code_errors(view, turned, id, false), static_cast<int>(cells.size()));
      EXPECT_GT(reader.code_errors(view, turned, id, true), static_cast<int>(cells.size()));
      // Against another id's code: many cells differ.
      EXPECT_GE(reader.code_errors(view, c, id + 1, true), 3);
    }
  }
}

}  // namespace
}  // namespace touchdown::scenario
