#pragma once
/// \file
/// The violation search's metrics (RLaGA paper, §4.3), computed from a
/// results file's records (records.hpp). Definitions and the choices the
/// source leaves open are in docs/architecture.md, "The violation
/// search" → "Metrics". Pure functions, thread-safe.
#include <optional>
#include <vector>

#include "touchdown/search/records.hpp"

namespace touchdown::search {

/// Which violations the metrics count: every one (the source's
/// definition, Table 2's comparison) or only the fair ones (Facts::fair:
/// not a Type II whose target was never observable long enough).
enum class Count { All, Fair };

struct SearchMetrics {
  int evaluated = 0;   ///< scenarios evaluated (records)
  int violations = 0;  ///< of them, with a violation of any type (counted)
  int type_i = 0, type_ii = 0, type_iii = 0;
  int off_marker = 0;  ///< landed off the marker after a true detection (or none)
  /// Violations the oracle found unfair: with Count::All counted in the
  /// figures above, with Count::Fair left out of them.
  int unfair = 0;
  /// Runs in which the system under test failed (threw, or answered a
  /// non-finite command): not violations, counted apart.
  int system_failed = 0;
  /// Every record carries its facts (results written since issue 52);
  /// false: fairness unknown, every violation counted as fair.
  bool facts_recorded = true;
  double violation_percent = 0;  ///< 100 × violations / evaluated; 0 when nothing was evaluated
  /// Scenarios evaluated until the K-th violation, that one included (a
  /// count, 1-based); nullopt: fewer than K violations.
  std::optional<int> top_k;
  /// Rounds until Types I, II and III have all appeared: a round is one
  /// evaluated scenario (not a generation), so this is the count of
  /// scenarios evaluated until the first scenario that completes the set,
  /// that one included; nullopt: some type never appeared.
  std::optional<int> rounds_all_types;
  /// eq. 7: the mean Euclidean distance over all pairs of violating
  /// scenarios between their normalised genes (each in [0, 1]), divided by
  /// sqrt(dimension) so that it lies in [0, 1]; 0 with fewer than 2
  /// violating scenarios or no genes.
  double parameter_distance = 0;
  /// Distinct kCoverageCell-sized cells visited by violating runs (the
  /// union of their Evaluation::cells): the 3-D trajectory coverage.
  int coverage_cells = 0;
};

/// Every metric over `records`, which must be in index order (record i has
/// index i) with genes of one length among the violating ones
/// (InvalidArgument otherwise, as for k < 1). `k`: Top-K's K.
/// `count`: every violation or the fair ones only (Top-K, rounds, distance
/// and coverage then over the fair ones too).
SearchMetrics compute_metrics(const std::vector<EvaluationRecord>& records, int k = 10, Count count = Count::All);

/// Violations found after each evaluation: element i counts the violating
/// (`count`) records among records[0..i].
std::vector<int> cumulative_violations(const std::vector<EvaluationRecord>& records, Count count = Count::All);

}  // namespace touchdown::search
