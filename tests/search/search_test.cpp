// The campaign loop (search.hpp) with a fake evaluator whose outcome is a
// pure function of the scenario (no simulation): determinism, the results
// directory, resuming a killed campaign, refusing another campaign's
// directory, and the GA's elitism. The real evaluator's runs are checked in
// run_search_test.cpp.
#include "touchdown/search/search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::search {
namespace {

namespace fs = std::filesystem;

// Fog makes it miss the marker (Type II), a bird makes it collide (Type
// III), a distractor lures it (Type I); DTL and TTL grow with the fog.
Evaluation fake_evaluation(const scenario::Scenario& s) {
  Evaluation e;
  e.time_limit = s.time_limit;
  e.dtl = 10 * s.weather.fog + 0.01 * s.marker.position.norm();
  e.ttl = 20 + 100 * s.weather.fog;
  bool bird = false;
  for (const auto& o : s.dynamic_objects) bird = bird || o.kind == scenario::DynamicKind::Bird;
  if (s.weather.fog > 0.25) {
    e.violation = scenario::Violation::TypeII;
    e.ttl = s.time_limit;
  } else if (bird) {
    e.violation = scenario::Violation::TypeIII;
  } else if (s.distractors.size() >= 3) {
    e.violation = scenario::Violation::TypeI;
    e.dtl = 3;
  }
  e.reward_sum = static_cast<double>(s.dynamic_objects.size());
  e.message = "fake";
  e.cells = {{static_cast<int>(s.marker.position.x() / 2), 0, 1}};
  return e;
}

// Calls on_done in reverse order (as threads may finish), and throws after
// `fail_after` evaluations (a killed campaign).
class FakeEvaluator final : public Evaluator {
 public:
  int fail_after = -1;
  int evaluated = 0;
  std::chrono::milliseconds pause{0};  // per batch: a stand-in for the runs' time
  std::vector<Evaluation> evaluate(const std::vector<scenario::Scenario>& scenarios,
                                   const std::function<void(std::size_t, const Evaluation&)>& on_done) override {
    std::vector<Evaluation> out(scenarios.size());
    std::this_thread::sleep_for(pause);
    for (std::size_t k = scenarios.size(); k-- > 0;) {
      if (fail_after >= 0 && evaluated >= fail_after) throw std::runtime_error("killed");
      out[k] = fake_evaluation(scenarios[k]);
      ++evaluated;
      if (on_done) on_done(k, out[k]);
    }
    return out;
  }
};

class SearchDir : public ::testing::Test {
 protected:
  test::TempDir tmp_;
  const fs::path& root_ = tmp_.path();
};

SearchOptions small(Method m) {
  SearchOptions o;
  o.method = m;
  o.budget = 30;
  o.ga.population = 6;
  o.seed = 7;
  return o;
}

TEST_F(SearchDir, SameSeedSameResultsFileForEveryMethod) {
  for (Method m : {Method::Rlaga, Method::DiverseGa, Method::ManyObjectiveGa, Method::Random}) {
    FakeEvaluator a, b;
    const SearchResult ra = run_search(small(m), a, root_ / (std::string(to_string(m)) + "-a"), false);
    const SearchResult rb = run_search(small(m), b, root_ / (std::string(to_string(m)) + "-b"), false);
    ASSERT_EQ(ra.records.size(), 30u) << to_string(m);
    EXPECT_EQ(test::read_text(root_ / (std::string(to_string(m)) + "-a") / "results.jsonl"),
              test::read_text(root_ / (std::string(to_string(m)) + "-b") / "results.jsonl"))
        << to_string(m);
    EXPECT_EQ(a.evaluated, 30);
    for (std::size_t i = 0; i < ra.records.size(); ++i) {
      EXPECT_EQ(ra.records[i].index, static_cast<int>(i));
      EXPECT_EQ(ra.records[i].generation, static_cast<int>(i) / 6);
      EXPECT_TRUE(fs::exists(root_ / (std::string(to_string(m)) + "-a") / ra.records[i].scenario));
    }
    // Another seed searches elsewhere.
    SearchOptions other = small(m);
    other.seed = 8;
    FakeEvaluator c;
    const SearchResult rc = run_search(other, c, root_ / (std::string(to_string(m)) + "-c"), false);
    EXPECT_NE(rc.records[0].genes, ra.records[0].genes);
  }
}

// The time inside the evaluator is told apart from the search's own work:
// 5 batches of at least 20 ms each are inside, the rest is the search's.
TEST_F(SearchDir, EvaluationTimeIsToldApartFromTheSearchsOwnWork) {
  FakeEvaluator e;
  e.pause = std::chrono::milliseconds(20);
  const SearchResult r = run_search(small(Method::DiverseGa), e, root_ / "c", false);
  EXPECT_GE(r.evaluation_s, 5 * 0.020);
  EXPECT_LE(r.evaluation_s, r.wall_s);
  EXPECT_GE(r.search_s(), 0.0);
  EXPECT_DOUBLE_EQ(r.search_s(), r.wall_s - r.evaluation_s);
  // Resumed to the end: nothing runs, so nothing is inside the evaluator.
  FakeEvaluator again;
  again.pause = std::chrono::milliseconds(20);
  const SearchResult resumed = run_search(small(Method::DiverseGa), again, root_ / "c", true);
  EXPECT_EQ(resumed.resumed, 30);
  EXPECT_EQ(resumed.evaluation_s, 0.0);
}

TEST_F(SearchDir, ScenarioFilesDecodeTheRecordedGenes) {
  FakeEvaluator e;
  const SearchOptions o = small(Method::Rlaga);
  const SearchResult r = run_search(o, e, root_ / "c", false);
  const ChromosomeLayout layout = search_layout(o);
  for (const auto& rec : r.records) {
    const scenario::Scenario s = scenario::load_scenario(root_ / "c" / rec.scenario);
    EXPECT_EQ(layout.normalised(layout.encode(s)), rec.genes) << rec.index;
    // rlaga: every dynamic object is the DQN's.
    for (const auto& obj : s.dynamic_objects) EXPECT_EQ(obj.motion, scenario::MotionKind::External);
    EXPECT_EQ(rec.evaluation.dtl, fake_evaluation(s).dtl);
    EXPECT_EQ(rec.fitness, fitness_eq6(rec.evaluation, o.violation_radius));
  }
}

// A directory kept without its scenario files (docs/results/table2 keeps
// only campaign.json, state.json and results.jsonl) gets them back, byte for
// byte, when resumed, and nothing is run again.
TEST_F(SearchDir, ResumingWritesMissingScenarioFilesBack) {
  FakeEvaluator e;
  const SearchOptions o = small(Method::Rlaga);
  (void)run_search(o, e, root_ / "c", false);
  const std::string first = test::read_text(root_ / "c" / "scenarios" / "000000.yaml");
  const std::string last = test::read_text(root_ / "c" / "scenarios" / "000029.yaml");
  fs::remove_all(root_ / "c" / "scenarios");
  FakeEvaluator again;
  const SearchResult r = run_search(o, again, root_ / "c", true);
  EXPECT_EQ(again.evaluated, 0);
  EXPECT_EQ(r.resumed, 30);
  EXPECT_EQ(test::read_text(root_ / "c" / "scenarios" / "000000.yaml"), first);
  EXPECT_EQ(test::read_text(root_ / "c" / "scenarios" / "000029.yaml"), last);
  // A campaign killed mid-generation and kept the same way resumes to the
  // same results file.
  FakeEvaluator killed;
  killed.fail_after = 14;
  EXPECT_THROW(run_search(o, killed, root_ / "k", false), std::runtime_error);
  fs::remove_all(root_ / "k" / "scenarios");
  FakeEvaluator rest;
  (void)run_search(o, rest, root_ / "k", true);
  EXPECT_EQ(test::read_text(root_ / "k" / "results.jsonl"), test::read_text(root_ / "c" / "results.jsonl"));
  EXPECT_EQ(test::read_text(root_ / "k" / "scenarios" / "000029.yaml"), last);
}

TEST_F(SearchDir, TheGaIsElitistAndFindsMoreThanItsSeedPool) {
  FakeEvaluator e;
  SearchOptions o = small(Method::DiverseGa);
  o.budget = 60;
  const SearchResult r = run_search(o, e, root_ / "c", false);
  double best_pool = -1;
  for (int i = 0; i < 6; ++i) best_pool = std::max(best_pool, r.records[static_cast<std::size_t>(i)].fitness);
  double best_last = -1;
  for (const auto& rec : r.records) best_last = std::max(best_last, rec.fitness);
  EXPECT_GE(best_last, best_pool);
  const ResultsDirectory d = load_results_directory(root_ / "c");
  EXPECT_EQ(d.records.size(), 60u);
  EXPECT_NE(d.campaign_json.find("\"diverse-ga\""), std::string::npos);
}

TEST_F(SearchDir, AKilledCampaignResumesToTheSameResultsFile) {
  for (Method m : {Method::Rlaga, Method::ManyObjectiveGa, Method::Random}) {
    const std::string name(to_string(m));
    FakeEvaluator whole;
    (void)run_search(small(m), whole, root_ / (name + "-whole"), false);
    for (int kill : {3, 6, 14, 29}) {  // mid seed pool, after it, mid generation, before the last
      const fs::path dir = root_ / (name + "-killed-" + std::to_string(kill));
      FakeEvaluator killed;
      killed.fail_after = kill;
      EXPECT_THROW(run_search(small(m), killed, dir, false), std::runtime_error);
      const std::string partial = test::read_text(dir / "results.jsonl");
      const int written = static_cast<int>(std::count(partial.begin(), partial.end(), '\n'));
      // Lines are written in index order: a run finished before its
      // predecessors waits for them (and is lost with the kill).
      EXPECT_EQ(partial, test::read_text(root_ / (name + "-whole") / "results.jsonl").substr(0, partial.size()));
      FakeEvaluator rest;
      const SearchResult r = run_search(small(m), rest, dir, true);
      EXPECT_EQ(test::read_text(dir / "results.jsonl"), test::read_text(root_ / (name + "-whole") / "results.jsonl"))
          << name << " " << kill;
      EXPECT_EQ(r.records.size(), 30u);
      // What was written is not run again.
      EXPECT_EQ(r.resumed, written) << name << " " << kill;
      EXPECT_EQ(rest.evaluated, 30 - written) << name << " " << kill;
    }
  }
}

TEST_F(SearchDir, ACutLastLineIsRunAgain) {
  FakeEvaluator whole;
  (void)run_search(small(Method::Random), whole, root_ / "whole", false);
  const fs::path dir = root_ / "cut";
  FakeEvaluator killed;
  killed.fail_after = 10;
  EXPECT_THROW(run_search(small(Method::Random), killed, dir, false), std::runtime_error);
  {
    std::ofstream f(dir / "results.jsonl", std::ios::binary | std::ios::app);
    f << "{\"index\": 10, \"gener";  // the kill came mid-write
  }
  FakeEvaluator rest;
  (void)run_search(small(Method::Random), rest, dir, true);
  EXPECT_EQ(test::read_text(dir / "results.jsonl"), test::read_text(root_ / "whole" / "results.jsonl"));
}

TEST_F(SearchDir, RefusesAnotherCampaignsDirectoryAndOverwritesNothing) {
  FakeEvaluator e;
  const fs::path dir = root_ / "c";
  (void)run_search(small(Method::DiverseGa), e, dir, false);
  const std::string before = test::read_text(dir / "results.jsonl");
  // Without --resume: the directory holds a campaign.
  try {
    (void)run_search(small(Method::DiverseGa), e, dir, false);
    FAIL();
  } catch (const InvalidArgument& x) {
    EXPECT_NE(std::string(x.what()).find("holds a campaign already"), std::string::npos) << x.what();
  }
  // --resume with other options: the key that differs is named.
  SearchOptions other = small(Method::DiverseGa);
  other.seed = 99;
  try {
    (void)run_search(other, e, dir, true);
    FAIL();
  } catch (const InvalidArgument& x) {
    EXPECT_NE(std::string(x.what()).find("another campaign: seed:"), std::string::npos) << x.what();
  }
  other = small(Method::Random);
  EXPECT_THROW(run_search(other, e, dir, true), InvalidArgument);
  EXPECT_EQ(test::read_text(dir / "results.jsonl"), before);
  // A directory without a campaign cannot be resumed.
  EXPECT_THROW(run_search(small(Method::DiverseGa), e, root_ / "empty", true), InvalidArgument);
}

TEST(SearchOptions, BadOptionsAreRefusedNamingTheKey) {
  SearchOptions o;
  std::string why;
  EXPECT_TRUE(o.validate(&why)) << why;
  EXPECT_EQ(o.generations(), 15);
  o.budget = 19;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("budget: 19 is less than the population (20)"), std::string::npos) << why;
  o.budget = 21;
  EXPECT_TRUE(o.validate(&why));
  EXPECT_EQ(o.generations(), 2);
  FakeEvaluator e;
  o.budget = 5;
  EXPECT_THROW(run_search(o, e, fs::temp_directory_path() / "td_search_never", false), InvalidArgument);
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "td_search_never"));
}

TEST(Method, NamesRoundTrip) {
  for (Method m : {Method::Rlaga, Method::DiverseGa, Method::ManyObjectiveGa, Method::Random}) {
    EXPECT_EQ(from_string<Method>(to_string(m)), m);
  }
  EXPECT_THROW(from_string<Method>("hill-climbing"), InvalidArgument);
}

}  // namespace
}  // namespace touchdown::search
