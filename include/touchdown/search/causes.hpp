#pragma once
/// \file
/// The cause of each violation (issue 52; the source's RQ1, "the number of
/// unique violation causes", which it classified by watching videos): a
/// label from a small vocabulary, read from the run's recorded facts
/// (Evaluation::facts) and its scenario. Distinct labels are distinct
/// defects; a search that finds one cause many times has found one defect.
///
/// The vocabulary (<kind>: the object's kind, "tree", "person", "lookalike";
/// <weather>: the scenario's dominant condition, dominant_weather()):
///   Type III    "collision with <kind> while approaching" (searching,
///               tracking, descending, landing: the reference systems'
///               phases), "... during <phase>" for a phase named otherwise
///   Type I      "look-alike accepted", "wrong id accepted",
///               "false positive on pattern", "false positive on <kind>",
///               "false positive on the ground[ (glare)]",
///               "estimate pulled off by false detections", and any of
///               these + " while descending" (committed on the target,
///               then re-aimed by that false detection)
///   off-marker  "drift off the marker after a true detection",
///               "descent aimed off a true detection", "blind landing (no
///               detection)"
///   Type II, fair (the target was observable long enough):
///               "<kind> between camera and target during descent",
///               "descent not completed in <weather>",
///               "target never brought into view in <weather>" (the probe
///               above the marker saw it; the system did not go there),
///               "observable target not detected in <weather>",
///               "sighting not held in <weather>"
///   Type II, unfair: "unfair: target covered by ground snow|ground leaves",
///               "unfair: target hidden by <kind>", "unfair: target not
///               visible in <weather>", "unfair: target <sight>"
/// Results written before issue 52 carry no facts: their causes read
/// "unknown (no facts recorded)".
#include <filesystem>
#include <string>
#include <vector>

#include "touchdown/scenario/scenario.hpp"
#include "touchdown/search/records.hpp"

namespace touchdown::search {

/// The scenario's dominant weather (scenario.hpp).
using scenario::dominant_weather;

/// The kind in an object's name: "static_objects[1] (pole)" → "pole"; the
/// name itself when it has no parenthesis.
std::string object_kind(const std::string& object);

/// The violation's cause label; "" for a run without a violation.
std::string violation_cause(const Evaluation& e, const scenario::Scenario& s);

/// One distinct cause in a results directory.
struct CauseCount {
  std::string cause;
  bool fair = true;
  int count = 0;
  int first_index = 0;   ///< the first record with it (its example)
  std::string scenario;  ///< that record's scenario file, relative to the directory
};

/// The distinct causes of `records`' violations (`scenarios[i]` is record
/// i's scenario), fair ones first, each group by count (descending), then
/// by first appearance.
std::vector<CauseCount> count_causes(const std::vector<EvaluationRecord>& records,
                                     const std::vector<scenario::Scenario>& scenarios);

/// The same for a results directory: reads results.jsonl and each violating
/// record's scenario file. ParseError / IoError naming the file.
std::vector<CauseCount> count_causes(const std::filesystem::path& results_dir);

/// Distinct fair causes among count_causes' result.
int distinct_fair_causes(const std::vector<CauseCount>& causes);

}  // namespace touchdown::search
