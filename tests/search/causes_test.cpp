// Issue 52 in the search: the facts a record carries (round trip, old
// records still read, bad facts refused), the fair and raw metrics of a
// hand-made results file, a cause label for a hand-built violation of each
// kind, and the distinct causes of a results file.
#include "touchdown/search/causes.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/records.hpp"

namespace {

namespace ts = touchdown::search;
namespace sc = touchdown::scenario;
using sc::Violation;

ts::Evaluation violation(Violation v) {
  ts::Evaluation e;
  e.violation = v;
  e.message = "hand-made";
  e.facts.recorded = true;
  e.facts.sighting_time = 5;
  e.facts.longest_s = 8;
  e.facts.probe_longest_s = 20;
  e.facts.observable_s = 9;
  e.facts.probe_observable_s = 20;
  return e;
}

sc::Scenario scene() {
  sc::Scenario s;
  s.marker.position = {0, 0};
  return s;
}

TEST(Causes, CollisionNamesTheObjectAndThePhase) {
  ts::Evaluation e = violation(Violation::TypeIII);
  e.facts.collided_with = "static_objects[1] (pole)";
  e.facts.collision_phase = "descend";
  EXPECT_EQ(ts::violation_cause(e, scene()), "collision with pole while descending");
  e.facts.collided_with = "dynamic_objects[0] (bird)";
  e.facts.collision_phase = "search";
  EXPECT_EQ(ts::violation_cause(e, scene()), "collision with bird while searching");
  for (const auto& [phase, words] : std::vector<std::pair<std::string, std::string>>{
           {"approach", " while approaching"},
           {"track", " while tracking"},
           {"land", " while landing"},
           {"descent", " while descending"},          // a synonym of descend
           {"hover", " during hover"},                // a phase a system from outside names
           {"replan-climb", " during replan-climb"},  // mm-mls's own
           {"", ""}}) {
    e.facts.collision_phase = phase;
    EXPECT_EQ(ts::violation_cause(e, scene()), "collision with bird" + words) << phase;
  }
}

TEST(Causes, TypeINamesWhatWasTakenForTheTarget) {
  ts::Evaluation e = violation(Violation::TypeI);
  sc::Scenario s = scene();
  e.facts.trigger = "distractors[0] (lookalike)";
  EXPECT_EQ(ts::violation_cause(e, s), "look-alike accepted");
  e.facts.trigger = "distractors[2] (wrong_id)";
  EXPECT_EQ(ts::violation_cause(e, s), "wrong id accepted");
  e.facts.trigger = "distractors[1] (pattern)";
  EXPECT_EQ(ts::violation_cause(e, s), "false positive on pattern");
  e.facts.trigger = "static_objects[0] (box)";
  EXPECT_EQ(ts::violation_cause(e, s), "false positive on box");
  e.facts.trigger = "ground";
  EXPECT_EQ(ts::violation_cause(e, s), "false positive on the ground");
  s.weather.ground_wetness = 0.8;
  EXPECT_EQ(ts::violation_cause(e, s), "false positive on the ground (glare)");
  e.facts.trigger = "marker";  // committed on the target, pulled off by earlier false sightings
  e.facts.false_detection = true;
  EXPECT_EQ(ts::violation_cause(e, s), "estimate pulled off by false detections");
  // Committed on the target and re-aimed on the way down by a look-alike.
  e.facts.descent_started = true;
  e.facts.descent_target = {0.2, 0.1};
  e.facts.last_accepted = "distractors[1] (lookalike)";
  EXPECT_EQ(ts::violation_cause(e, s), "look-alike accepted while descending");
  e.facts.last_accepted = "ground";
  EXPECT_EQ(ts::violation_cause(e, s), "false positive on the ground (glare) while descending");
  // Aimed off before it: the estimate was pulled off, whatever came last.
  e.facts.descent_target = {4.0, 0.0};
  EXPECT_EQ(ts::violation_cause(e, s), "estimate pulled off by false detections");
}

TEST(Causes, OffMarkerLandings) {
  ts::Evaluation e = violation(Violation::OffMarker);
  EXPECT_EQ(ts::violation_cause(e, scene()), "blind landing (no detection)");
  e.facts.trigger = "marker";
  e.facts.descent_started = true;
  e.facts.descent_target = {0.3, 0.1};
  EXPECT_EQ(ts::violation_cause(e, scene()), "drift off the marker after a true detection");
  e.facts.descent_target = {3.0, 0.0};
  EXPECT_EQ(ts::violation_cause(e, scene()), "descent aimed off a true detection");
}

TEST(Causes, FairNoLandings) {
  sc::Scenario fog = scene();
  fog.weather.fog = 0.15;
  ts::Evaluation e = violation(Violation::TypeII);
  e.facts.fair = true;
  // The system's own camera never had it; the probe did: no search.
  e.facts.observable_s = 0;
  e.facts.longest_s = 0;
  EXPECT_EQ(ts::violation_cause(e, fog), "target never brought into view in fog");
  EXPECT_EQ(ts::violation_cause(e, scene()), "target never brought into view in clear");
  // In view long enough, nothing accepted.
  e.facts.observable_s = e.facts.longest_s = 12;
  EXPECT_EQ(ts::violation_cause(e, fog), "observable target not detected in fog");
  e.facts.last_accepted = "marker";
  EXPECT_EQ(ts::violation_cause(e, fog), "sighting not held in fog");
  // A descent that a person walking under it interrupted.
  e.facts.descent_started = true;
  e.facts.occluders = {{"dynamic_objects[0] (person)", 20, 23, 30, 25}};
  EXPECT_EQ(ts::violation_cause(e, scene()), "person between camera and target during descent");
  e.facts.occluders.clear();
  EXPECT_EQ(ts::violation_cause(e, fog), "descent not completed in fog");
}

TEST(Causes, UnfairNoLandingsSayWhyNoCameraCould) {
  ts::Evaluation e = violation(Violation::TypeII);
  e.facts.fair = false;
  e.facts.longest_s = e.facts.probe_longest_s = 0;
  sc::Scenario s = scene();
  s.weather.ground_snow = 0.9;
  e.facts.probe_failure = "covered";
  EXPECT_EQ(ts::violation_cause(e, s), "unfair: target covered by ground snow");
  s.weather.ground_snow = 0;
  s.weather.ground_leaves = 0.7;
  EXPECT_EQ(ts::violation_cause(e, s), "unfair: target covered by ground leaves");
  // Wrong cells with nothing on the ground: named after the weather in the air.
  sc::Scenario falling = scene();
  falling.weather.snow = 0.6;
  EXPECT_EQ(ts::violation_cause(e, falling), "unfair: target not readable in snowfall");
  sc::StaticObject box;
  box.kind = sc::StaticKind::Box;
  box.position = {0.3, 0};
  s.static_objects = {box};
  e.facts.probe_failure = "hidden";
  EXPECT_EQ(ts::violation_cause(e, s), "unfair: target hidden by box");
  sc::Scenario fog = scene();
  fog.weather.fog = 0.34;
  e.facts.probe_failure = "low-contrast";
  EXPECT_EQ(ts::violation_cause(e, fog), "unfair: target not visible in fog");
  // Snow on the ground reads as one colour too: in clear air it is the cover,
  // in thick fog the fog (lawn11 of the README has both, fog 0.341).
  sc::Scenario snowed = scene();
  snowed.weather.ground_snow = 0.58;
  snowed.weather.rain = 0.81;
  EXPECT_EQ(ts::violation_cause(e, snowed), "unfair: target covered by ground snow");
  snowed.weather.fog = 0.341;
  EXPECT_EQ(ts::violation_cause(e, snowed), "unfair: target not visible in fog");
  EXPECT_FALSE(e.fair_violation());
}

TEST(Causes, DominantWeatherAndObjectKind) {
  sc::Weather w;
  EXPECT_EQ(ts::dominant_weather(w), "clear");
  w.fog = 0.05;  // half of the fog level that counts
  EXPECT_EQ(ts::dominant_weather(w), "clear");
  w.rain = 0.9;
  EXPECT_EQ(ts::dominant_weather(w), "rain");
  w.fog = 0.3;
  EXPECT_EQ(ts::dominant_weather(w), "fog");
  w = {};
  w.ambient = 0.2;
  EXPECT_EQ(ts::dominant_weather(w), "low light");
  EXPECT_EQ(ts::object_kind("static_objects[12] (tree)"), "tree");
  EXPECT_EQ(ts::object_kind("ground"), "ground");
}

ts::EvaluationRecord record(int index, ts::Evaluation e, std::vector<double> genes) {
  ts::EvaluationRecord r;
  r.index = index;
  r.scenario = "scenarios/" + std::to_string(index) + ".yaml";
  r.genes = std::move(genes);
  r.evaluation = std::move(e);
  return r;
}

// 6 runs: a fair Type I (index 1), an unfair Type II (2), a fair Type II (3),
// a collision (4), an off-marker landing (5); index 0 lands.
std::vector<ts::EvaluationRecord> hand_made() {
  ts::Evaluation ok = violation(Violation::None);
  ts::Evaluation type_i = violation(Violation::TypeI);
  type_i.facts.trigger = "distractors[0] (lookalike)";
  ts::Evaluation unfair = violation(Violation::TypeII);
  unfair.facts.fair = false;
  unfair.facts.probe_failure = "low-contrast";
  unfair.facts.longest_s = unfair.facts.probe_longest_s = 0;
  ts::Evaluation fair = violation(Violation::TypeII);
  fair.facts.observable_s = fair.facts.longest_s = 0;
  ts::Evaluation crash = violation(Violation::TypeIII);
  crash.facts.collided_with = "static_objects[0] (tree)";
  crash.facts.collision_phase = "search";
  crash.facts.occluders = {{"static_objects[0] (tree)", 1.5, 2.25, 4, 0}};
  crash.facts.nearest_object = "static_objects[0] (tree)";
  crash.facts.nearest_t = 2.5;
  crash.facts.nearest_phase = "search";
  ok.facts.nearest_object = "dynamic_objects[0] (dog)";
  ok.facts.nearest_m = 0.75;
  ok.facts.nearest_t = 21.5;
  ok.facts.nearest_phase = "descend";
  ts::Evaluation off = violation(Violation::OffMarker);
  off.facts.trigger = "marker";
  return {record(0, ok, {0.5, 0.5}), record(1, type_i, {0, 0}), record(2, unfair, {1, 1}),
          record(3, fair, {1, 0}),   record(4, crash, {0, 1}),  record(5, off, {0.5, 0})};
}

std::vector<ts::EvaluationRecord> through_a_file(const std::vector<ts::EvaluationRecord>& written) {
  const touchdown::test::TempDir dir;
  const auto path = dir / "results.jsonl";
  {
    std::ofstream out(path, std::ios::binary);
    for (const auto& r : written) out << ts::record_line(r) << '\n';
  }
  return ts::load_records(path);
}

TEST(FairMetrics, HandMadeResultsFile) {
  const auto records = through_a_file(hand_made());
  ASSERT_EQ(records.size(), 6u);
  // The facts survive the file exactly.
  EXPECT_EQ(ts::record_line(records[4]), ts::record_line(hand_made()[4]));
  EXPECT_EQ(records[4].evaluation.facts.occluders.size(), 1u);
  EXPECT_EQ(records[4].evaluation.facts.occluders[0].last_t, 2.25);
  EXPECT_EQ(ts::record_line(records[0]), ts::record_line(hand_made()[0]));
  EXPECT_EQ(records[0].evaluation.facts.nearest_object, "dynamic_objects[0] (dog)");
  EXPECT_EQ(records[0].evaluation.facts.nearest_m, 0.75);
  EXPECT_EQ(records[0].evaluation.facts.nearest_phase, "descend");
  EXPECT_EQ(records[4].evaluation.facts.nearest_m, 0.0);
  // A scene without objects writes no "nearest" and reads back without one.
  EXPECT_EQ(ts::record_line(records[1]).find("nearest"), std::string::npos);
  EXPECT_TRUE(records[1].evaluation.facts.nearest_object.empty());
  const ts::SearchMetrics raw = ts::compute_metrics(records, 2);
  EXPECT_EQ(raw.violations, 5);
  EXPECT_EQ(raw.type_i, 1);
  EXPECT_EQ(raw.type_ii, 2);
  EXPECT_EQ(raw.type_iii, 1);
  EXPECT_EQ(raw.off_marker, 1);
  EXPECT_EQ(raw.unfair, 1);
  EXPECT_EQ(*raw.top_k, 3);  // the 2nd violation is the unfair one at index 2
  EXPECT_EQ(*raw.rounds_all_types, 5);
  const ts::SearchMetrics fair = ts::compute_metrics(records, 2, ts::Count::Fair);
  EXPECT_TRUE(fair.facts_recorded);
  EXPECT_EQ(fair.violations, 4);
  EXPECT_EQ(fair.type_ii, 1);
  EXPECT_EQ(fair.unfair, 1);
  EXPECT_DOUBLE_EQ(fair.violation_percent, 100.0 * 4 / 6);
  EXPECT_EQ(*fair.top_k, 4);  // index 1, then the fair Type II at index 3
  // eq. 7 over the 4 fair violations' genes (0,0), (1,0), (0,1), (0.5,0):
  // pairs 1, 1, 0.5, sqrt 2, 0.5, sqrt 1.25; mean over sqrt 2.
  const double pairs = 1 + 1 + 0.5 + std::sqrt(2.0) + 0.5 + std::sqrt(1.25);
  EXPECT_NEAR(fair.parameter_distance, pairs / 6 / std::sqrt(2.0), 1e-15);
  EXPECT_EQ(ts::cumulative_violations(records, ts::Count::Fair), (std::vector<int>{0, 1, 1, 2, 3, 4}));
  EXPECT_EQ(ts::cumulative_violations(records), (std::vector<int>{0, 1, 2, 3, 4, 5}));
}

TEST(FairMetrics, OldResultsReadWithoutFacts) {
  // A line written before issue 52 (the fuzz seed's): no "facts" key.
  const std::string old =
      R"({"index":0,"generation":0,"scenario":"scenarios/000000.yaml","fitness":1.5,"genes":[0.5],)"
      R"("evaluation":{"violation":"II","message":"Type II: did not land in 60 s","dtl":3.25,"ttl":60,)"
      R"("time_limit":60,"landed":false,"collided":false,"reward_sum":12.5,"frames":1800,"flight_s":60,"cells":[]}})";
  const ts::EvaluationRecord r = ts::parse_record_line(old, "old.jsonl", 1);
  EXPECT_FALSE(r.evaluation.facts.recorded);
  EXPECT_TRUE(r.evaluation.fair_violation()) << "without facts every violation counts";
  EXPECT_EQ(ts::record_line(r), old) << "written back as it was";
  const ts::SearchMetrics fair = ts::compute_metrics({r}, 10, ts::Count::Fair);
  EXPECT_FALSE(fair.facts_recorded);
  EXPECT_EQ(fair.violations, 1);
  EXPECT_EQ(ts::violation_cause(r.evaluation, sc::Scenario{}), "unknown (no facts recorded)");
}

TEST(FairMetrics, BadFactsAreRefusedNamingTheKey) {
  std::string line = ts::record_line(hand_made()[4]);
  auto refused = [](const std::string& text, const std::string& key) {
    try {
      (void)ts::parse_record_line(text, "r.jsonl", 3);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const touchdown::ParseError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("r.jsonl:3"), std::string::npos) << e.what();
    }
  };
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = line;
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  refused(replaced("\"fair\":true", "\"fair\":1"), "evaluation.facts.fair");
  refused(replaced("\"probe_failure\":\"observable\"", "\"probe_failure\":\"blurry\""),
          "evaluation.facts.probe_failure");
  refused(replaced("\"frames\":4,", "\"frames\":0,"), "evaluation.facts.occluders[0].frames");
  refused(replaced("\"last_t\":2.25", "\"last_t\":1"), "evaluation.facts.occluders[0].last_t");
  refused(replaced("\"collision_phase\":", "\"extra\":1,\"collision_phase\":"), "evaluation.facts.extra");
  refused(replaced("\"descent_target\":[0,0]", "\"descent_target\":[0]"), "evaluation.facts.descent_target");
  refused(replaced("\"nearest\":{\"object\":\"static_objects[0] (tree)\"", "\"nearest\":{\"object\":\"\""),
          "evaluation.facts.nearest.object");
  refused(replaced("\"m\":0,", "\"m\":-1,"), "evaluation.facts.nearest.m");
  refused(replaced("\"phase\":\"search\"}", "\"phase\":\"search\",\"x\":1}"), "evaluation.facts.nearest.x");
  refused(replaced("\"nearest\":{", "\"nearest\":7,\"z\":{"), "evaluation.facts.nearest: expected an object");
}

TEST(CountCauses, DistinctCausesWithCountsAndAnExample) {
  auto records = hand_made();
  // A second look-alike landing: the same cause again.
  ts::Evaluation again = records[1].evaluation;
  records.push_back(record(6, again, {0.2, 0.2}));
  const std::vector<sc::Scenario> scenes(records.size(), scene());
  const std::vector<ts::CauseCount> causes = ts::count_causes(records, scenes);
  ASSERT_EQ(causes.size(), 5u);
  EXPECT_EQ(causes[0].cause, "look-alike accepted");
  EXPECT_EQ(causes[0].count, 2);
  EXPECT_EQ(causes[0].first_index, 1);
  EXPECT_EQ(causes[0].scenario, "scenarios/1.yaml");
  EXPECT_TRUE(causes[0].fair);
  EXPECT_EQ(causes.back().cause, "unfair: target not visible in clear");
  EXPECT_FALSE(causes.back().fair);
  EXPECT_EQ(ts::distinct_fair_causes(causes), 4);
  EXPECT_THROW((void)ts::count_causes(records, {}), touchdown::InvalidArgument);
}

}  // namespace
