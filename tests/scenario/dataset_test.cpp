// Detector datasets (dataset.hpp): labels against the world's own mask and
// the pinhole model on hand-built scenes, distractor kinds, an object in
// front of the target, determinism per (seed, index), and the splits.
#include "touchdown/scenario/dataset.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>

#include "scenario/clear_scenario.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

SceneState nadir(const Scenario& s, const Eigen::Vector3d& at) {
  SceneState state;
  state.T_world_body.translation() = at;
  for (const DynamicObject& o : s.dynamic_objects) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << o.position, 0;
    state.T_world_dynamic.push_back(T);
  }
  return state;
}

/// The bounding box of the mask's pixels of `label` [px; max exclusive].
bool mask_box(const CameraFrame& f, Label label, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  int x0 = f.width, y0 = f.height, x1 = -1, y1 = -1;
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      if (f.mask[static_cast<std::size_t>(y * f.width + x)] != mask_value(label)) continue;
      x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
    }
  }
  *lo = Eigen::Vector2d(x0, y0);
  *hi = Eigen::Vector2d(x1 + 1, y1 + 1);
  return x1 >= 0;
}

TEST(DatasetLabels, TheTargetsBoxIsThePinholeProjectionAndMatchesTheMask) {
  Scenario s = test::clear_scenario();  // a 1 m 4X4_50 marker at the origin
  s.marker.yaw_deg = 0;
  const CameraOptions camera;  // 640 x 480, fx = 320, 5 cm below the body's origin
  const DatasetFrame f = label_frame(s, camera, nadir(s, {0, 0, 8 - camera.offset_body.z()}));
  ASSERT_TRUE(f.target.in_view());
  // 1 m with the camera 8 m up: 40 px a side about the principal point (319.5, 239.5).
  EXPECT_NEAR(f.target.box_max.x() - f.target.box_min.x(), 40.0, 1e-6);
  EXPECT_NEAR(f.target.box_max.y() - f.target.box_min.y(), 40.0, 1e-6);
  EXPECT_NEAR(0.5 * (f.target.box_min + f.target.box_max).x(), 319.5, 1e-6);
  EXPECT_NEAR(0.5 * (f.target.box_min + f.target.box_max).y(), 239.5, 1e-6);
  EXPECT_NEAR(f.target.inside_fraction, 1.0, 1e-9);
  EXPECT_NEAR(f.target.visible_fraction, 1.0, 1e-9);
  EXPECT_EQ(f.view.sight, Sight::Observable) << to_string(f.view.sight);
  EXPECT_NEAR(f.distance, 8.0, 1e-9);
  // The mask's marker pixels are the bordered code and its white margin of
  // one cell (1/6 m for a 4x4 code: 6.7 px): the label's box grown by it.
  Eigen::Vector2d lo, hi;
  ASSERT_TRUE(mask_box(f.frame, Label::Marker, &lo, &hi));
  const double margin = 40.0 / 6;
  EXPECT_NEAR(lo.x(), f.target.box_min.x() - margin, 1.5);
  EXPECT_NEAR(lo.y(), f.target.box_min.y() - margin, 1.5);
  EXPECT_NEAR(hi.x(), f.target.box_max.x() + margin, 1.5);
  EXPECT_NEAR(hi.y(), f.target.box_max.y() + margin, 1.5);
  // Corners: clockwise on the screen from the one nearest the top-left.
  const auto& c = f.target.corners;
  EXPECT_LT(c[0].sum(), std::min({c[1].sum(), c[2].sum(), c[3].sum()}));
  double area2 = 0;
  for (std::size_t i = 0; i < 4; ++i) area2 += c[i].x() * c[(i + 1) % 4].y() - c[(i + 1) % 4].x() * c[i].y();
  EXPECT_NEAR(area2 / 2, 1600.0, 1e-6) << "positive: clockwise with y down";
}

TEST(DatasetLabels, DistractorsKeepTheirKindsAndBoxes) {
  Scenario s = test::clear_scenario();
  Distractor look;
  look.kind = DistractorKind::Lookalike;
  look.flipped_bits = 1;
  look.position = {3, 0};
  Distractor wrong;
  wrong.kind = DistractorKind::WrongId;
  wrong.id = 7;
  wrong.position = {-3, 1};
  wrong.size = 0.5;
  s.distractors = {look, wrong};
  const DatasetFrame f = label_frame(s, CameraOptions{}, nadir(s, {0, 0, 8.05}));
  ASSERT_EQ(f.distractors.size(), 2u);
  EXPECT_EQ(f.distractors[0].kind, DistractorKind::Lookalike);
  EXPECT_EQ(f.distractors[1].kind, DistractorKind::WrongId);
  // 1 m and 0.5 m at 8 m: 40 and 20 px a side, all of it showing.
  for (const DistractorLabel& d : f.distractors) {
    ASSERT_TRUE(d.quad.in_view());
    EXPECT_NEAR(d.quad.visible_fraction, 1.0, 0.02);
  }
  EXPECT_NEAR(f.distractors[0].quad.box_max.x() - f.distractors[0].quad.box_min.x(), 40.0, 1e-6);
  EXPECT_NEAR(f.distractors[1].quad.box_max.x() - f.distractors[1].quad.box_min.x(), 20.0, 1e-6);
  // The union of both distractors' mask pixels lies inside their boxes grown by a margin cell.
  Eigen::Vector2d lo, hi;
  ASSERT_TRUE(mask_box(f.frame, Label::Distractor, &lo, &hi));
  Eigen::Vector2d blo = f.distractors[0].quad.box_min.cwiseMin(f.distractors[1].quad.box_min);
  Eigen::Vector2d bhi = f.distractors[0].quad.box_max.cwiseMax(f.distractors[1].quad.box_max);
  EXPECT_GE(lo.x(), blo.x() - 40.0 / 6 - 1.5);
  EXPECT_GE(lo.y(), blo.y() - 40.0 / 6 - 1.5);
  EXPECT_LE(hi.x(), bhi.x() + 40.0 / 6 + 1.5);
  EXPECT_LE(hi.y(), bhi.y() + 40.0 / 6 + 1.5);
  // The target is not a distractor: its box holds no distractor pixels.
  EXPECT_EQ(f.target.visible_fraction, 1.0);
}

TEST(DatasetLabels, AnObjectInFrontLowersTheVisibleFractionAsTheMaskCountsIt) {
  Scenario s = test::clear_scenario();
  s.marker.size = 2.0;
  DynamicObject person;
  person.kind = DynamicKind::Person;
  person.size = {0.5, 0.8, 1.75};
  person.position = {0.5, 0};  // on the marker's right half
  person.motion = MotionKind::Still;
  s.dynamic_objects = {person};
  const DatasetFrame f = label_frame(s, CameraOptions{}, nadir(s, {0, 0, 8}));
  ASSERT_TRUE(f.target.in_view());
  EXPECT_GT(f.target.visible_fraction, 0.5);
  EXPECT_LT(f.target.visible_fraction, 0.97);
  // The renderer's own count of the marker's visible pixels (with the
  // margin) against its unhidden area gives the same fraction within a
  // few percent (the label counts inside the bordered code only).
  const double rendered = f.frame.marker_area_visible_px / f.frame.marker_area_truth_px;
  EXPECT_NEAR(f.target.visible_fraction, rendered, 0.08);
}

TEST(DatasetLabels, AMarkerBehindTheCameraOrOutOfTheImageIsNotInView) {
  Scenario s = test::clear_scenario();
  const DatasetFrame far = label_frame(s, CameraOptions{}, nadir(s, {30, 0, 8}));
  EXPECT_FALSE(far.target.in_view());
  EXPECT_EQ(far.target.visible_fraction, 0.0);
  // Its centre 8 m to the side at 8 m (fx = 320 px): 320 px from the
  // principal point 319.5, so 20.5 of its 40 px inside along the image's
  // x axis; out of the 480 px high image along its y axis.
  const CameraOptions camera;
  const auto inside = [&](const Eigen::Vector2d& xy) {
    const DatasetFrame f = label_frame(s, camera, nadir(s, {xy.x(), xy.y(), 8 - camera.offset_body.z()}));
    return f.target.in_view() ? f.target.inside_fraction : 0.0;
  };
  const double a = inside({8, 0}), b = inside({0, 8});
  EXPECT_NEAR(std::max(a, b), 20.5 / 40, 1e-9);
  EXPECT_EQ(std::min(a, b), 0.0);
}

TEST(Dataset, AFrameDependsOnItsSeedAndIndexOnly) {
  DatasetOptions o;
  o.seed = 11;
  const DatasetFrame a = render_dataset_frame(o, 3);
  const DatasetFrame b = render_dataset_frame(o, 3);
  EXPECT_EQ(a.scenario_seed, b.scenario_seed);
  EXPECT_EQ(a.frame.image.pixels, b.frame.image.pixels);
  EXPECT_EQ(a.target.corners, b.target.corners);
  EXPECT_EQ(a.scenario.marker.dictionary, "4X4_50");
  EXPECT_EQ(a.scenario.marker.id, 0);
  const DatasetFrame c = render_dataset_frame(o, 4);
  EXPECT_NE(a.scenario_seed, c.scenario_seed);
  o.seed = 12;
  EXPECT_NE(render_dataset_frame(o, 3).scenario_seed, a.scenario_seed);
}

TEST(Dataset, TheTargetIsTheRequestedMarkerAndWrongIdsStayWrong) {
  DatasetOptions o;
  o.dictionary = "5X5_100";
  o.marker_id = 42;
  int wrong = 0;
  for (int i = 0; i < 40; ++i) {
    const DatasetFrame f = render_dataset_frame(o, i);
    ASSERT_EQ(f.scenario.marker.dictionary, "5X5_100");
    ASSERT_EQ(f.scenario.marker.id, 42);
    std::string why;
    ASSERT_TRUE(f.scenario.validate(&why)) << why;
    for (const Distractor& d : f.scenario.distractors) {
      if (d.kind != DistractorKind::WrongId) continue;
      ++wrong;
      EXPECT_NE(d.id, 42);
      EXPECT_LT(d.id, 100);
    }
  }
  EXPECT_GT(wrong, 0) << "40 random scenes hold a wrong-id distractor";
}

TEST(Dataset, SplitsFollowTheFractions) {
  DatasetOptions o;
  o.validation_fraction = 0.25;
  o.test_fraction = 0.25;
  // dataset_split is the rendered frame's split, without the rendering.
  for (int i = 0; i < 4; ++i) EXPECT_EQ(dataset_split(o, i), render_dataset_frame(o, i).split) << i;
  int counts[3] = {0, 0, 0};
  for (int i = 0; i < 2000; ++i) ++counts[static_cast<int>(dataset_split(o, i))];
  // 2000 draws: each share within ~4.5 standard deviations (σ ≈ 0.011, 0.0097).
  EXPECT_NEAR(counts[0] / 2000.0, 0.5, 0.05);
  EXPECT_NEAR(counts[1] / 2000.0, 0.25, 0.045);
  EXPECT_NEAR(counts[2] / 2000.0, 0.25, 0.045);
  EXPECT_THROW((void)dataset_split(o, -1), InvalidArgument);
}

TEST(Dataset, InvalidOptionsNameTheKey) {
  DatasetOptions o;
  o.dictionary = "9X9_1";
  EXPECT_THROW(render_dataset_frame(o, 0), InvalidArgument);
  o = {};
  o.marker_id = 50;
  try {
    (void)render_dataset_frame(o, 0);
    ADD_FAILURE() << "id 50 of 4X4_50 accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("marker"), std::string::npos) << e.what();
  }
  o = {};
  o.test_fraction = 0.8;
  o.validation_fraction = 0.3;
  EXPECT_THROW(render_dataset_frame(o, 0), InvalidArgument);
}

TEST(Dataset, MarkerSpecIsANameAColonAndAWholeInteger) {
  std::string dictionary = "kept";
  int id = -7;
  EXPECT_TRUE(parse_marker_spec("5X5_100:42", dictionary, id));
  EXPECT_EQ(dictionary, "5X5_100");
  EXPECT_EQ(id, 42);
  for (const char* bad : {"4X4_50", "4X4_50:", ":3", "4X4_50:3x", "4X4_50:x3", "4X4_50: 3", "4X4_50:99999999999"}) {
    dictionary = "kept", id = -7;
    EXPECT_FALSE(parse_marker_spec(bad, dictionary, id)) << bad;
    EXPECT_EQ(dictionary, "kept") << bad;
    EXPECT_EQ(id, -7) << bad;
  }
}

TEST(Dataset, WrittenFilesAreTheFramesForAnyThreadCountAndRefuseAnExistingDirectory) {
  const touchdown::test::TempDir dir;
  DatasetOptions o;
  o.seed = 5;
  BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const DatasetSummary a = write_dataset(o, 3, dir / "a", one);
  const DatasetSummary b = write_dataset(o, 3, dir / "b", two);
  EXPECT_EQ(a.count, 3);
  EXPECT_EQ(a.splits[0] + a.splits[1] + a.splits[2], 3);
  EXPECT_EQ(a.splits, b.splits);
  const std::string labels = touchdown::test::read_text(dir / "a" / "labels.jsonl");
  EXPECT_EQ(labels, touchdown::test::read_text(dir / "b" / "labels.jsonl"));
  // Line i is frame i's label, as dataset_label_json writes it.
  const std::string first = labels.substr(0, labels.find('\n'));
  EXPECT_EQ(first, dataset_label_json(render_dataset_frame(o, 0), "images/000000.png"));
  EXPECT_EQ(std::count(labels.begin(), labels.end(), '\n'), 3);
  for (const char* image : {"images/000000.png", "images/000001.png", "images/000002.png"}) {
    EXPECT_EQ(touchdown::test::read_text(dir / "a" / image), touchdown::test::read_text(dir / "b" / image)) << image;
  }
  EXPECT_NE(touchdown::test::read_text(dir / "a" / "dataset.json").find("\"touchdown-dataset/1\""), std::string::npos);
  EXPECT_THROW((void)write_dataset(o, 3, dir / "a", one), IoError);
  EXPECT_THROW((void)write_dataset(o, 0, dir / "c", one), InvalidArgument);
  EXPECT_FALSE(std::filesystem::exists(dir / "c"));
  // A cancelled run leaves no directory.
  const std::atomic<bool> cancel{true};
  BatchOptions cancelled;
  cancelled.cancel = &cancel;
  EXPECT_EQ(write_dataset(o, 3, dir / "d", cancelled).count, 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "d"));
}

}  // namespace
}  // namespace touchdown::scenario
