#pragma once
// The sweep's decision mode (internal; SweepOptions::decide): flies only the
// landings that can change the decision, in deterministic waves.
#include <chrono>

#include "touchdown/twin/sweep.hpp"

namespace touchdown::twin::internal {

/// Lands one run in the twin, its result and wall time into the record
/// (what both the full sweep and the decision mode fly).
void fly_run(RunRecord& run, const LandingSimulator& sim);

/// Flies `out.runs` (planned for every heading × run, heading-major) in
/// waves and keeps only the landings flown, heading-major; sets each
/// heading's HeadingScore::flown, `out.decided`, `out.completeness` (the
/// share of the full sweep's landings flown). Needs `out.threshold` and
/// each heading's `unobserved` (place_headings) set.
///
/// The decision equals the full sweep's: the same chosen heading, the same
/// S of it (all its runs flown, with the same conditions), the same
/// safe/unsafe. A heading is unsafe at its first run that is invalid, tips
/// or strikes (the full metric) or ends at or above the threshold; S is the
/// maximum over runs, so a heading whose worst run so far is above the best
/// complete safe heading's S (or equal with a higher index: ties go to the
/// lower heading) cannot be chosen. Without a safe heading the full sweep
/// reports the lowest S among the scored ones: a second phase flies on with
/// the same bound over scored headings.
///
/// Waves: run 0 of every heading still in play; then, while no heading is
/// complete, every remaining run of the most promising one (the lowest
/// worst run, then the lower index); then the next run of every heading
/// still in play. Each wave is chosen from the earlier waves' results only,
/// so the result is the same for any thread count.
///
/// `deadline` > 0: no wave starts after that many seconds since `t0`; the
/// headings still in play are HeadingFlown::UntilDeadline, `decided` false.
/// With a deadline the second phase is not flown: "do not land" is settled
/// when every heading is unsafe, and the lowest S reported is the lowest so
/// far.
void fly_decisive(SweepResult& out, const LandingSimulator& sim, const SweepOptions& o,
                  std::chrono::steady_clock::time_point t0);

}  // namespace touchdown::twin::internal
