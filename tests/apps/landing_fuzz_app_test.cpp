// landing_fuzz end to end: a small campaign and its metrics, the same
// results file on 2 MPI ranks as in one process, resuming, and bad input
// (unknown method, budget below the population, corrupt or wrong-version
// weights, another campaign's directory) as one line with exit 2 and
// nothing overwritten.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "test_util.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace td = touchdown;
using td::test::AppRun;
using td::test::TempDir;
namespace fs = std::filesystem;

namespace {

AppRun fuzz_app(const std::string& args, const TempDir& dir) { return td::test::run_app(LANDING_FUZZ_EXE, args, dir); }

// A short base scenario (10 s time limit) so that each run is cheap.
std::string short_base(const TempDir& dir) {
  td::scenario::Scenario s;
  s.time_limit = 10;
  const fs::path p = dir / "base.yaml";
  std::ofstream(p) << td::scenario::to_yaml(s);
  return p.string();
}

int lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

void expect_one_line(const AppRun& r, const std::string& needle) {
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(needle), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(LandingFuzzApp, CampaignWritesItsDirectoryAndMetricsReadsIt) {
  TempDir dir;
  const std::string common = " --budget 4 --population 2 --seed 2 --threads 2 --base " + short_base(dir);
  const AppRun r = fuzz_app("campaign --method diverse-ga --json --out " + (dir / "c").string() + common, dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["metrics"]["evaluated"], 4);
  EXPECT_EQ(j["method"], "diverse-ga");
  EXPECT_EQ(lines(td::test::read_text(dir / "c" / "results.jsonl")), 4);
  for (const char* f : {"campaign.json", "state.json", "scenarios/000000.yaml", "scenarios/000003.yaml"}) {
    EXPECT_TRUE(fs::exists(dir / "c" / f)) << f;
  }
  const AppRun m = fuzz_app("metrics --json " + (dir / "c").string(), dir);
  ASSERT_EQ(m.code, 0) << m.err;
  td::test::expect_one_json_line(m.out);
  EXPECT_EQ(nlohmann::json::parse(m.out)["metrics"], j["metrics"]);
  // Human output names every metric.
  const AppRun h = fuzz_app("metrics " + (dir / "c").string(), dir);
  ASSERT_EQ(h.code, 0) << h.err;
  for (const char* key : {"violations", "top-10", "all three types", "parameter distance", "3-D coverage"}) {
    EXPECT_NE(h.out.find(key), std::string::npos) << key;
  }
  // Resuming a finished campaign runs nothing and changes nothing.
  const std::string before = td::test::read_text(dir / "c" / "results.jsonl");
  const AppRun again =
      fuzz_app("campaign --method diverse-ga --resume --json --out " + (dir / "c").string() + common, dir);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(nlohmann::json::parse(again.out)["resumed"], 4);
  EXPECT_EQ(td::test::read_text(dir / "c" / "results.jsonl"), before);
}

// Issue 53: a campaign of the learned detector records its model (the ONNX
// file's and manifest's FNV-1a), from campaign and from compare alike, so
// that neither resumes on another model; an ArUco campaign records none.
TEST(LandingFuzzApp, LearnedCampaignsRecordTheirModel) {
  TempDir dir;
  const std::string id = td::scenario::learned_model_id(td::scenario::default_model_path());
  ASSERT_EQ(id.rfind("fnv1a64:", 0), 0u) << id;
  const std::string small = " --budget 2 --population 2 --threads 2";
  const AppRun c = fuzz_app("campaign --method random --system learned-mls --out " + (dir / "c").string() + small +
                                " --base " + short_base(dir),
                            dir);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_EQ(nlohmann::json::parse(td::test::read_text(dir / "c" / "campaign.json")).value("detector_model", ""), id);
  const AppRun m = fuzz_app(
      "compare --methods random --maps ground --seeds 1 --system learned-mls --out " + (dir / "t").string() + small,
      dir);
  ASSERT_EQ(m.code, 0) << m.err;
  const auto cell =
      nlohmann::json::parse(td::test::read_text(dir / "t" / "ground" / "random" / "seed-1" / "campaign.json"));
  EXPECT_EQ(cell.value("detector_model", ""), id);
  EXPECT_EQ(cell.value("detector", ""), "learned");
  const AppRun a =
      fuzz_app("campaign --method random --out " + (dir / "a").string() + small + " --base " + short_base(dir), dir);
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_FALSE(nlohmann::json::parse(td::test::read_text(dir / "a" / "campaign.json")).contains("detector_model"));
}

// For a built-in system, a plug-in's (issue 55: each rank loads the library
// itself) and a process system (each rank's threads start their own), the
// same results file from two ranks as from one process.
TEST(LandingFuzzApp, TwoMpiRanksWriteTheSameResultsAsOneProcess) {
  const std::string mpiexec = MPIEXEC;
  if (mpiexec.empty() || !fs::exists(mpiexec)) GTEST_SKIP() << "no mpirun";
  TempDir dir;
  const std::vector<std::string> systems{"opencv-mls",
                                         std::string("plugin:") + TOUCHDOWN_TEST_PLUGIN + ":test-gps-lander",
                                         std::string("'exec:") + TOUCHDOWN_EXEC_CHILD + " lander'"};
  for (std::size_t k = 0; k < systems.size(); ++k) {
    const std::string common = " --method rlaga --episodes 20 --budget 4 --population 2 --seed 5 --threads 1 --base " +
                               short_base(dir) + " --system " + systems[k];
    const fs::path one_dir = dir / ("one-" + std::to_string(k)), two_dir = dir / ("two-" + std::to_string(k));
    const AppRun one = fuzz_app("campaign --out " + one_dir.string() + common, dir);
    ASSERT_EQ(one.code, 0) << one.err;
    // Open MPI refuses root unless told (CI runs as root). Under ASan its
    // plug-ins (MCA components, unloaded at MPI_Finalize, so LeakSanitizer
    // cannot name them for a suppression) leak their strings: leak checks are
    // off for the two ranks only (set here, so that every process under
    // mpiexec inherits it; `-x` passes it on); the one-process run above
    // keeps them.
    const char* asan = std::getenv("ASAN_OPTIONS");
    const std::string saved = asan ? asan : "";
    ::setenv("ASAN_OPTIONS", "detect_leaks=0", 1);
    const std::string env =
        "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 ";
    const AppRun two = td::test::run_app(env + mpiexec + " -x ASAN_OPTIONS -np 2 " + LANDING_FUZZ_EXE,
                                         "campaign --out " + two_dir.string() + common, dir);
    if (asan) {
      ::setenv("ASAN_OPTIONS", saved.c_str(), 1);
    } else {
      ::unsetenv("ASAN_OPTIONS");
    }
    ASSERT_EQ(two.code, 0) << two.err << two.out;
    const std::string results = td::test::read_text(one_dir / "results.jsonl");
    EXPECT_EQ(results, td::test::read_text(two_dir / "results.jsonl")) << systems[k];
    EXPECT_EQ(td::test::read_text(one_dir / "dqn_weights.txt"), td::test::read_text(two_dir / "dqn_weights.txt"));
    std::string recorded = systems[k];
    recorded.erase(std::remove(recorded.begin(), recorded.end(), '\''), recorded.end());  // the shell's quotes
    EXPECT_NE(td::test::read_text(one_dir / "campaign.json").find("\"system\": \"" + recorded + "\""),
              std::string::npos)
        << recorded;
    EXPECT_EQ(std::count(results.begin(), results.end(), '\n'), 4);
  }
}

// Every scenario of an rlaga campaign replays with `landing_scenario
// campaign --weights DIR/dqn_weights.txt` to the same outcome, message and
// all (the DQN drives the replay's objects as it drove the search's); the
// same file without the weights runs another flight (its person stands
// still). The README's campaign (30 s limit, seed 1), whose DQN-driven
// person walks into the drone.
TEST(LandingFuzzApp, AnRlagaCampaignReplaysWithItsWeights) {
  TD_FULL_SIZE_ONLY();  // 8 closed-loop scenarios, then 16 replays: ~90 s under ASan
  TempDir dir;
  td::scenario::Scenario base;
  base.time_limit = 30;
  std::ofstream(dir / "base30.yaml") << td::scenario::to_yaml(base);
  const fs::path c = dir / "rl";
  ASSERT_EQ(fuzz_app("campaign --method rlaga --budget 8 --population 4 --seed 1 --threads 2 --base " +
                         (dir / "base30.yaml").string() + " --out " + c.string(),
                     dir)
                .code,
            0);
  std::vector<nlohmann::json> records;
  std::string files;
  {
    std::ifstream in(c / "results.jsonl");
    for (std::string line; std::getline(in, line);) {
      records.push_back(nlohmann::json::parse(line));
      files += " " + (c / records.back()["scenario"].get<std::string>()).string();
    }
  }
  ASSERT_EQ(records.size(), 8u);
  const auto replay = [&](const std::string& weights, const std::string& scenario_files) {
    const fs::path csv = dir / "replay.csv";
    fs::remove(csv);
    const AppRun r = td::test::run_app(
        LANDING_SCENARIO_EXE, "campaign --threads 2 " + weights + "--csv " + csv.string() + scenario_files, dir);
    EXPECT_EQ(r.code, 0) << r.err;
    std::vector<std::pair<std::string, std::string>> rows;  // (type, message)
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      std::vector<std::string> cells;
      std::size_t start = 0;
      for (int k = 0; k < 13; ++k) {  // message is the 14th, last column (it may hold commas)
        const std::size_t comma = line.find(',', start);
        cells.push_back(line.substr(start, comma - start));
        start = comma + 1;
      }
      std::string message = line.substr(start);
      if (message.size() >= 2 && message.front() == '"') message = message.substr(1, message.size() - 2);
      rows.emplace_back(cells[3], message);
    }
    return rows;
  };
  const auto with = replay("--weights " + (c / "dqn_weights.txt").string() + " ", files);
  ASSERT_EQ(with.size(), records.size());
  int driven = -1;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto& e = records[i]["evaluation"];
    EXPECT_EQ(with[i].first, e["violation"].get<std::string>()) << i;
    EXPECT_EQ(with[i].second, e["message"].get<std::string>()) << i;
    if (driven < 0 && e["message"].get<std::string>().find("collided with dynamic_objects") != std::string::npos) {
      driven = static_cast<int>(i);
    }
  }
  ASSERT_GE(driven, 0) << "no run of this campaign collided with a moving object: pick another seed";
  const auto without = replay("", " " + (c / records[driven]["scenario"].get<std::string>()).string());
  ASSERT_EQ(without.size(), 1u);
  EXPECT_NE(without[0].second, with[driven].second);
  // Bad weights: one line, exit 2, no CSV.
  std::ofstream(dir / "bad.txt") << "touchdown-dqn-weights 1\nnot a number\n";
  const AppRun bad = td::test::run_app(LANDING_SCENARIO_EXE,
                                       "campaign --weights " + (dir / "bad.txt").string() + " --csv " +
                                           (dir / "b.csv").string() + " " + (c / "scenarios/000000.yaml").string(),
                                       dir);
  expect_one_line(bad, "bad.txt");
  EXPECT_FALSE(fs::exists(dir / "b.csv"));
}

TEST(LandingFuzzApp, BadInputIsOneLineWithExitTwoAndNothingOverwritten) {
  TempDir dir;
  const std::string base = " --base " + short_base(dir);
  expect_one_line(fuzz_app("campaign --method hill-climbing --out " + (dir / "x").string(), dir), "hill-climbing");
  expect_one_line(fuzz_app("campaign --method random --budget 10 --population 20 --out " + (dir / "x").string(), dir),
                  "budget: 10 is less than the population (20)");
  EXPECT_FALSE(fs::exists(dir / "x"));
  // Corrupt, truncated and wrong-version weights.
  std::ofstream(dir / "garbage.json") << "not weights at all";
  expect_one_line(fuzz_app("campaign --method rlaga --weights " + (dir / "garbage.json").string() + " --out " +
                               (dir / "x").string() + base,
                           dir),
                  "garbage.json");
  ASSERT_EQ(fuzz_app("train-dqn --episodes 5 -o " + (dir / "w.txt").string(), dir).code, 0);
  const std::string weights = td::test::read_text(dir / "w.txt");
  std::ofstream(dir / "cut.json") << weights.substr(0, weights.size() / 2);
  expect_one_line(fuzz_app("campaign --method rlaga --weights " + (dir / "cut.json").string() + " --out " +
                               (dir / "x").string() + base,
                           dir),
                  "cut.json");
  std::string v2 = weights;
  ASSERT_EQ(v2.rfind("touchdown-dqn-weights 1\n", 0), 0u) << weights.substr(0, 200);
  v2[22] = '9';
  std::ofstream(dir / "v9.json") << v2;
  expect_one_line(fuzz_app("campaign --method rlaga --weights " + (dir / "v9.json").string() + " --out " +
                               (dir / "x").string() + base,
                           dir),
                  "v9.json");
  EXPECT_FALSE(fs::exists(dir / "x"));
  // Another campaign's directory: refused without and with --resume.
  const std::string c = (dir / "c").string();
  ASSERT_EQ(fuzz_app("campaign --method random --budget 2 --population 2 --out " + c + base, dir).code, 0);
  const std::string before = td::test::read_text(dir / "c" / "results.jsonl");
  expect_one_line(fuzz_app("campaign --method random --budget 2 --population 2 --out " + c + base, dir),
                  "holds a campaign already");
  expect_one_line(
      fuzz_app("campaign --method random --budget 2 --population 2 --seed 9 --resume --out " + c + base, dir),
      "another campaign: seed:");
  expect_one_line(fuzz_app("campaign --method diverse-ga --budget 2 --population 2 --resume --out " + c + base, dir),
                  "another campaign: method:");
  EXPECT_EQ(td::test::read_text(dir / "c" / "results.jsonl"), before);
  expect_one_line(fuzz_app("metrics " + (dir / "nowhere").string(), dir), "nowhere");
  // shrink of a scenario that passes: nothing to shrink, no output file.
  const std::string clear = (fs::path(TOUCHDOWN_SOURCE_DIR) / "data/scenarios/clear_ground.yaml").string();
  expect_one_line(fuzz_app("shrink " + clear + " -o " + (dir / "small.yaml").string(), dir), "nothing to shrink");
  EXPECT_FALSE(fs::exists(dir / "small.yaml"));
  // Issue 58, item 6: options that do not apply are refused, not ignored.
  expect_one_line(fuzz_app("shrink " + clear + " --index 3 -o " + (dir / "small.yaml").string(), dir),
                  "--index: picks a scenario of a results directory");
  expect_one_line(fuzz_app("campaign --method rlaga --min-distance 0.1 --out " + (dir / "y").string() + base, dir),
                  "--diversity");
  expect_one_line(fuzz_app("campaign --method rlaga --niche-capacity 3 --out " + (dir / "y").string() + base, dir),
                  "--diversity");
  EXPECT_FALSE(fs::exists(dir / "y"));
  // Issue 58, item 2: a missing parent is refused, as by every other app, and not created.
  const std::string deep = (dir / "no" / "such" / "x").string();
  expect_one_line(fuzz_app("campaign --method random --budget 2 --population 2 --out " + deep + base, dir),
                  "output directory '" + (dir / "no" / "such").string() + "' does not exist");
  expect_one_line(fuzz_app("compare --seeds 1 --budget 2 --population 2 --out " + deep, dir), "does not exist");
  EXPECT_FALSE(fs::exists(dir / "no"));
  // compare's method options: each known once, and only where they apply.
  const std::string out = " --seeds 1 --budget 2 --population 2 --out " + (dir / "methods").string();
  for (const auto& [method, says] : std::vector<std::pair<std::string, std::string>>{
           {"rlaga+fast", "unknown option '+fast'"},
           {"rlaga+cover+cover", "'+cover' given twice"},
           {"rlaga+diversity+cover", "drop '+diversity'"},
           {"rlaga+cover-drawn+diversity", "drop '+diversity'"},
           {"rlaga+cover+cover-drawn", "two seed pools"},
           {"rlaga+cover-mixed+cover", "'+cover-mixed' and '+cover' are two"},
           {"rlaga+cover-mixed+cover-mixed", "given twice"},
           {"rlaga+cover-and-spread+cover", "two seed pools"},
           {"rlaga+spread", "unknown option '+spread'"},
           {"random+near-miss", "random has no options"},
           {"many-objective-ga+near-miss", "no scalar fitness"},
           {"hill-climbing+cover", "hill-climbing"}}) {
    expect_one_line(fuzz_app("compare --methods " + method + out, dir), says);
  }
  EXPECT_FALSE(fs::exists(dir / "methods"));
  // A system spec that does not resolve: one line naming it.
  expect_one_line(fuzz_app("campaign --method random --system plugin:" + (dir / "none.so").string() + " --out " +
                               (dir / "y").string() + base,
                           dir),
                  "none.so: no such file");
}

TEST(LandingFuzzApp, HelpShowsEveryDefault) {
  TempDir dir;
  for (const char* sub : {"campaign", "compare"}) {
    const AppRun r = fuzz_app(std::string(sub) + " --help", dir);
    ASSERT_EQ(r.code, 0);
    td::test::expect_help_shows_defaults(r.out);
  }
}

}  // namespace
