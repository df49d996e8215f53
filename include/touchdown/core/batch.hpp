#pragma once
/// \file
/// The one batch runner under every closed loop that runs many independent
/// jobs: the sweep's landings, the mission envelope's missions, a
/// campaign's scenarios (and through it the search's evaluations). One
/// thread rule, one progress signature, cancellation, and no process-wide
/// setting changed (no `tbb::global_control`): two batches in one process
/// each keep their own thread count.
///
/// Determinism: jobs are handed out in index order and each job writes only
/// its own result slot, so a batch's results do not depend on the thread
/// count. Each loop seeds job i from (its seed, a stream made of i) through
/// `Rng(seed, stream)` (random.hpp) — never from a thread or a clock:
///   sweep        run r at heading h:  Rng(seed, h · 1000003 + r)
///   mission      run i:               Rng(seed, 8 i + k), k = vehicle 0, perception 1
///   campaign     scenario i:          random_scenario(first_seed + i, map)
/// These three mappings predate the runner; they are kept because every
/// recorded reference (golden sweeps, the 48 scenario outcomes, kept
/// campaigns, the mission figures) depends on them.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>

namespace touchdown {

/// Where a batch stands, for a progress bar: `done` of `total` jobs
/// finished (1, 2, …, total over the calls), the latest being job `index`,
/// `elapsed_s` since the batch began and `eta_s`, the remaining time at the
/// mean rate so far (−1 until the first job finished).
struct Progress {
  std::size_t done = 0, total = 0, index = 0;
  double elapsed_s = 0;
  double eta_s = -1;
};

/// `done` of `total` (the latest job `index`) at this moment of work begun
/// at `start`, with its ETA: for a loop that reports progress across
/// several batches.
Progress progress_since(std::chrono::steady_clock::time_point start, std::size_t done, std::size_t total,
                        std::size_t index);

/// The one progress signature. Called once after each job finishes, from
/// the worker that ran it but one call at a time (under a lock). An
/// exception from it stops the batch and propagates.
using ProgressCallback = std::function<void(const Progress&)>;

/// The one thread rule: 0 = every core (std::thread::hardware_concurrency,
/// at least 1), n ≥ 1 = n threads; negative is refused (InvalidArgument,
/// naming `key`).
int resolve_threads(int threads, const std::string& key = "threads");

/// For Options::validate: false (with `why` = "KEY: must be >= 0 (0 = every
/// core)") when `threads` is negative.
bool check_threads(int threads, const std::string& key, std::string* why);

struct BatchOptions {
  int threads = 0;            ///< the thread rule above
  ProgressCallback progress;  ///< may be empty
  /// When it becomes true, no further job starts; the jobs running finish.
  /// May be null.
  const std::atomic<bool>* cancel = nullptr;
};

struct BatchReport {
  /// Jobs [0, completed) ran to their end (all of them unless cancelled).
  std::size_t completed = 0;
  bool cancelled = false;
  double wall_s = 0;
};

/// Workers a batch of `jobs` uses: min(resolve_threads(threads), jobs), at
/// least 1.
std::size_t batch_workers(std::size_t jobs, int threads);

/// Runs job(index, worker) for every index in [0, jobs), on
/// batch_workers(jobs, options.threads) threads (on the calling thread
/// alone when that is 1). `worker` in [0, batch_workers) names the thread
/// that runs the job, for per-thread state (one landing system per worker).
/// An exception from a job stops the other workers after their current job
/// and the first one caught is rethrown once all have stopped.
BatchReport run_batch(std::size_t jobs, const BatchOptions& options,
                      const std::function<void(std::size_t index, std::size_t worker)>& job);

}  // namespace touchdown
