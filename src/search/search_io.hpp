#pragma once
// The results directory's campaign.json and state.json (docs/formats.md,
// "Violation search results directory"); private to the search module.
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/search/search.hpp"

namespace touchdown::search::detail {

/// campaign.json: what the campaign was asked to do (every option that
/// changes its results), as indented JSON with a trailing newline.
std::string campaign_config(const SearchOptions& options);
/// Empty when the two campaign.json texts ask for the same campaign; else
/// "KEY: the directory's campaign has A, this one B" for the first key that
/// differs. Throws ParseError naming `source` when `on_disk` is not a
/// campaign.json.
std::string config_difference(std::string_view on_disk, std::string_view wanted, std::string_view source);

/// state.json: the pool after the last finished generation.
struct PoolMember {
  int index = 0;  ///< its line in results.jsonl (0-based)
  Chromosome chromosome;
};
struct PoolState {
  int generation = -1;  ///< the last finished generation; -1: none
  int evaluated = 0;    ///< scenarios evaluated by the end of it
  std::vector<PoolMember> pool;
};
std::string state_json(const PoolState& state);
/// Throws ParseError naming `source` and the key.
PoolState parse_state(std::string_view text, std::string_view source);

}  // namespace touchdown::search::detail
