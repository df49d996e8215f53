#pragma once
// The planner's options as YAML (internal): the keys of the landing problem
// file's planner part (docs/formats.md, "Landing problem": limits, order,
// segments, durations, time, corridor, obstacles), read under a key prefix so
// that another file can hold them in a section (the mission's
// `guidance.planner`). Errors name the prefixed key.
#include <string>
#include <vector>

#include "core/yaml_util.hpp"
#include "touchdown/plan/planner.hpp"

namespace touchdown::plan::io {

/// The planner keys that read_planner() reads.
inline constexpr const char* kPlannerKeys[] = {"limits", "order",    "segments", "durations",
                                               "time",   "corridor", "obstacles"};

/// Reads the planner keys present in `map` into `options` (the others keep
/// their values); `at` prefixes every key in messages ("" or "section.").
void read_planner(const touchdown::detail::YamlReader& r, const YAML::Node& map, const std::string& at,
                  bool limits_required, PlannerOptions& options, std::vector<std::string>& warnings);

}  // namespace touchdown::plan::io
