// The search with real runs: the local evaluator gives the same
// evaluations for any thread count and agrees with a single run_scenario
// (DQN-driven objects included), and shrink() names what a hand-built
// Type II needs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "scenario/plugins/gps_lander.hpp"
#include "test_util.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/object_policy.hpp"
#include "touchdown/search/search.hpp"
#include "touchdown/search/shrink.hpp"

namespace touchdown::search {
namespace {

namespace fs = std::filesystem;

EvaluatorOptions small_camera(int threads) {
  EvaluatorOptions o;
  o.run.camera.width = 320;
  o.run.camera.height = 240;
  o.threads = threads;
  return o;
}

std::shared_ptr<const QNetwork> some_network() {
  auto net = std::make_shared<QNetwork>();
  Rng rng(5);
  net->initialise(rng);
  return net;
}

TEST(LocalEvaluator, SameResultsFileForOneAndTwoThreads) {
  SearchOptions o;
  o.method = Method::Rlaga;
  o.budget = 4;
  o.ga.population = 2;
  o.seed = 3;
  o.base.time_limit = 10;
  o.weights_id = "test";
  const test::TempDir dir;  // its own directory: ctest -j runs tests side by side
  const fs::path& root = dir.path();
  EvaluatorOptions one = small_camera(1), two = small_camera(2);
  one.policy = two.policy = some_network();
  LocalEvaluator e1(one);
  // The registry's `local` is the same evaluator, named.
  const std::unique_ptr<Evaluator> e2 = evaluator_registry().get("local").factory(two);
  EXPECT_TRUE(e2->coordinator());
  const SearchResult r1 = run_search(o, e1, root / "one", false);
  const SearchResult r2 = run_search(o, *e2, root / "two", false);
  ASSERT_EQ(r1.records.size(), 4u);
  EXPECT_EQ(test::read_text(root / "one" / "results.jsonl"), test::read_text(root / "two" / "results.jsonl"));
  // A record is the run of its scenario file, objects driven by the policy.
  const scenario::Scenario s = scenario::load_scenario(root / "one" / r1.records[3].scenario);
  auto system = scenario::make_landing_system("opencv-mls");
  scenario::RunOptions run = one.run;
  run.external = ObjectPolicy(one.policy, one.decision_period);
  const Evaluation single = evaluate_result(scenario::run_scenario(s, *system, run), s.time_limit);
  EXPECT_EQ(single.message, r1.records[3].evaluation.message);
  EXPECT_EQ(single.dtl, r1.records[3].evaluation.dtl);
  EXPECT_EQ(single.reward_sum, r1.records[3].evaluation.reward_sum);
  EXPECT_EQ(single.cells, r1.records[3].evaluation.cells);
}

TEST(EvaluatorRegistry, NamesTheBuiltInAndRefusesAnUnknownOne) {
  EXPECT_TRUE(evaluator_registry().find("local").has_value());
  try {
    (void)evaluator_registry().get("cluster");
    FAIL() << "accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("evaluator: unknown 'cluster' (known: local"), std::string::npos) << e.what();
  }
  // Bad options are refused by the factory as by the constructor.
  EvaluatorOptions bad = small_camera(1);
  bad.decision_period = 0;
  EXPECT_THROW((void)evaluator_registry().get("local").factory(bad), InvalidArgument);
}

// A system under test that throws is a result: its runs are "system failed",
// no violation, scored 0 (a crash's TTL would otherwise rank it above every
// landing), counted apart, and the records read back.
TEST(LocalEvaluator, AFailingSystemScoresNothingAndIsNoViolation) {
  SearchOptions o;
  o.method = Method::DiverseGa;
  o.budget = 4;
  o.ga.population = 2;
  o.base.time_limit = 10;
  EvaluatorOptions e = small_camera(2);
  e.system = scenario::SystemFactory(
      "faulty", [](const scenario::MlsOptions&) { return std::make_unique<test_plugin::GpsLander>("faulty", 0.5); });
  LocalEvaluator evaluator(e);
  const test::TempDir dir;
  const SearchResult r = run_search(o, evaluator, dir.path(), false);
  ASSERT_EQ(r.records.size(), 4u);
  for (const EvaluationRecord& rec : r.records) {
    EXPECT_TRUE(rec.evaluation.system_failed()) << rec.evaluation.message;
    EXPECT_FALSE(rec.evaluation.violation_found());
    EXPECT_EQ(rec.fitness, 0.0);
    EXPECT_NE(rec.evaluation.message.find("system failed: update() threw at t = 0.5"), std::string::npos)
        << rec.evaluation.message;
  }
  const std::vector<EvaluationRecord> read = load_records(dir.path() / "results.jsonl");
  ASSERT_EQ(read.size(), 4u);
  EXPECT_EQ(read[2].evaluation.violation, scenario::Violation::SystemFailed);
  const SearchMetrics m = compute_metrics(read);
  EXPECT_EQ(m.violations, 0);
  EXPECT_EQ(m.system_failed, 4);
  // campaign.json names the system that ran (the factory's name), and a
  // SearchOptions::system naming another is refused before anything runs.
  EXPECT_NE(test::read_text(dir.path() / "campaign.json").find("\"system\": \"faulty\""), std::string::npos);
  o.system = "opencv-mls";
  const test::TempDir other;
  try {
    (void)run_search(o, evaluator, other.path(), false);
    ADD_FAILURE() << "a system the evaluator does not run was accepted";
  } catch (const InvalidArgument& refused) {
    EXPECT_NE(std::string(refused.what()).find("system 'opencv-mls' is not the evaluator's system 'faulty'"),
              std::string::npos)
        << refused.what();
  }
  EXPECT_FALSE(std::filesystem::exists(other.path() / "results.jsonl"));
}

// A box over the marker hides it (Type II); light fog, rain, a far tree and
// a far walking person are beside the point. Shrinking must name the box
// alone and reset everything else.
TEST(Shrink, NamesExactlyTheBoxOverTheMarkerOfAHandBuiltTypeII) {
  scenario::Scenario s;  // the drone 8 m west of the marker at 12 m
  s.time_limit = 25;
  s.weather.fog = 0.02;
  s.weather.rain = 0.3;
  scenario::StaticObject box;
  box.kind = scenario::StaticKind::Box;
  box.position = s.marker.position;
  box.size = {1.8, 1.8, 0.4};
  scenario::StaticObject tree;
  tree.kind = scenario::StaticKind::Tree;
  tree.position = {12, 12};
  tree.size = {3, 0.4, 6};
  s.static_objects = {box, tree};
  scenario::DynamicObject person;
  person.position = {-10, 12};
  person.heading_deg = 90;
  s.dynamic_objects = {person};
  std::string why;
  ASSERT_TRUE(s.validate(&why)) << why;
  LocalEvaluator evaluator(small_camera(1));
  std::vector<int> progress;
  const ShrinkResult r = shrink(s, scenario::Scenario{}, evaluator,
                                [&](const Progress& p) { progress.push_back(static_cast<int>(p.done)); });
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.violation, scenario::Violation::TypeII) << r.message;
  EXPECT_EQ(r.necessary, std::vector<std::string>{"static_objects[0] (box)"});
  ASSERT_EQ(r.steps.size(), 5u);  // box, tree, person, fog, rain
  EXPECT_EQ(r.steps[0].gene, "static_objects[0] (box)");
  EXPECT_EQ(r.steps[0].outcome, scenario::Violation::None) << r.steps[0].message;
  EXPECT_EQ(r.runs(), 6);
  EXPECT_EQ(progress.back(), 6);
  // The smallest scenario: the box on a clear day, nothing else.
  EXPECT_EQ(r.smallest.static_objects.size(), 1u);
  EXPECT_EQ(r.smallest.static_objects[0].kind, scenario::StaticKind::Box);
  EXPECT_TRUE(r.smallest.dynamic_objects.empty());
  EXPECT_EQ(r.smallest.weather.fog, 0.0);
  EXPECT_EQ(r.smallest.weather.rain, 0.0);
  // ... and it still fails the same way (an independent run).
  auto system = scenario::make_landing_system("opencv-mls");
  scenario::RunOptions run = small_camera(1).run;
  EXPECT_EQ(scenario::run_scenario(r.smallest, *system, run).status, scenario::Violation::TypeII);
}

TEST(Shrink, AScenarioThatPassesHasNothingToShrink) {
  scenario::Scenario s;
  s.time_limit = 40;
  LocalEvaluator evaluator(small_camera(1));
  const ShrinkResult r = shrink(s, scenario::Scenario{}, evaluator);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.status, ShrinkStatus::NotViolating);
  EXPECT_TRUE(r.steps.empty());
  EXPECT_EQ(to_string(r.status), "not_violating");
}

}  // namespace
}  // namespace touchdown::search
