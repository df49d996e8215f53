// The detector benchmark's scoring (detector_bench.hpp): average precision
// against hand computations, which targets count, matching by IoU and id,
// and the labels reader's errors.
#include "touchdown/scenario/detector_bench.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

TEST(AveragePrecision, MatchesHandComputedCurves) {
  // Ranked: hit, miss, hit with 2 positives: recall 0.5 at precision 1,
  // recall 1 at precision 2/3 -> AP = 0.5 * 1 + 0.5 * 2/3.
  EXPECT_NEAR(average_precision({{0.9, true}, {0.8, false}, {0.7, true}}, 2), 0.5 + 0.5 * 2.0 / 3, 1e-12);
  // The same detections in another input order: ranked by confidence.
  EXPECT_NEAR(average_precision({{0.7, true}, {0.9, true}, {0.8, false}}, 2), 0.5 + 0.5 * 2.0 / 3, 1e-12);
  // A miss first: precision envelope 2/3 from the start -> AP = 2/3.
  EXPECT_NEAR(average_precision({{0.9, false}, {0.8, true}, {0.7, true}}, 2), 2.0 / 3, 1e-12);
  // Perfect, and half the positives never found.
  EXPECT_NEAR(average_precision({{0.5, true}, {0.4, true}}, 2), 1.0, 1e-12);
  EXPECT_NEAR(average_precision({{0.5, true}}, 2), 0.5, 1e-12);
  EXPECT_EQ(average_precision({}, 3), 0.0);
  EXPECT_TRUE(std::isnan(average_precision({{0.5, false}}, 0)));
}

BenchLabel target_at(double x, double y, double side) {
  BenchLabel l;
  l.in_view = true;
  l.has_corners = true;
  l.corners = {Eigen::Vector2d(x, y), Eigen::Vector2d(x + side, y), Eigen::Vector2d(x + side, y + side),
               Eigen::Vector2d(x, y + side)};
  l.box_min = {x, y};
  l.box_max = {x + side, y + side};
  l.inside_fraction = 1;
  l.visible_fraction = 1;
  return l;
}

MarkerDetection detection(double x, double y, double side, double confidence, int id = 0) {
  MarkerDetection d;
  d.box_min = {x, y};
  d.box_max = {x + side, y + side};
  d.confidence = confidence;
  d.id = id;
  return d;
}

TEST(BenchRole, PositiveIgnoredOrNone) {
  BenchLabel l = target_at(100, 100, 40);
  EXPECT_EQ(bench_role(l), TargetRole::Positive);
  l.visible_fraction = 0.5;  // mostly hidden by an object
  EXPECT_EQ(bench_role(l), TargetRole::Ignored);
  l = target_at(100, 100, 6);  // smaller than 8 px a side
  EXPECT_EQ(bench_role(l), TargetRole::Ignored);
  l = target_at(100, 100, 40);
  l.inside_fraction = 0.5;  // half out of the image
  EXPECT_EQ(bench_role(l), TargetRole::Ignored);
  l.in_view = false;
  EXPECT_EQ(bench_role(l), TargetRole::None);
}

TEST(ScoreFrame, OneHitPerTargetByIoUAndIdOthersAreFalsePositives) {
  const BenchLabel l = target_at(100, 100, 40);
  // IoU of a 40 px box shifted by 10 px: 30·40 / (2·1600 − 1200) = 0.6 → hit;
  // shifted by 20 px: 20·40 / 2400 = 0.33 → a false positive.
  const BenchFrame f = score_frame(l,
                                   {detection(110, 100, 40, 0.8), detection(100, 100, 40, 0.9),
                                    detection(120, 100, 40, 0.95), detection(100, 100, 40, 0.99, 7)},
                                   0);
  ASSERT_EQ(f.detections.size(), 3u) << "the id-7 detection is another marker's, not scored";
  // Highest confidence first: 0.95 (IoU 0.33: false), 0.9 (hit), 0.8 (a second match: false).
  EXPECT_FALSE(f.detections[0].hit);
  EXPECT_TRUE(f.detections[1].hit);
  EXPECT_FALSE(f.detections[2].hit);
  const BenchFigures b = bench_figures({&f}, 0.85);
  EXPECT_EQ(b.positives, 1);
  EXPECT_EQ(b.hits, 1);
  EXPECT_EQ(b.false_positives, 1);
  EXPECT_NEAR(b.recall(), 1.0, 1e-12);
  EXPECT_NEAR(b.precision(), 0.5, 1e-12);
}

TEST(ScoreFrame, DetectionsOfAnIgnoredTargetCostNothing) {
  BenchLabel l = target_at(100, 100, 40);
  l.visible_fraction = 0.4;
  const BenchFrame f = score_frame(l, {detection(100, 100, 40, 0.9), detection(300, 300, 40, 0.9)}, 0);
  EXPECT_EQ(f.role, TargetRole::Ignored);
  ASSERT_EQ(f.detections.size(), 1u);
  EXPECT_FALSE(f.detections[0].hit);  // the one elsewhere is a false positive
}

TEST(ReadBenchLabels, ErrorsNameTheFileLineAndKey) {
  touchdown::test::TempDir dir;
  const auto path = dir.path() / "labels.jsonl";
  std::ofstream(path)
      << R"({"image":"images/000000.png","split":"test","weather":"fog","phase":"search",)"
      << R"("distance":9.5,"target":{"in_view":true,"corners":[[1,2],[3,2],[3,4],[1,4]],)"
      << R"("box":[1,2,3,4],"inside_fraction":1,"visible_fraction":1},"distractors":[{"in_view":true}]})"
      << "\n"
      << R"({"image":"images/000001.png","split":"test"})"
      << "\n";
  try {
    (void)read_bench_labels(path);
    ADD_FAILURE() << "a line without its keys was read";
  } catch (const ParseError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("labels.jsonl:2: weather"), std::string::npos) << m;
  }
  std::ofstream(path) << R"({"image":"../x.png","split":"test","weather":"fog","phase":"search",)"
                      << R"("distance":9.5,"target":{"in_view":false,"corners":[],)"
                      << R"("box":[0,0,0,0],"inside_fraction":0,"visible_fraction":0},"distractors":[]})"
                      << "\n";
  EXPECT_THROW(read_bench_labels(path), ParseError);
  std::ofstream(path) << "{not json\n";
  EXPECT_THROW(read_bench_labels(path), ParseError);
  EXPECT_THROW(read_bench_labels(dir.path() / "none.jsonl"), IoError);
}

TEST(ReadBenchLabels, ReadsWhatTheDatasetWrites) {
  touchdown::test::TempDir dir;
  const auto path = dir.path() / "labels.jsonl";
  std::ofstream(path) << R"({"image":"images/000000.png","split":"test","weather":"fog","phase":"search",)"
                      << R"("distance":9.5,"target":{"in_view":true,"corners":[[1,2],[3,2],[3,4],[1,4]],)"
                      << R"("box":[1,2,3,4],"inside_fraction":1,"visible_fraction":0.75},)"
                      << R"("distractors":[{"in_view":true},{"in_view":false}]})"
                      << "\n";
  const auto l = read_bench_labels(path);
  ASSERT_EQ(l.size(), 1u);
  EXPECT_EQ(l[0].weather, "fog");
  EXPECT_EQ(l[0].distractors_in_view, 1);
  EXPECT_EQ(l[0].corners[2], Eigen::Vector2d(3, 4));
  EXPECT_EQ(l[0].box_max, Eigen::Vector2d(3, 4));
  EXPECT_DOUBLE_EQ(l[0].visible_fraction, 0.75);
  EXPECT_EQ(distance_band(l[0].distance), "6-10 m");
  EXPECT_EQ(visible_band(0.75), "0.6-0.8");
}

}  // namespace
}  // namespace touchdown::scenario
