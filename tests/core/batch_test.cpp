// The one batch runner (core/batch.hpp): every job once, results in their
// slots whatever the thread count, the thread rule, progress counting up
// with its ETA, cancellation leaving a prefix, and a job's exception
// stopping the batch.
#include "touchdown/core/batch.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"

namespace touchdown {
namespace {

// Job i's result depends on (seed, i) only, as every loop's does.
std::vector<double> seeded_results(std::size_t n, int threads) {
  std::vector<double> out(n, -1);
  BatchOptions o;
  o.threads = threads;
  const BatchReport r = run_batch(n, o, [&](std::size_t i, std::size_t) {
    Rng rng(7, i);
    double sum = 0;
    for (int k = 0; k < 1000; ++k) sum += rng.uniform();
    out[i] = sum;
  });
  EXPECT_EQ(r.completed, n);
  EXPECT_FALSE(r.cancelled);
  return out;
}

TEST(Batch, SameResultsForAnyThreadCount) {
  const std::vector<double> one = seeded_results(50, 1);
  for (const int threads : {2, 3, 8, 0}) EXPECT_EQ(seeded_results(50, threads), one) << threads << " threads";
  for (const double v : one) EXPECT_GT(v, 0);
}

TEST(Batch, RunsEveryJobOnceOnItsWorkers) {
  const std::size_t n = 200;
  std::vector<std::atomic<int>> runs(n);
  std::vector<std::atomic<int>> worker_of(n);
  BatchOptions o;
  o.threads = 3;
  run_batch(n, o, [&](std::size_t i, std::size_t worker) {
    ++runs[i];
    worker_of[i] = static_cast<int>(worker);
  });
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(runs[i].load(), 1) << i;
    EXPECT_GE(worker_of[i].load(), 0);
    EXPECT_LT(worker_of[i].load(), 3);
  }
}

TEST(Batch, OneWorkerRunsOnTheCallingThreadInOrder) {
  std::vector<std::size_t> order;
  std::set<std::thread::id> ids;
  BatchOptions o;
  o.threads = 1;
  run_batch(5, o, [&](std::size_t i, std::size_t worker) {
    order.push_back(i);
    ids.insert(std::this_thread::get_id());
    EXPECT_EQ(worker, 0u);
  });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  ASSERT_EQ(ids.size(), 1u);
  EXPECT_EQ(*ids.begin(), std::this_thread::get_id());
}

TEST(Batch, TheThreadRule) {
  EXPECT_EQ(resolve_threads(3), 3);
  EXPECT_GE(resolve_threads(0), 1);
  EXPECT_EQ(resolve_threads(0), static_cast<int>(std::max(1u, std::thread::hardware_concurrency())));
  try {
    (void)resolve_threads(-2, "envelope.threads");
    FAIL() << "-2 threads accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_STREQ(e.what(), "envelope.threads: must be >= 0 (0 = every core), got -2");
  }
  std::string why;
  EXPECT_TRUE(check_threads(0, "threads", &why));
  EXPECT_FALSE(check_threads(-1, "threads", &why));
  EXPECT_EQ(why, "threads: must be >= 0 (0 = every core), got -1");
  EXPECT_EQ(batch_workers(0, 4), 1u);
  EXPECT_EQ(batch_workers(2, 4), 2u);
  EXPECT_EQ(batch_workers(10, 4), 4u);
  BatchOptions o;
  o.threads = -1;
  EXPECT_THROW(run_batch(3, o, [](std::size_t, std::size_t) {}), InvalidArgument);
}

TEST(Batch, ProgressCountsUpWithEachIndexOnce) {
  const std::size_t n = 40;
  std::vector<Progress> calls;
  BatchOptions o;
  o.threads = 2;
  o.progress = [&](const Progress& p) { calls.push_back(p); };  // serialised: no lock needed
  run_batch(n, o, [](std::size_t, std::size_t) {});
  ASSERT_EQ(calls.size(), n);
  std::set<std::size_t> indices;
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(calls[k].done, k + 1);
    EXPECT_EQ(calls[k].total, n);
    EXPECT_GE(calls[k].eta_s, 0);
    indices.insert(calls[k].index);
  }
  EXPECT_EQ(indices.size(), n);
  EXPECT_EQ(*indices.rbegin(), n - 1);
  EXPECT_DOUBLE_EQ(calls.back().eta_s, 0);
}

// The ETA is the mean rate's: after 1 of 4 jobs in t seconds, 3 t remain.
TEST(Batch, TheEtaIsTheMeanRates) {
  const auto start = std::chrono::steady_clock::now() - std::chrono::seconds(10);
  const Progress p = progress_since(start, 1, 4, 0);
  EXPECT_NEAR(p.elapsed_s, 10, 0.5);
  EXPECT_NEAR(p.eta_s, 3 * p.elapsed_s, 1e-9);
  EXPECT_EQ(progress_since(start, 0, 4, 0).eta_s, -1);
  EXPECT_EQ(progress_since(start, 4, 4, 3).eta_s, 0);
}

TEST(Batch, CancellationLeavesTheCompletedPrefix) {
  for (const int threads : {1, 2, 4}) {
    const std::size_t n = 100;
    std::atomic<bool> cancel{false};
    std::vector<std::atomic<int>> ran(n);
    BatchOptions o;
    o.threads = threads;
    o.cancel = &cancel;
    // 1 ms a job, so that the other workers take only a few jobs more
    // while job 10 cancels.
    const BatchReport r = run_batch(n, o, [&](std::size_t i, std::size_t) {
      ++ran[i];
      if (i == 10) cancel = true;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    });
    EXPECT_TRUE(r.cancelled) << threads;
    EXPECT_GE(r.completed, 11u) << threads;
    EXPECT_LT(r.completed, n) << threads;
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(ran[i].load(), i < r.completed ? 1 : 0) << i << ", " << threads;
  }
  std::atomic<bool> already{true};
  BatchOptions o;
  o.cancel = &already;
  int count = 0;
  const BatchReport none = run_batch(5, o, [&](std::size_t, std::size_t) { ++count; });
  EXPECT_EQ(none.completed, 0u);
  EXPECT_EQ(count, 0);
}

TEST(Batch, AJobsExceptionStopsTheBatchAndPropagates) {
  for (const int threads : {1, 2}) {
    std::atomic<int> started{0};
    BatchOptions o;
    o.threads = threads;
    EXPECT_THROW(run_batch(1000, o,
                           [&](std::size_t i, std::size_t) {
                             ++started;
                             if (i == 3) throw std::runtime_error("job 3 failed");
                             std::this_thread::sleep_for(std::chrono::microseconds(200));
                           }),
                 std::runtime_error);
    EXPECT_LT(started.load(), 1000) << threads;  // the others stopped
  }
  BatchOptions o;
  o.threads = 1;
  o.progress = [](const Progress& p) {
    if (p.done == 2) throw InvalidArgument("stop");
  };
  int ran = 0;
  EXPECT_THROW(run_batch(10, o, [&](std::size_t, std::size_t) { ++ran; }), InvalidArgument);
  EXPECT_EQ(ran, 2);
}

TEST(Batch, AnEmptyBatchRunsNothing) {
  int count = 0;
  const BatchReport r = run_batch(0, BatchOptions{}, [&](std::size_t, std::size_t) { ++count; });
  EXPECT_EQ(count, 0);
  EXPECT_EQ(r.completed, 0u);
  EXPECT_FALSE(r.cancelled);
}

}  // namespace
}  // namespace touchdown
