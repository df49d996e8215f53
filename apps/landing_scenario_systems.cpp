// landing_scenario contract and systems: the landing systems a spec names
// and whether one keeps the LandingSystem contract.
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
#include "landing_scenario.hpp"
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

struct ContractArgs {
  std::string system = "opencv-mls";
  std::string detector = "aruco";
  double max_time = 0;
  bool json = false;
};

CLI::App* add_contract_command(CLI::App& app, ContractArgs& a) {
  auto* cmd = app.add_subcommand(
      "contract",
      "check that a landing system keeps the LandingSystem contract (name, frameless steps, finite outputs, "
      "determinism, reset, independence); exit 1 when a clause fails");
  add_system_option(*cmd, a.system);
  add_detector_option(*cmd, a.detector);
  cmd->add_option("--max-time", a.max_time,
                  "end every run after this many simulated seconds (default 0: the scenarios' own 35 s and 12 s), "
                  "for a quicker check")
      ->check(CLI::Range(0.0, 300.0))
      ->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON object per clause instead of the table");
  return cmd;
}

int contract_command(const ContractArgs& a) {
  ts::MlsOptions mls;
  mls.detector.kind = a.detector;
  const ts::SystemFactory factory(a.system);
  (void)factory.make(mls);  // a spec that does not resolve is bad input (exit 2), not a broken clause
  ts::contract::Factory f(a.system, [factory, mls] { return factory.make(mls); });
  f.script.max_time = a.max_time;
  if (!a.json) {
    std::cout << "contract   " << a.system << ": " << ts::contract::clauses().size()
              << " clauses, closed-loop runs on the clear test scenario and a second one\n";
  }
  int failed = 0;
  (void)ts::contract::run_contract(f, [&](const ts::contract::ClauseResult& r) {
    failed += r.verdict.ok ? 0 : 1;
    if (a.json) {
      std::cout << Json{{"clause", r.clause->name},
                        {"ok", r.verdict.ok},
                        {"message", r.verdict.message},
                        {"seconds", round3(r.seconds)}}
                       .dump()
                << std::endl;
      return;
    }
    const std::string name(r.clause->name);
    std::cout << name << std::string(15 - name.size(), ' ') << (r.verdict.ok ? "ok      " : "FAILED  ")
              << format_fixed(r.seconds, 1) << " s  "
              << (r.verdict.ok ? std::string(r.clause->promise) : r.verdict.message) << std::endl;
  });
  if (!a.json) {
    std::cout << "result     "
              << (failed == 0 ? "every clause holds"
                              : std::to_string(failed) + " of " + std::to_string(ts::contract::clauses().size()) +
                                    " clauses fail")
              << "\n";
  }
  return failed == 0 ? 0 : 1;
}

struct SystemsArgs {
  std::vector<std::string> plugins;
  bool json = false;
};

CLI::App* add_systems_command(CLI::App& app, SystemsArgs& a) {
  auto* cmd = app.add_subcommand("systems",
                                 "list the landing systems under test: the built-ins and those of plug-in libraries");
  cmd->add_option("--plugin", a.plugins, "also load this plug-in library and list its systems (repeatable)")
      ->check(td::app::existing_file());
  cmd->add_flag("--json", a.json, "one JSON object per line instead of the table");
  return cmd;
}

int systems_command(const SystemsArgs& a) {
  std::map<std::string, std::string> origin;  // name -> the spec that reaches it
  for (const std::string& path : a.plugins) {
    for (const std::string& name : ts::load_system_plugin(path)) origin[name] = "plugin:" + path + ":" + name;
  }
  const auto entries = ts::system_registry().entries();
  std::size_t width = 0;
  for (const auto& e : entries) width = std::max(width, e.name.size());
  for (const auto& e : entries) {
    const auto it = origin.find(e.name);
    const std::string spec = it != origin.end() ? it->second : e.name;
    if (a.json) {
      std::cout << Json{{"name", e.name}, {"spec", spec}, {"description", e.description}, {"options", e.options}}.dump()
                << "\n";
    } else {
      const std::string indent(width + 2, ' ');
      std::cout << e.name << std::string(width + 2 - e.name.size(), ' ') << e.description << "\n";
      if (!e.options.empty()) std::cout << indent << "options: " << e.options << "\n";
      if (it != origin.end()) std::cout << indent << "--system " << spec << "\n";
    }
  }
  if (!a.json) {
    std::cout << "\nand any system in another process: --system exec:COMMAND, or "
                 "exec,step-timeout=SECONDS,start-timeout=SECONDS:COMMAND (defaults 10 and 30 s; docs/formats.md, "
                 "\"System protocol\")\n";
  }
  return 0;
}

}  // namespace

namespace touchdown::app::scenario_app {

Subcommand add_contract(CLI::App& app) {
  return make_subcommand<ContractArgs>(app, add_contract_command, contract_command);
}

Subcommand add_systems(CLI::App& app) {
  return make_subcommand<SystemsArgs>(app, add_systems_command, systems_command);
}

}  // namespace touchdown::app::scenario_app
