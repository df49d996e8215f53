#pragma once
// landing_fuzz's subcommands, a group per source file (landing_fuzz.cpp:
// main, campaign, train-dqn and the pieces they share; _report: metrics,
// causes, compare; _shrink: shrink).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "app_common.hpp"
#include "touchdown/search/campaign_policy.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/metrics.hpp"
#include "touchdown/search/search.hpp"

namespace touchdown::app::fuzz_app {

Subcommand add_metrics(CLI::App& app);
Subcommand add_causes(CLI::App& app);
Subcommand add_compare(CLI::App& app);
Subcommand add_shrink(CLI::App& app);

/// The options every evaluating subcommand takes: the system, its detector, threads.
struct Common {
  std::string system = "opencv-mls";
  std::string detector = "aruco";
  int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
};
void add_common(CLI::App& cmd, Common& c);
touchdown::search::EvaluatorOptions evaluator_options(const Common& c,
                                                      std::shared_ptr<const touchdown::search::QNetwork> policy);
/// Sets the detector a campaign runs (learned-mls: always the learned one)
/// and, for the learned one, its model's id (campaign.json's detector_model).
void set_detector(touchdown::search::SearchOptions& o, const Common& c);
std::string percent(double v);
/// A count or "not found".
std::string optional_count(const std::optional<int>& v);
/// The metrics as JSON (keys in docs/cli.md's order).
nlohmann::ordered_json metrics_json(const touchdown::search::SearchMetrics& m);
/// Raw (the source's definition) and, when the records carry their facts,
/// fair metrics (issue 52), on stdout.
void print_metrics(const touchdown::search::SearchMetrics& m,
                   const std::optional<touchdown::search::SearchMetrics>& fair = std::nullopt);
/// The DQN of an rlaga campaign: --weights, else the directory's copy when
/// resuming, else pre-trained now (deterministic for the seed).
touchdown::search::CampaignPolicy campaign_policy(const std::string& weights_path, const std::filesystem::path& dir,
                                                  bool resume, int episodes, std::uint64_t seed, bool quiet);
/// A search's progress line: generation and violations by type.
std::string search_detail(const touchdown::search::SearchProgress& p);
void keep_weights(const std::shared_ptr<const touchdown::search::QNetwork>& policy, const std::filesystem::path& dir);

}  // namespace touchdown::app::fuzz_app
