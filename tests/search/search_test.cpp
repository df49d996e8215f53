// The campaign loop (search.hpp) with a fake evaluator whose outcome is a
// pure function of the scenario (no simulation): determinism, the results
// directory, resuming a killed campaign, refusing another campaign's
// directory, and the GA's elitism. The real evaluator's runs are checked in
// run_search_test.cpp.
#include "touchdown/search/search.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "search/cover_pool.hpp"
#include "search/search_io.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/search/causes.hpp"
#include "touchdown/search/genetic.hpp"

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

// The same with the facts of issue 52: a run that would land, in a scene
// with an odd seed, is an unfair Type II (its marker never observable), a collision is with the bird while
// descending, a Type I was committed on the first distractor.
Evaluation fake_with_facts(const scenario::Scenario& s) {
  Evaluation e = fake_evaluation(s);
  if (e.violation == scenario::Violation::None && s.seed % 2 == 1) {
    e.violation = scenario::Violation::TypeII;
    e.ttl = s.time_limit;
  }
  e.facts.recorded = true;
  e.facts.sighting_time = 5;
  const bool unseen = s.seed % 2 == 1;
  e.facts.probe_longest_s = unseen ? 0 : 20;
  e.facts.probe_failure = unseen ? "low-contrast" : "observable";
  e.facts.fair = e.violation != scenario::Violation::TypeII || !unseen;
  if (e.violation == scenario::Violation::TypeIII) {
    e.facts.collided_with = "dynamic_objects[0] (bird)";
    e.facts.collision_phase = "descend";
  }
  if (e.violation == scenario::Violation::TypeI) {
    e.facts.trigger = "distractors[0] (" + std::string(scenario::to_string(s.distractors[0].kind)) + ")";
  }
  if (!s.dynamic_objects.empty()) {  // a stand-in clearance: a fifth of the first one's distance from the marker
    e.facts.nearest_object = "dynamic_objects[0] (" + std::string(scenario::to_string(s.dynamic_objects[0].kind)) + ")";
    e.facts.nearest_m = 0.2 * (s.dynamic_objects[0].position - s.marker.position).norm();
    e.facts.nearest_phase = "descend";
  }
  return e;
}

// Calls on_done in reverse order (as threads may finish), and throws after
// `fail_after` evaluations (a killed campaign).
class FakeEvaluator final : public Evaluator {
 public:
  int fail_after = -1;
  int evaluated = 0;
  bool facts = false;                  // fake_with_facts instead of fake_evaluation
  bool crowd = false;                  // with facts: a landing without a near miss is a fair Type II instead
  std::chrono::milliseconds pause{0};  // per batch: a stand-in for the runs' time
  bool flaky = false;                  // the system under test fails in every scenario whose seed is a multiple of 3
  std::vector<Evaluation> evaluate(const std::vector<scenario::Scenario>& scenarios,
                                   const std::function<void(std::size_t, const Evaluation&)>& on_done) override {
    std::vector<Evaluation> out(scenarios.size());
    std::this_thread::sleep_for(pause);
    for (std::size_t k = scenarios.size(); k-- > 0;) {
      if (fail_after >= 0 && evaluated >= fail_after) throw std::runtime_error("killed");
      out[k] = facts ? fake_with_facts(scenarios[k]) : fake_evaluation(scenarios[k]);
      if (crowd && out[k].violation == scenario::Violation::None && !(near_miss_term(out[k]) > 0)) {
        out[k].violation = scenario::Violation::TypeII;
        out[k].ttl = out[k].time_limit;
        out[k].facts.fair = true;
      }
      if (flaky && scenarios[k].seed % 3 == 0) {
        out[k] = Evaluation{};
        out[k].violation = scenario::Violation::SystemFailed;
        out[k].message = "system failed: update() threw at step 12: planted";
        out[k].time_limit = scenarios[k].time_limit;
        out[k].ttl = scenarios[k].time_limit;
      }
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
  if (m == Method::Rlaga) o.weights_id = "fake-dqn";  // FakeEvaluator moves nothing
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

// Runs whose system failed are results like any other: written, read back
// as failed (not as a landing), scored 0, and not run again on resume.
TEST_F(SearchDir, SystemFailedRunsAreKeptAndResumed) {
  FakeEvaluator whole;
  whole.flaky = true;
  const SearchResult w = run_search(small(Method::Rlaga), whole, root_ / "whole", false);
  int failed = 0;
  for (const auto& rec : w.records) {
    if (!rec.evaluation.system_failed()) continue;
    ++failed;
    EXPECT_EQ(rec.fitness, 0.0);
    EXPECT_FALSE(rec.evaluation.violation_found());
  }
  ASSERT_GT(failed, 0);
  ASSERT_LT(failed, 30);
  for (int kill : {5, 17}) {
    const fs::path dir = root_ / ("killed-" + std::to_string(kill));
    FakeEvaluator killed;
    killed.flaky = true;
    killed.fail_after = kill;
    EXPECT_THROW(run_search(small(Method::Rlaga), killed, dir, false), std::runtime_error);
    FakeEvaluator rest;
    rest.flaky = true;
    const SearchResult r = run_search(small(Method::Rlaga), rest, dir, true);
    EXPECT_EQ(test::read_text(dir / "results.jsonl"), test::read_text(root_ / "whole" / "results.jsonl")) << kill;
    EXPECT_EQ(rest.evaluated, 30 - r.resumed) << kill;
    int failed_again = 0;
    for (std::size_t i = 0; i < r.records.size(); ++i) {
      failed_again += r.records[i].evaluation.system_failed() ? 1 : 0;
      EXPECT_EQ(r.records[i].evaluation.message, w.records[i].evaluation.message) << kill << " " << i;
    }
    EXPECT_EQ(failed_again, failed) << kill;
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
  // Another learned model: a campaign never resumes on another detector.
  EXPECT_EQ(test::read_text(dir / "campaign.json").find("detector_model"), std::string::npos);
  other = small(Method::DiverseGa);
  other.detector_model = "fnv1a64:1234";
  try {
    (void)run_search(other, e, dir, true);
    FAIL();
  } catch (const InvalidArgument& x) {
    EXPECT_NE(std::string(x.what()).find("detector_model"), std::string::npos) << x.what();
  }
  EXPECT_EQ(test::read_text(dir / "results.jsonl"), before);
  // A directory without a campaign cannot be resumed.
  EXPECT_THROW(run_search(small(Method::DiverseGa), e, root_ / "empty", true), InvalidArgument);
}

SearchOptions diverse(Method m) {
  SearchOptions o = small(m);
  o.budget = 48;
  o.diversity = true;
  return o;
}

double distance(const std::vector<double>& a, const std::vector<double>& b) {
  double d2 = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d2 += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(d2 / static_cast<double>(a.size()));
}

double min_pairwise(const std::vector<EvaluationRecord>& r, std::size_t n) {
  double best = 1e9;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) best = std::min(best, distance(r[i].genes, r[j].genes));
  }
  return best;
}

TEST_F(SearchDir, DiversityIsDeterministicAndResumesToTheSameFile) {
  FakeEvaluator a, b;
  a.facts = b.facts = true;
  (void)run_search(diverse(Method::Rlaga), a, root_ / "a", false);
  (void)run_search(diverse(Method::Rlaga), b, root_ / "b", false);
  const std::string whole = test::read_text(root_ / "a" / "results.jsonl");
  EXPECT_EQ(whole, test::read_text(root_ / "b" / "results.jsonl"));
  for (int kill : {4, 13, 31}) {
    const fs::path dir = root_ / ("k" + std::to_string(kill));
    FakeEvaluator killed;
    killed.facts = true;
    killed.fail_after = kill;
    EXPECT_THROW(run_search(diverse(Method::Rlaga), killed, dir, false), std::runtime_error);
    FakeEvaluator rest;
    rest.facts = true;
    (void)run_search(diverse(Method::Rlaga), rest, dir, true);
    EXPECT_EQ(test::read_text(dir / "results.jsonl"), whole) << kill;
  }
  EXPECT_NE(test::read_text(root_ / "a" / "campaign.json").find("\"diversity\""), std::string::npos);
}

TEST_F(SearchDir, DiversitySpreadsItsSeedPoolAwayFromRandomSamplings) {
  FakeEvaluator a, r;
  a.facts = r.facts = true;
  const SearchResult d = run_search(diverse(Method::DiverseGa), a, root_ / "d", false);
  SearchOptions random_options = small(Method::Random);
  random_options.budget = 48;
  const SearchResult rnd = run_search(random_options, r, root_ / "r", false);
  // Not random sampling's pool: none of its 6 members is one of random's first 48.
  for (std::size_t i = 0; i < 6; ++i) {
    for (const EvaluationRecord& x : rnd.records) EXPECT_NE(d.records[i].genes, x.genes) << i;
  }
  // Maximin over 48 candidates: its closest pair is farther apart than random's.
  EXPECT_GT(min_pairwise(d.records, 6), min_pairwise(rnd.records, 6));
}

TEST_F(SearchDir, DiversityCoverPoolRunsEachConditionFirstAndIsRecorded) {
  SearchOptions o = diverse(Method::Rlaga);
  o.diversity_pool = SeedPool::Cover;
  FakeEvaluator a, b;
  a.facts = b.facts = true;
  const SearchResult r = run_search(o, a, root_ / "c", false);
  // Population 6: fog, wrong_id, rain, lookalike, snowfall, pattern. The
  // fake misses the marker in fog > 0.25 (the fog member's is ≥ 0.36).
  EXPECT_EQ(r.records[0].evaluation.violation, scenario::Violation::TypeII);
  const ChromosomeLayout layout = search_layout(o);
  const auto pool = detail::cover_pool(layout, o.seed, 0, 6);
  for (std::size_t k = 0; k < pool.size(); ++k) {
    EXPECT_EQ(r.records[k].genes, layout.normalised(layout.fit(pool[k].scenario))) << pool[k].condition;
  }
  const std::string json = test::read_text(root_ / "c" / "campaign.json");
  EXPECT_NE(json.find("\"pool\": \"cover\""), std::string::npos);
  // A spread campaign's is written as before the option (kept ones resume).
  (void)run_search(diverse(Method::Rlaga), b, root_ / "s", false);
  EXPECT_EQ(test::read_text(root_ / "s" / "campaign.json").find("\"pool\""), std::string::npos);
  // The other pool's campaign is refused, naming the key.
  FakeEvaluator c;
  try {
    (void)run_search(diverse(Method::Rlaga), c, root_ / "c", true);
    ADD_FAILURE() << "resumed a cover campaign as a spread one";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("diversity.pool"), std::string::npos) << e.what();
  }
  // Killed and resumed: the same file.
  FakeEvaluator killed, rest;
  killed.facts = rest.facts = true;
  killed.fail_after = 4;
  EXPECT_THROW(run_search(o, killed, root_ / "k", false), std::runtime_error);
  (void)run_search(o, rest, root_ / "k", true);
  EXPECT_EQ(test::read_text(root_ / "k" / "results.jsonl"), test::read_text(root_ / "c" / "results.jsonl"));
}

// Runs `o` (a covering pool) in `dir` and checks what every covering pool
// shares: its first n records are cover_pool(background)'s n members, in
// order; campaign.json names the pool; the campaign is not resumed under
// the pool `other`.
SearchResult expect_covering_run(const SearchOptions& o, detail::Background background, int n, const fs::path& dir,
                                 SeedPool other) {
  FakeEvaluator a, b;
  a.facts = b.facts = true;
  const SearchResult r = run_search(o, a, dir, false);
  const ChromosomeLayout layout = search_layout(o);
  const auto pool = detail::cover_pool(layout, o.seed, 0, n, background);
  EXPECT_GE(r.records.size(), pool.size());
  for (std::size_t k = 0; k < pool.size() && k < r.records.size(); ++k) {
    EXPECT_EQ(r.records[k].genes, layout.normalised(layout.fit(pool[k].scenario))) << pool[k].condition;
  }
  const std::string name(enum_name(o.diversity_pool));
  EXPECT_NE(test::read_text(dir / "campaign.json").find("\"pool\": \"" + name + "\""), std::string::npos) << name;
  SearchOptions resumed = o;
  resumed.diversity_pool = other;
  EXPECT_THROW((void)run_search(resumed, b, dir, true), InvalidArgument) << name << " resumed as " << enum_name(other);
  return r;
}

TEST_F(SearchDir, DiversityCoverDrawnPoolRunsEachConditionOnADrawnSceneAndIsRecorded) {
  SearchOptions o = diverse(Method::Rlaga);
  o.diversity_pool = SeedPool::CoverDrawn;
  const SearchResult r = expect_covering_run(o, detail::Background::Drawn, 6, root_ / "d", SeedPool::Cover);
  const ChromosomeLayout layout = search_layout(o);
  const auto benign = detail::cover_pool(layout, o.seed, 0, 6, detail::Background::Benign);
  for (std::size_t k = 0; k < benign.size(); ++k) {
    EXPECT_NE(r.records[k].genes, layout.normalised(layout.fit(benign[k].scenario))) << benign[k].condition;
  }
}

TEST_F(SearchDir, DiversityCoverMixedPoolRunsTheMixedMembersAndIsRecorded) {
  SearchOptions o = diverse(Method::Rlaga);
  o.ga.population = 20;  // every condition, the moving objects' among them
  o.budget = 20;
  o.diversity_pool = SeedPool::CoverMixed;
  (void)expect_covering_run(o, detail::Background::Mixed, 20, root_ / "m", SeedPool::CoverDrawn);
}

// cover-and-spread: generation 0 is cover-mixed's members, then a
// population of the spread pool's; selection keeps a population of them
// and every later generation is a population.
TEST_F(SearchDir, DiversityCoverAndSpreadRunsBothKindsInItsFirstGeneration) {
  SearchOptions o = diverse(Method::Rlaga);  // population 6, budget 48
  o.diversity_pool = SeedPool::CoverAndSpread;
  ASSERT_EQ(o.first_generation(), 26);
  const SearchResult r = expect_covering_run(o, detail::Background::Mixed, 20, root_ / "s", SeedPool::CoverMixed);
  ASSERT_EQ(r.records.size(), 48u);
  std::vector<int> per_generation;
  for (const EvaluationRecord& rec : r.records) {
    if (per_generation.size() <= static_cast<std::size_t>(rec.generation)) per_generation.resize(rec.generation + 1);
    ++per_generation[static_cast<std::size_t>(rec.generation)];
  }
  EXPECT_EQ(per_generation, (std::vector<int>{26, 6, 6, 6, 4}));
  // The other 6 are the spread pool's: what a spread campaign of population
  // 6 runs first.
  SearchOptions spread = o;
  spread.diversity_pool = SeedPool::Spread;
  spread.budget = 6;
  FakeEvaluator c;
  c.facts = true;
  const SearchResult first = run_search(spread, c, root_ / "p", false);
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(r.records[20 + k].genes, first.records[k].genes) << k;
  // Killed in generation 0 and resumed: the same results file.
  FakeEvaluator killed, rest;
  killed.facts = rest.facts = true;
  killed.fail_after = 10;
  EXPECT_THROW(run_search(o, killed, root_ / "k", false), std::runtime_error);
  (void)run_search(o, rest, root_ / "k", true);
  EXPECT_EQ(test::read_text(root_ / "k" / "results.jsonl"), test::read_text(root_ / "s" / "results.jsonl"));
}

TEST_F(SearchDir, DiversityRunsNoScenarioNearOneAlreadyRun) {
  FakeEvaluator e;
  e.facts = true;
  SearchOptions o = diverse(Method::DiverseGa);
  o.min_distance = 0.05;
  const SearchResult r = run_search(o, e, root_ / "d", false);
  int near = 0;
  for (std::size_t j = 6; j < r.records.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) near += distance(r.records[i].genes, r.records[j].genes) < 0.05 ? 1 : 0;
  }
  EXPECT_EQ(near, 0);
  // Without the option the GA re-runs near-copies of its pool.
  FakeEvaluator plain;
  const SearchResult p = run_search(small(Method::DiverseGa), plain, root_ / "p", false);
  int plain_near = 0;
  for (std::size_t j = 6; j < p.records.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) plain_near += distance(p.records[i].genes, p.records[j].genes) < 0.05 ? 1 : 0;
  }
  EXPECT_GT(plain_near, 0);
}

TEST_F(SearchDir, DiversityScoresARepeatedCauseLess) {
  FakeEvaluator e;
  e.facts = true;
  const SearchOptions o = diverse(Method::DiverseGa);
  const SearchResult r = run_search(o, e, root_ / "d", false);
  std::map<std::string, int> seen;
  int repeats = 0, unfair = 0;
  for (const EvaluationRecord& rec : r.records) {
    const Evaluation& ev = rec.evaluation;
    if (ev.violation_found() && !ev.fair_violation()) {
      EXPECT_EQ(rec.fitness, 0.0) << rec.index;
      ++unfair;
      continue;
    }
    const double base = fitness_eq1(ev, o.violation_radius);
    if (!ev.fair_violation()) {
      EXPECT_EQ(rec.fitness, base) << rec.index;
      continue;
    }
    const scenario::Scenario s = scenario::load_scenario(root_ / "d" / rec.scenario);
    int& n = seen[violation_cause(ev, s)];
    EXPECT_DOUBLE_EQ(rec.fitness, base / (1 + n)) << rec.index;
    repeats += n > 0 ? 1 : 0;
    ++n;
  }
  EXPECT_GT(repeats, 0) << "the fake world has few causes: some must repeat";
  EXPECT_GT(seen.size(), 1u);
  // (Unfair runs scoring 0 is checked where the fake world makes them:
  // FairFitnessScoresUnfairViolationsAsNone; the same rule applies here.)
  (void)unfair;
}

// One campaign (fake_with_facts; `crowd` as FakeEvaluator's) stopped at
// each generation's end: for every generation after the first, `check`
// gets the run so far, its directory, the generation, the pool state.json
// holds then, and the candidates it was chosen from (the last pool and the
// generation's offspring).
template <class Check>
void each_pool(const SearchOptions& options, const fs::path& root, bool crowd, Check check) {
  std::vector<int> previous;
  for (int budget = options.ga.population; budget <= options.budget; budget += options.ga.population) {
    SearchOptions o = options;
    o.budget = budget;
    FakeEvaluator e;
    e.facts = true;
    e.crowd = crowd;
    const fs::path dir = root / std::to_string(budget);
    const SearchResult r = run_search(o, e, dir, false);
    const detail::PoolState state = detail::parse_state(test::read_text(dir / "state.json"), "state.json");
    std::vector<int> pool;
    for (const detail::PoolMember& m : state.pool) pool.push_back(m.index);
    if (!previous.empty()) {
      std::vector<int> all = previous;
      for (const EvaluationRecord& rec : r.records)
        if (rec.generation == state.generation) all.push_back(rec.index);
      check(r, dir, state.generation, pool, all);
    }
    previous = pool;
  }
}

// Clearing's promise, checked generation by generation from outside: when
// the pool holds more than `capacity` fair violations of one cause, no
// candidate it left out (of the last pool and the generation's offspring)
// kept a positive fitness after clearing at that capacity — the extra ones
// are there only because nothing better was left. The pools come from
// state.json of the same campaign stopped at each generation's end (every
// budget is a prefix of the longest: the draws depend on nothing else).
bool clearing_holds(const SearchOptions& options, const fs::path& root, int capacity) {
  bool holds = true;
  each_pool(
      options, root, false,
      [&](const SearchResult& r, const fs::path& dir, int, const std::vector<int>& pool, const std::vector<int>& all) {
        std::vector<double> fitness;
        std::vector<std::string> cause;
        for (int i : all) {
          const EvaluationRecord& rec = r.records.at(static_cast<std::size_t>(i));
          fitness.push_back(rec.fitness);
          cause.push_back(rec.evaluation.fair_violation()
                              ? violation_cause(rec.evaluation, scenario::load_scenario(dir / rec.scenario))
                              : std::string());
        }
        const std::vector<double> cleared = clear_niches(fitness, cause, capacity);
        std::map<std::string, int> in_pool;
        int most = 0;
        double best_left_out = 0;
        for (std::size_t k = 0; k < all.size(); ++k) {
          const bool member = std::find(pool.begin(), pool.end(), all[k]) != pool.end();
          if (member && !cause[k].empty()) most = std::max(most, ++in_pool[cause[k]]);
          if (!member) best_left_out = std::max(best_left_out, cleared[k]);
        }
        if (most > capacity && best_left_out > 0) holds = false;
      });
  return holds;
}

TEST_F(SearchDir, DiversityLetsNoCauseFillMoreThanItsNicheOfThePool) {
  for (Method m : {Method::DiverseGa, Method::ManyObjectiveGa}) {
    const std::string name = std::to_string(static_cast<int>(m));
    SearchOptions o = diverse(m);
    o.niche_capacity = 1;
    EXPECT_TRUE(clearing_holds(o, root_ / ("one" + name), 1)) << name;
    // A niche as large as the pool is no clearing: one cause then takes
    // places that a fitter candidate of another would have had.
    o.niche_capacity = o.ga.population;
    EXPECT_FALSE(clearing_holds(o, root_ / ("all" + name), 1)) << name;
  }
  SearchOptions o = diverse(Method::Rlaga);
  o.niche_capacity = 7;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("niche_capacity: 7 is outside [1, population = 6]"), std::string::npos) << why;
  o.niche_capacity = 2;
  FakeEvaluator e;
  (void)run_search(o, e, root_ / "c", false);
  EXPECT_NE(test::read_text(root_ / "c" / "campaign.json").find("\"niche_capacity\": 2"), std::string::npos);
}

TEST_F(SearchDir, FairFitnessScoresUnfairViolationsAsNone) {
  FakeEvaluator e;
  e.facts = true;
  SearchOptions o = small(Method::DiverseGa);
  o.fair_fitness = true;
  const SearchResult r = run_search(o, e, root_ / "f", false);
  int unfair = 0;
  for (const EvaluationRecord& rec : r.records) {
    if (rec.evaluation.violation_found() && !rec.evaluation.fair_violation()) {
      EXPECT_EQ(rec.fitness, 0.0);
      ++unfair;
    } else {
      EXPECT_EQ(rec.fitness, fitness_eq1(rec.evaluation, o.violation_radius));
    }
  }
  EXPECT_GT(unfair, 0);
  EXPECT_NE(test::read_text(root_ / "f" / "campaign.json").find("\"fair_fitness\": true"), std::string::npos);
}

TEST_F(SearchDir, TheNearMissTermAddsToTheScalarFitnessAndIsRecorded) {
  FakeEvaluator e;
  e.facts = true;
  SearchOptions o = small(Method::DiverseGa);
  o.near_miss = true;
  const SearchResult r = run_search(o, e, root_ / "n", false);
  int near = 0;
  for (const EvaluationRecord& rec : r.records) {
    const double term = near_miss_term(rec.evaluation);
    near += term > 0;
    if (rec.evaluation.system_failed()) continue;
    EXPECT_DOUBLE_EQ(rec.fitness, fitness_eq1(rec.evaluation, o.violation_radius) + term) << rec.index;
  }
  EXPECT_GT(near, 0) << "no scene had an object within the range: the test shows nothing";
  EXPECT_NE(test::read_text(root_ / "n" / "campaign.json").find("\"near_miss\": true"), std::string::npos);
  // Without it, campaign.json has no such key (campaigns from before resume).
  FakeEvaluator e2;
  e2.facts = true;
  (void)run_search(small(Method::DiverseGa), e2, root_ / "m", false);
  EXPECT_EQ(test::read_text(root_ / "m" / "campaign.json").find("near_miss"), std::string::npos);
}

// With the near-miss term every pool after the first holds the frontier:
// of the last pool and the generation's offspring, the population / 4
// fittest landings with a near miss (all of them when fewer). The pools
// come from state.json of the campaign stopped at each generation's end.
// Returns how many frontier members the pools held (0: the test showed nothing).
int frontier_kept(const SearchOptions& options, const fs::path& root, bool crowd) {
  int kept = 0;
  each_pool(options, root, crowd,
            [&](const SearchResult& r, const fs::path&, int generation, const std::vector<int>& pool,
                const std::vector<int>& all) {
              std::vector<std::pair<double, int>> near;  // (fitness, index) of the near-miss landings
              for (int i : all) {
                const EvaluationRecord& rec = r.records.at(static_cast<std::size_t>(i));
                if (!rec.evaluation.violation_found() && near_miss_term(rec.evaluation) > 0)
                  near.emplace_back(rec.fitness, i);
              }
              std::stable_sort(near.begin(), near.end(),
                               [](const auto& a, const auto& b) { return a.first > b.first; });
              const std::size_t quota = std::min(near.size(), static_cast<std::size_t>(options.ga.population / 4));
              for (std::size_t k = 0; k < quota; ++k) {
                EXPECT_NE(std::find(pool.begin(), pool.end(), near[k].second), pool.end())
                    << "generation " << generation << ": frontier member " << near[k].second << " left out";
                ++kept;
              }
            });
  return kept;
}

TEST_F(SearchDir, TheNearMissFrontierKeepsAQuarterOfThePool) {
  // Every landing without a near miss a Type II: violations would fill the
  // pool (eq. 1 ranks any above a landing) but for the frontier.
  SearchOptions o = small(Method::DiverseGa);
  o.budget = 48;
  o.ga.population = 8;
  o.near_miss = true;
  EXPECT_GT(frontier_kept(o, root_ / "near", true), 0) << "no near-miss landing: the test shows nothing";
  o.diversity = true;
  EXPECT_GT(frontier_kept(o, root_ / "diverse", false), 0) << "no near-miss landing: the test shows nothing";
}

TEST(SearchOptions, BadOptionsAreRefusedNamingTheKey) {
  SearchOptions o;
  std::string why;
  // rlaga (the default method) without the DQN that moves its objects.
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("weights_id: rlaga moves the scenarios' objects with a DQN, and none is given"), std::string::npos)
      << why;
  o.weights_id = "dqn";
  EXPECT_TRUE(o.validate(&why)) << why;
  EXPECT_EQ(o.generations(), 15);
  o.budget = 19;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("budget: 19 is less than the population (20)"), std::string::npos) << why;
  o.budget = 21;
  EXPECT_TRUE(o.validate(&why));
  EXPECT_EQ(o.generations(), 2);
  EXPECT_EQ(o.first_generation(), 20);
  // cover-and-spread: the 20 conditions and a population in generation 0.
  SearchOptions both;
  both.diversity = true;
  both.diversity_pool = SeedPool::CoverAndSpread;
  EXPECT_EQ(both.first_generation(), 40);
  EXPECT_EQ(both.generations(), 1 + 13);  // 40, then 13 of 20
  both.budget = 30;
  EXPECT_EQ(both.first_generation(), 30);
  EXPECT_EQ(both.generations(), 1);
  both.diversity = false;  // the pool is the diversity option's
  EXPECT_EQ(both.first_generation(), 20);
  FakeEvaluator e;
  o.budget = 5;
  EXPECT_THROW(run_search(o, e, fs::temp_directory_path() / "td_search_never", false), InvalidArgument);
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / "td_search_never"));
  SearchOptions d;
  d.weights_id = "dqn";
  d.method = Method::Random;
  d.diversity = true;
  EXPECT_FALSE(d.validate(&why));
  EXPECT_NE(why.find("diversity"), std::string::npos) << why;
  for (Method m : {Method::Random, Method::ManyObjectiveGa}) {
    SearchOptions n;
    n.method = m;
    n.near_miss = true;
    EXPECT_FALSE(n.validate(&why));
    EXPECT_NE(why.find("near_miss: needs a method with a scalar fitness"), std::string::npos) << why;
  }
  d.method = Method::Rlaga;
  d.min_distance = 2;
  EXPECT_FALSE(d.validate(&why));
  EXPECT_NE(why.find("min_distance"), std::string::npos) << why;
}

TEST(Method, NamesRoundTrip) {
  for (Method m : {Method::Rlaga, Method::DiverseGa, Method::ManyObjectiveGa, Method::Random}) {
    EXPECT_EQ(from_string<Method>(to_string(m)), m);
  }
  EXPECT_THROW(from_string<Method>("hill-climbing"), InvalidArgument);
}

}  // namespace
}  // namespace touchdown::search
