// landing_fuzz shrink: a violation reduced to the genes it needs.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "app_common.hpp"
#include "core/io_util.hpp"
#include "landing_fuzz.hpp"
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/search/campaign_policy.hpp"
#include "touchdown/search/causes.hpp"
#include "touchdown/search/compare.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/mpi_evaluator.hpp"
#include "touchdown/search/search.hpp"
#include "touchdown/search/shrink.hpp"
#include "touchdown/search/surrogate.hpp"

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::fuzz_app;
using tsr::kWeightsFile;

// ---- shrink ----------------------------------------------------------------------------

struct ShrinkArgs {
  Common common;
  std::string input, out, weights;
  int index = -1;
  bool json = false;
};

CLI::App* add_shrink_command(CLI::App& app, ShrinkArgs& a) {
  auto* cmd = app.add_subcommand(
      "shrink",
      "why did it fail: reset genes to benign values while the violation stays; the smallest failing "
      "scenario and the genes it needs");
  cmd->add_option("INPUT", a.input, "a results directory (its campaign's system and weights) or a scenario file")
      ->required();
  cmd->add_option("--index", a.index, "results directory: the scenario's index (default: the first violation)")
      ->check(CLI::Range(0, 100000000));
  add_common(*cmd, a.common);
  cmd->add_option("--weights", a.weights, "scenario file: DQN weights driving its external objects")
      ->check(td::app::existing_file());
  cmd->add_option("-o,--output", a.out, "the smallest failing scenario (YAML)")
      ->required()
      ->check(output_extension(".yaml"));
  cmd->add_flag("--json", a.json, "the result as one JSON object on stdout");
  return cmd;
}

int shrink_command(ShrinkArgs& a) {
  td::StagedOutputs staged;
  const fs::path tmp = staged.add(a.out, "--output");
  ts::Scenario scenario, base;
  std::string source = a.input;
  std::shared_ptr<const tsr::QNetwork> policy;
  if (!fs::is_directory(a.input) && a.index >= 0) {
    throw td::InvalidArgument("--index: picks a scenario of a results directory; " + a.input +
                              " is a scenario file (issue 58: an option that does not apply is refused)");
  }
  if (!a.weights.empty()) policy = std::make_shared<const tsr::QNetwork>(tsr::load_weights(a.weights));
  if (fs::is_directory(a.input)) {
    const tsr::ResultsDirectory d = tsr::load_results_directory(a.input);
    const Json campaign = Json::parse(d.campaign_json);
    const tsr::EvaluationRecord* pick = nullptr;
    for (const auto& r : d.records) {
      if (a.index >= 0 ? r.index == a.index : r.evaluation.violation_found()) {
        pick = &r;
        break;
      }
    }
    if (!pick) {
      throw td::InvalidArgument(
          a.input + ": " +
          (a.index >= 0 ? "no scenario with index " + std::to_string(a.index) : std::string("no violation to shrink")));
    }
    source = (fs::path(a.input) / pick->scenario).string();
    scenario = ts::load_scenario(source);
    base = ts::parse_scenario(campaign.at("base_scenario").dump(), a.input + "/campaign.json: base_scenario");
    a.common.system = campaign.value("system", a.common.system);
    a.common.detector = campaign.value("detector", std::string("aruco"));
    const fs::path stored = fs::path(a.input) / kWeightsFile;
    if (!policy && fs::exists(stored)) policy = std::make_shared<const tsr::QNetwork>(tsr::load_weights(stored));
  } else {
    scenario = ts::load_scenario(a.input);
    base.map = scenario.map;
  }
  cv::setNumThreads(1);
  tsr::LocalEvaluator evaluator(evaluator_options(a.common, policy));
  ProgressBar bar("landing_fuzz", "evaluations");
  const tsr::ShrinkResult r =
      tsr::shrink(scenario, base, evaluator, [&](const td::Progress& p) { bar.draw(p.done, p.total); });
  bar.close();
  if (!r.ok()) {
    throw td::InvalidArgument(source + ": not a violation on " + a.common.system + " (" + r.message +
                              "): nothing to shrink");
  }
  write_text(tmp, ts::to_yaml(r.smallest), a.out);
  staged.commit();
  if (a.json) {
    Json j;
    j["scenario"] = source;
    j["system"] = a.common.system;
    j["violation"] = ts::to_string(r.violation);
    j["message"] = r.message;
    j["necessary"] = r.necessary;
    Json steps = Json::array();
    for (const auto& s : r.steps) {
      steps.push_back({{"gene", s.gene},
                       {"tried", s.tried},
                       {"outcome", ts::to_string(s.outcome)},
                       {"kept", s.kept},
                       {"message", s.message}});
    }
    j["steps"] = std::move(steps);
    j["smallest"] = a.out;
    j["runs"] = r.runs();
    std::cout << j.dump() << "\n";
  } else {
    std::cout << "scenario   " << source << " on " << a.common.system << ": type " << ts::to_string(r.violation) << " ("
              << r.message << ")\n";
    for (const auto& s : r.steps) {
      std::cout << "  reset " << s.gene << ": "
                << (!s.tried ? s.message
                             : (s.kept ? "still type " + std::string(ts::to_string(s.outcome)) + ", kept"
                                       : "now " +
                                             (s.outcome == ts::Violation::None
                                                  ? std::string("no violation")
                                                  : "type " + std::string(ts::to_string(s.outcome))) +
                                             ": needed"))
                << "\n";
    }
    std::cout << "needs      ";
    for (std::size_t i = 0; i < r.necessary.size(); ++i) std::cout << (i ? ", " : "") << r.necessary[i];
    std::cout << (r.necessary.empty() ? "none of its genes (with every gene reset it still fails: the cause lies in "
                                        "the base scenario's own fields)"
                                      : "")
              << "\n"
              << "smallest   " << a.out << " (" << r.runs() << " runs)\n";
  }
  return kExitOk;
}

}  // namespace

namespace touchdown::app::fuzz_app {

Subcommand add_shrink(CLI::App& app) { return make_subcommand<ShrinkArgs>(app, add_shrink_command, shrink_command); }

}  // namespace touchdown::app::fuzz_app
