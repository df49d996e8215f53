#pragma once
/// \file
/// The landing problem file of `landing_plan` (docs/formats.md, "Landing
/// problem"): the drone's start state, an optional goal, the pad's motion
/// and the planner's options, all in one YAML file. Pad frame, SI units,
/// angles in degrees in the file and radians in the structs.
///
/// Every error is a ParseError "source:line: key: what" naming the key path
/// (`limits.v_max`, `obstacles[2].max`); unknown keys are errors at every
/// level. Thread-safe: pure functions.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/plan/planner.hpp"

namespace touchdown::plan {

/// Everything plan() takes.
struct PlanProblem {
  KinematicState start;                ///< pad frame
  std::optional<KinematicState> goal;  ///< pad frame; empty: default_goal(options)
  PadMotion pad;                       ///< the pad's predicted motion
  PlannerOptions options;              ///< limits, order, segments, durations, corridor, obstacles
  /// Values that parse but look wrong, one line each ("p.yaml:41:
  /// corridor.camera.rpy_deg: [-0.78, 0, 1.57] look like radians ..."): the
  /// library never prints; landing_plan shows them on stderr.
  std::vector<std::string> warnings;
};

/// Parses a problem. Throws ParseError naming `source`, the line and the
/// key for malformed YAML, unknown keys, missing or non-finite numbers and
/// invalid values; the result's options validate.
PlanProblem parse_plan_problem(std::string_view yaml_text, std::string_view source);

/// The planner's keys of a landing problem (limits, order, segments,
/// durations, time, corridor, obstacles) read from the mapping at the
/// dotted `section` of another YAML document ("guidance.planner" of a
/// mission file) into `options`; keys absent keep their values, and no
/// such section reads nothing. Throws ParseError "source:line:
/// section.key: what" for malformed YAML, an unknown key or a bad value,
/// as the document's own reader does (the caller validates the options);
/// InvalidArgument for an empty part in `section`. Warnings as the
/// problem's.
void parse_planner_section(std::string_view yaml_text, std::string_view source, std::string_view section,
                           PlannerOptions& options, std::vector<std::string>& warnings);

/// Reads and parses a problem file (IoError when it cannot be read).
PlanProblem load_plan_problem(const std::string& path);

/// The problem as YAML that parse_plan_problem() reads back to the same
/// values (numbers exact; angles through degrees, so to rounding).
std::string plan_problem_to_yaml(const PlanProblem& problem);

}  // namespace touchdown::plan
