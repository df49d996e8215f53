#include "twin/sweep_decide.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "touchdown/core/batch.hpp"

namespace touchdown::twin::internal {
namespace {

// What the waves know of one heading.
struct Track {
  int flown = 0;                                            // runs 0..flown-1 flown
  double worst = -std::numeric_limits<double>::infinity();  // max final nutation of its settled runs
  bool scored = false;                                      // a run settled
  bool unsafe = false;                                      // a run disqualified it (or unobserved terrain)
  bool outranked = false;                                   // cannot be chosen
  [[nodiscard]] bool complete(int m) const { return flown == m; }
};

// (worst, index) ordering: the full sweep's argmin with ties to the lower index.
bool ranks_before(const Track& a, int ia, const Track& b, int ib) {
  return a.worst < b.worst || (a.worst == b.worst && ia < ib);
}

// Does this settled or unsettled run make its heading unsafe?
bool disqualifies(const RunResult& r, const SweepOptions& o, double threshold) {
  if (!r.ok()) return true;
  if (o.metric == SafetyMetric::Full && (r.tipped || r.body_strike > 0 || r.arm_strike > 0 || r.prop_strike > 0)) {
    return true;
  }
  return !(r.nutation < threshold);
}

}  // namespace

void fly_run(RunRecord& run, const LandingSimulator& sim) {
  const auto start = std::chrono::steady_clock::now();
  run.result = sim.land(run.conditions);
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void fly_decisive(SweepResult& out, const LandingSimulator& sim, const SweepOptions& o,
                  std::chrono::steady_clock::time_point t0) {
  const int n = o.headings, m = o.runs;
  const double threshold = out.threshold.value();
  std::vector<Track> tracks(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j)
    tracks[static_cast<std::size_t>(j)].unsafe = out.headings[static_cast<std::size_t>(j)].unobserved;
  std::vector<char> flown(out.runs.size(), 0);
  const std::size_t total = out.runs.size();
  std::size_t done = 0;
  BatchOptions batch;
  batch.threads = o.threads;
  if (o.progress) {
    batch.progress = [&](const Progress& p) { o.progress(progress_since(t0, ++done, total, p.index)); };
  }
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  const auto at = [m](int j, int i) {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(m) + static_cast<std::size_t>(i);
  };

  bool second_phase = false, stopped = false;
  std::vector<std::size_t> wave;
  for (;;) {
    // The bound: the best complete heading that can be chosen (safe in the
    // first phase, scored in the second).
    int bound = -1;
    for (int j = 0; j < n; ++j) {
      const Track& t = tracks[static_cast<std::size_t>(j)];
      const bool eligible = second_phase ? t.scored : !t.unsafe;
      if (t.complete(m) && eligible &&
          (bound < 0 || ranks_before(t, j, tracks[static_cast<std::size_t>(bound)], bound))) {
        bound = j;
      }
    }
    // Still in play: not complete, not out of this phase, not outranked.
    std::vector<int> live;
    for (int j = 0; j < n; ++j) {
      Track& t = tracks[static_cast<std::size_t>(j)];
      if (t.complete(m) || (!second_phase && t.unsafe)) continue;
      if (bound >= 0 && (second_phase ? t.scored : t.flown > 0) &&
          ranks_before(tracks[static_cast<std::size_t>(bound)], bound, t, j)) {
        t.outranked = true;
        continue;
      }
      t.outranked = false;
      live.push_back(j);
    }
    if (live.empty()) {
      // No safe heading: "do not land" is settled. Without a deadline, on
      // to the lowest S among the scored headings, as the full sweep
      // reports it; with one, that is not worth the time.
      if (second_phase || bound >= 0 || o.deadline > 0) break;
      second_phase = true;
      continue;
    }
    if (o.deadline > 0 && elapsed() >= o.deadline) {
      stopped = true;
      break;
    }
    wave.clear();
    for (const int j : live) {
      if (tracks[static_cast<std::size_t>(j)].flown == 0) wave.push_back(at(j, 0));
    }
    if (wave.empty() && bound < 0) {
      int c = live.front();
      for (const int j : live) {
        if (ranks_before(tracks[static_cast<std::size_t>(j)], j, tracks[static_cast<std::size_t>(c)], c)) c = j;
      }
      for (int i = tracks[static_cast<std::size_t>(c)].flown; i < m; ++i) wave.push_back(at(c, i));
    } else if (wave.empty()) {
      for (const int j : live) wave.push_back(at(j, tracks[static_cast<std::size_t>(j)].flown));
    }
    run_batch(wave.size(), batch, [&](std::size_t k, std::size_t) { fly_run(out.runs[wave[k]], sim); });
    for (const std::size_t k : wave) {
      const RunRecord& r = out.runs[k];
      Track& t = tracks[static_cast<std::size_t>(r.heading)];
      flown[k] = 1;
      t.flown = std::max(t.flown, r.run + 1);
      if (r.result.ok()) {
        t.scored = true;
        t.worst = std::max(t.worst, r.result.nutation);
      }
      t.unsafe = t.unsafe || disqualifies(r.result, o, threshold);
    }
  }
  // Only the landings flown, heading-major; how far each heading went.
  std::vector<RunRecord> kept;
  kept.reserve(static_cast<std::size_t>(std::count(flown.begin(), flown.end(), 1)));
  for (std::size_t k = 0; k < out.runs.size(); ++k) {
    if (flown[k] != 0) kept.push_back(std::move(out.runs[k]));
  }
  out.runs = std::move(kept);
  for (int j = 0; j < n; ++j) {
    const Track& t = tracks[static_cast<std::size_t>(j)];
    HeadingFlown& f = out.headings[static_cast<std::size_t>(j)].flown;
    if (t.complete(m)) {
      f = HeadingFlown::All;
    } else if (t.outranked) {
      f = HeadingFlown::UntilOutranked;
    } else if (t.unsafe) {
      f = HeadingFlown::UntilUnsafe;
    } else {
      f = HeadingFlown::UntilDeadline;
    }
  }
  out.decided = !stopped;
  out.completeness = static_cast<double>(out.runs.size()) / static_cast<double>(total);
  if (o.progress) o.progress(progress_since(t0, total, total, total > 0 ? total - 1 : 0));
}

}  // namespace touchdown::twin::internal
