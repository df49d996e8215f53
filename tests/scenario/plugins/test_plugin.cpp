// The plug-in library of system_registry_test.cpp and of the contract
// command's app test: the GPS lander, a faulty one, and two that break the
// LandingSystem contract (state kept across reset(); state shared by all
// objects, so that two fresh objects differ).
#include <atomic>
#include <memory>

#include "gps_lander.hpp"
#include "touchdown/scenario/plugin.hpp"

namespace {

namespace ts = touchdown::scenario;

// Its descent speed creeps up with every run the object has flown.
class Stateful final : public ts::LandingSystem {
 public:
  [[nodiscard]] std::string_view name() const override { return "test-stateful"; }
  void reset(const ts::SystemSetup&) override { ++runs_; }
  ts::SystemOutput update(const ts::SystemInput&) override {
    ts::SystemOutput out;
    out.command.velocity_world = {0, 0, -0.1 * runs_};
    return out;
  }

 private:
  int runs_ = 0;
};

// Counts steps in a process-wide counter: no two objects see the same.
std::atomic<long> g_shared_steps{0};
class Shared final : public ts::LandingSystem {
 public:
  [[nodiscard]] std::string_view name() const override { return "test-shared"; }
  void reset(const ts::SystemSetup&) override {}
  ts::SystemOutput update(const ts::SystemInput&) override {
    ts::SystemOutput out;
    out.command.velocity_world = {1e-6 * static_cast<double>(g_shared_steps++ % 1000), 0, 0};
    return out;
  }
};

void register_systems(touchdown::scenario::PluginRegistrar& r) {
  using touchdown::test_plugin::GpsLander;
  r.add("test-gps-lander", "flies to the GPS target and lands there, camera unused", "none: fixed gains",
        [](const touchdown::scenario::MlsOptions&) { return std::make_unique<GpsLander>("test-gps-lander"); });
  r.add("test-gps-lander-faulty", "test-gps-lander that throws from update() after 3 s",
        [](const touchdown::scenario::MlsOptions&) {
          return std::make_unique<GpsLander>("test-gps-lander-faulty", 3.0);
        });
  r.add("test-stateful", "keeps state across reset() (breaks the contract)",
        [](const ts::MlsOptions&) { return std::make_unique<Stateful>(); });
  r.add("test-shared", "objects share a step counter: not deterministic (breaks the contract)",
        [](const ts::MlsOptions&) { return std::make_unique<Shared>(); });
}

}  // namespace

TOUCHDOWN_PLUGIN("plug-in tests: a GPS lander, a faulty one, two that break the contract", register_systems)
