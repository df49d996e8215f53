// DQN benchmarks (issue 32; docs/benchmarks.md, "Violation search" → "DQN"):
// pre-training on the surrogate (800 episodes, the source's count; target
// ≤ 30 s on one core) and one greedy inference. The training benchmark
// also reports the trained greedy policy's mean eq. 5 return on 100 fresh
// surrogate episodes and a uniform random policy's on the same episodes.
#include <benchmark/benchmark.h>

#include "touchdown/search/dqn.hpp"
#include "touchdown/search/surrogate.hpp"

namespace {

using namespace touchdown;
using namespace touchdown::search;

void BM_TrainDqn800(benchmark::State& state) {
  const SurrogateOptions env;
  DqnTraining trained{QNetwork(24), {}};
  for (auto _ : state) {
    trained = train_dqn({}, env, 800, 1);
    benchmark::DoNotOptimize(trained.network);
  }
  const QNetwork& net = trained.network;
  state.counters["greedy_return"] = surrogate_mean_return(
      env, [&](const DqnState& s, Rng&) { return net.greedy(s); }, 100, 7);
  state.counters["random_return"] = surrogate_mean_return(
      env, [](const DqnState&, Rng& rng) { return static_cast<int>(rng.uniform() * kDqnActions); }, 100, 7);
  double last = 0;
  for (std::size_t i = trained.episode_returns.size() - 100; i < trained.episode_returns.size(); ++i)
    last += trained.episode_returns[i] / 100;
  state.counters["last100_train_return"] = last;
}
BENCHMARK(BM_TrainDqn800)->Unit(benchmark::kSecond)->Iterations(1);

void BM_GreedyInference(benchmark::State& state) {
  Rng rng(3);
  QNetwork net(24);
  net.initialise(rng);
  DqnState s{1.5, -2.0, 3.0, 0.5};
  for (auto _ : state) {
    benchmark::DoNotOptimize(net.greedy(s));
    s[0] += 1e-9;
  }
}
BENCHMARK(BM_GreedyInference);

}  // namespace

BENCHMARK_MAIN();
