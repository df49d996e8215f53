#pragma once
/// \file
/// Why did it fail? (beyond the RLaGA paper, which classified causes by
/// watching videos): a violating scenario is shrunk by resetting its genes
/// to benign values one group at a time — each weather property to a clear
/// day's, each object and distractor removed, the scene's seed and the
/// marker's position to the base's — keeping every reset after which the
/// same violation type still happens. What is left is a smallest scenario
/// that still fails, and the groups whose reset made it pass (or fail
/// differently) are the ones its failure needs: a tested cause.
///
/// Greedy and one pass (delta debugging's "1-minimal" per group, Zeller &
/// Hildebrandt 2002): the result depends on the order of the groups, which
/// is fixed (objects, then distractors, then weather, then seed and
/// marker), so the same scenario always shrinks the same way.
#include <functional>
#include <string>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/search/search.hpp"

namespace touchdown::search {

/// One tried reset.
struct ShrinkStep {
  std::string gene;  ///< e.g. "weather.fog", "static_objects[2] (box)", "marker.position"
  scenario::Violation outcome = scenario::Violation::None;  ///< of the run with the reset
  std::string message;                                      ///< that run's outcome line
  bool kept = false;                                        ///< the reset kept the violation type: it stays reset
  /// False when the reset would make the scenario invalid (not run, not
  /// counted as necessary; `message` says why).
  bool tried = true;
};

enum class ShrinkStatus {
  Shrunk,        ///< the violation happened and `smallest` still has it
  NotViolating,  ///< the scenario given did not violate: nothing to shrink
};

}  // namespace touchdown::search

template <>
struct touchdown::EnumNames<touchdown::search::ShrinkStatus> {
  static constexpr std::array<std::string_view, 2> names{"shrunk", "not_violating"};
};

namespace touchdown::search {

inline std::string_view to_string(ShrinkStatus s) { return enum_name(s); }

struct ShrinkResult {
  ShrinkStatus status = ShrinkStatus::NotViolating;
  scenario::Violation violation = scenario::Violation::None;  ///< the original run's
  std::string message;                                        ///< the original run's outcome line
  scenario::Scenario smallest;                                ///< every kept reset applied
  std::vector<std::string> necessary;                         ///< genes whose reset lost the violation type
  std::vector<ShrinkStep> steps;                              ///< in the order tried
  [[nodiscard]] int runs() const { return 1 + static_cast<int>(steps.size()); }
  [[nodiscard]] bool ok() const { return status == ShrinkStatus::Shrunk; }
};

/// Shrinks `scenario` with runs on `evaluator` (one at a time: each step
/// depends on the one before). `base` gives the benign seed and marker
/// position. `progress(done, total)` after each run (total = runs at most).
ShrinkResult shrink(const scenario::Scenario& scenario, const scenario::Scenario& base, Evaluator& evaluator,
                    const ProgressCallback& progress = {});

}  // namespace touchdown::search
