#pragma once
// landing_scenario's subcommands, a group per source file
// (landing_scenario.cpp: main, random, campaign; _run: run; _detect:
// dataset, detect, detect-bench; _systems: contract, systems). Each add_X
// declares its subcommand's options on `app` and returns what runs it.
#include <CLI/CLI.hpp>
#include <string>

#include "app_common.hpp"

namespace touchdown::app::scenario_app {

Subcommand add_run(CLI::App& app);
Subcommand add_random(CLI::App& app);
Subcommand add_campaign(CLI::App& app);
Subcommand add_dataset(CLI::App& app);
Subcommand add_detect(CLI::App& app);
Subcommand add_bench(CLI::App& app);
Subcommand add_contract(CLI::App& app);
Subcommand add_systems(CLI::App& app);

/// "DICT:ID" → dictionary and id (checked by DatasetOptions::validate);
/// InvalidArgument naming `option` otherwise.
void parse_marker(const std::string& text, const std::string& option, std::string* dictionary, int* id);

/// The --map name that leaves the map to the random draw.
extern const std::string kAnyMap;

}  // namespace touchdown::app::scenario_app
