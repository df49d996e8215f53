// The plug-in library of system_registry_test.cpp: two systems.
#include <memory>

#include "gps_lander.hpp"
#include "touchdown/scenario/plugin.hpp"

namespace {

void register_systems(touchdown::scenario::PluginRegistrar& r) {
  using touchdown::test_plugin::GpsLander;
  r.add("test-gps-lander", "flies to the GPS target and lands there, camera unused",
        [](const touchdown::scenario::MlsOptions&) { return std::make_unique<GpsLander>("test-gps-lander"); });
  r.add("test-gps-lander-faulty", "test-gps-lander that throws from update() after 3 s",
        [](const touchdown::scenario::MlsOptions&) {
          return std::make_unique<GpsLander>("test-gps-lander-faulty", 3.0);
        });
}

}  // namespace

TOUCHDOWN_PLUGIN("plug-in tests: a GPS lander and a faulty one", register_systems)
