#include "touchdown/core/batch.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "touchdown/core/error.hpp"

namespace touchdown {

bool check_threads(int threads, const std::string& key, std::string* why) {
  if (threads >= 0) return true;
  if (why != nullptr) *why = key + ": must be >= 0 (0 = every core), got " + std::to_string(threads);
  return false;
}

int resolve_threads(int threads, const std::string& key) {
  std::string why;
  if (!check_threads(threads, key, &why)) throw InvalidArgument(why);
  if (threads > 0) return threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

std::size_t batch_workers(std::size_t jobs, int threads) {
  return std::max<std::size_t>(1, std::min(jobs, static_cast<std::size_t>(resolve_threads(threads))));
}

Progress progress_since(std::chrono::steady_clock::time_point start, std::size_t done, std::size_t total,
                        std::size_t index) {
  Progress p;
  p.done = done;
  p.total = total;
  p.index = index;
  p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (done > 0)
    p.eta_s = p.elapsed_s / static_cast<double>(done) * static_cast<double>(total > done ? total - done : 0);
  return p;
}

BatchReport run_batch(std::size_t jobs, const BatchOptions& options,
                      const std::function<void(std::size_t index, std::size_t worker)>& job) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t workers = batch_workers(jobs, options.threads);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};  // a job failed
  std::mutex progress_mutex;
  std::size_t done = 0;  // guarded by progress_mutex
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const auto cancelled = [&] { return options.cancel != nullptr && options.cancel->load(); };

  const auto work = [&](std::size_t worker) {
    try {
      while (!stop.load() && !cancelled()) {
        const std::size_t i = next++;
        if (i >= jobs) break;
        job(i, worker);
        if (options.progress) {
          const std::lock_guard lock(progress_mutex);
          options.progress(progress_since(t0, ++done, jobs, i));
        }
      }
    } catch (...) {
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
    }
  };
  if (workers <= 1) {
    work(0);
  } else {
    std::vector<std::jthread> pool;
    pool.reserve(workers);
    for (std::size_t w = 0; w < workers; ++w) pool.emplace_back(work, w);
  }  // joined here
  if (failure) std::rethrow_exception(failure);
  BatchReport report;
  // Indices are handed out in order and every started job finished, so the
  // completed ones are a prefix.
  report.completed = std::min(next.load(), jobs);
  report.cancelled = report.completed < jobs;
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace touchdown
