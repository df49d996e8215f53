// landing_scenario: runs a landing system under test in a marker-landing
// scenario (docs/formats.md, "Landing scenarios") and reports the outcome
// with the RLaGA paper's violation types; or writes a random valid scenario.
// This file: main, random and campaign; the other subcommands are in
// landing_scenario_*.cpp (landing_scenario.hpp).
#include "landing_scenario.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app_common.hpp"
#include "core/svg_plot.hpp"
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/contract.hpp"
#include "touchdown/scenario/dataset.hpp"
#include "touchdown/scenario/detector_bench.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/report.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/object_policy.hpp"
#include "video.hpp"

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::scenario_app;

// ---- random: write a random scenario ----------------------------------------------------

struct RandomArgs {
  std::uint64_t seed = 1;
  std::string out_path;
  std::optional<ts::MapKind> map;  // empty: any
};

CLI::App* add_random_command(CLI::App& app, RandomArgs& a) {
  auto* cmd = app.add_subcommand("random", "write a random valid scenario drawn from the bounds table");
  add_seed_option(*cmd, "--seed", a.seed, "random seed");
  add_enum_option(*cmd, "--map", a.map, kAnyMap, td::enum_names_list<ts::MapKind>() + " or " + kAnyMap);
  cmd->add_option("-o,--output", a.out_path, "scenario file to write (.yaml or .json)")
      ->required()
      ->check([](const std::string& p) {
        const auto ext = fs::path(p).extension();
        return ext == ".yaml" || ext == ".yml" || ext == ".json" ? std::string()
                                                                 : "must end in .yaml, .yml or .json, got '" + p + "'";
      });
  return cmd;
}

int random_command(const RandomArgs& a) {
  td::StagedOutputs staged;
  const fs::path tmp = staged.add(a.out_path, "--output");
  const ts::Scenario s = a.map ? ts::random_scenario(a.seed, *a.map) : ts::random_scenario(a.seed);
  const bool as_json = fs::path(a.out_path).extension() == ".json";
  write_text(tmp, as_json ? ts::to_json(s) : ts::to_yaml(s), a.out_path);
  staged.commit();
  std::cerr << "landing_scenario: wrote " << a.out_path << " (" << ts::to_string(s.map) << ", "
            << s.static_objects.size() << " static, "
            << count_noun(static_cast<long long>(s.dynamic_objects.size()), "moving object") << ", "
            << count_noun(static_cast<long long>(s.distractors.size()), "distractor") << ")\n";
  return kExitOk;
}

// ---- campaign: many scenarios ----------------------------------------------------------

struct CampaignArgs {
  std::vector<std::string> files;
  std::uint64_t first_seed = 1;
  int count = 100;
  std::optional<ts::MapKind> map;  // empty: any
  std::string csv_path, weights_path, marker;
  std::string system = "opencv-mls";
  bool json = false, whole_frame = false;
  ts::CampaignOptions campaign;
};

CLI::App* add_campaign_command(CLI::App& app, CampaignArgs& a) {
  auto* cmd = app.add_subcommand(
      "campaign",
      "run many scenarios (random ones by seed, or the given files) in parallel; violation rate and type mix");
  a.campaign.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  auto* files_opt = cmd->add_option("SCENARIO", a.files, "scenario files (default: random ones)");
  add_seed_option(*cmd, "--seed", a.first_seed, "seed of the first random scenario")->excludes(files_opt);
  cmd->add_option("--count", a.count, "random scenarios")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str()
      ->excludes(files_opt);
  add_enum_option(*cmd, "--map", a.map, kAnyMap,
                  "map of the random scenarios: " + td::enum_names_list<ts::MapKind>() + " or " + kAnyMap)
      ->excludes(files_opt);
  add_system_option(*cmd, a.system);
  add_detector_option(*cmd, a.campaign.mls.detector.kind);
  cmd->add_option("--marker", a.marker,
                  "the target of the random scenarios, DICTIONARY:ID (default: drawn; a learned detector needs "
                  "its model's marker)")
      ->excludes(files_opt);
  cmd->add_option("--threads", a.campaign.threads, "worker threads (0 = every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--whole-frame-detection", a.whole_frame,
                "detect in the whole frame every time (no tracking ROI), as the published baseline");
  cmd->add_option("--weights", a.weights_path,
                  "drive every scenario's `external` dynamic objects with this DQN, as the landing_fuzz rlaga "
                  "campaign that wrote the files did (its dqn_weights.txt); without it they stay")
      ->check(td::app::existing_file());
  cmd->add_option("--csv", a.csv_path, "one row per scenario")->check(output_extension(".csv"));
  cmd->add_flag("--json", a.json, "the summary as one JSON object on stdout");
  return cmd;
}

int campaign_command(CampaignArgs& a) {
  td::StagedOutputs staged;
  const fs::path csv_tmp = stage(staged, a.csv_path, "--csv");
  std::vector<ts::Scenario> scenarios;
  std::vector<std::string> names;
  std::string source;
  if (!a.files.empty()) {
    for (const auto& f : a.files) {
      scenarios.push_back(ts::load_scenario(f));
      names.push_back(f);
    }
    source = count_noun(static_cast<long long>(a.files.size()), "file");
  } else {
    if (a.first_seed > std::numeric_limits<std::uint64_t>::max() - static_cast<std::uint64_t>(a.count - 1)) {
      throw td::InvalidArgument("--seed " + std::to_string(a.first_seed) + " with --count " + std::to_string(a.count) +
                                ": the seeds would pass 18446744073709551615 (2^64 - 1)");
    }
    scenarios = ts::random_scenarios(a.first_seed, a.count, a.map);
    if (!a.marker.empty()) {
      std::string dictionary;
      int id = 0;
      parse_marker(a.marker, "--marker", &dictionary, &id);
      for (ts::Scenario& s : scenarios) ts::set_target(s, dictionary, id);
    }
    for (int i = 0; i < a.count; ++i)
      names.push_back("seed " + std::to_string(a.first_seed + static_cast<std::uint64_t>(i)));
    source = "random, seeds " + std::to_string(a.first_seed) + ".." +
             std::to_string(a.first_seed + static_cast<std::uint64_t>(a.count) - 1) + ", map " +
             (a.map ? std::string(ts::to_string(*a.map)) : kAnyMap);
  }
  a.campaign.mls.detector.roi = !a.whole_frame;
  a.campaign.system = a.system;
  if (!a.weights_path.empty()) {
    // One network, shared read-only; one ObjectPolicy per run (it keeps the
    // run's held action), as the search's LocalEvaluator does.
    auto network = std::make_shared<const tsr::QNetwork>(tsr::load_weights(a.weights_path));
    a.campaign.external_for = [network](std::size_t) {
      return std::function<void(const ts::World&, std::vector<ts::ObjectAction>&)>(tsr::ObjectPolicy(network));
    };
  }
  // The campaign's threads are the parallelism: OpenCV's own would
  // oversubscribe the cores.
  cv::setNumThreads(1);
  // A bar with the time left (lines off a terminal), from the scenarios
  // finished (the library calls this one scenario at a time).
  ProgressBar bar("landing_scenario", "scenarios");
  bar.draw(0, scenarios.size());
  a.campaign.progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
  ts::CampaignResult c;
  try {
    c = ts::run_campaign(scenarios, a.campaign);
  } catch (...) {
    bar.close();
    throw;
  }
  if (!a.csv_path.empty()) write_text(csv_tmp, ts::campaign_csv(c, names), a.csv_path);
  staged.commit();
  if (a.json) {
    std::cout << ts::campaign_json(c, source, a.campaign) << "\n";
  } else {
    std::cout << ts::campaign_summary(c, source, a.campaign, names);
  }
  return kExitOk;
}

}  // namespace

namespace touchdown::app::scenario_app {

// The --map name that leaves the map to the random draw.
const std::string kAnyMap = "any";

/// "DICT:ID" → dictionary and id (checked by DatasetOptions::validate).
void parse_marker(const std::string& text, const std::string& option, std::string* dictionary, int* id) {
  if (!ts::parse_marker_spec(text, *dictionary, *id))
    throw td::InvalidArgument(option + " " + text + ": expected DICTIONARY:ID, e.g. 4X4_50:0");
}

Subcommand add_random(CLI::App& app) { return make_subcommand<RandomArgs>(app, add_random_command, random_command); }

Subcommand add_campaign(CLI::App& app) {
  return make_subcommand<CampaignArgs>(app, add_campaign_command, campaign_command);
}

}  // namespace touchdown::app::scenario_app

int main(int argc, char** argv) {
  namespace sa = touchdown::app::scenario_app;
  CLI::App app{
      "Run a marker-landing system under test in a scenario (weather, markers, objects) and classify the "
      "outcome; or write a random scenario.",
      "landing_scenario"};
  app.require_subcommand(1);
  const std::vector<Subcommand> commands{sa::add_run(app),    sa::add_contract(app), sa::add_systems(app),
                                         sa::add_bench(app),  sa::add_detect(app),   sa::add_dataset(app),
                                         sa::add_random(app), sa::add_campaign(app)};
  return run(app, argc, argv, [&] { return run_parsed(commands); });
}
