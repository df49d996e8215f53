// Plug-in libraries that must be refused (system_registry_test.cpp), one
// per build of this file: TEST_PLUGIN_KIND selects which.
//   1 built against another touchdown version,
//   2 another plug-in ABI,
//   3 registers a name that is taken (opencv-mls),
//   4 registers nothing,
//   5 throws while registering,
//   6 no entry point at all.
// Kinds 1 and 2 abort if their register function is ever called: the host
// must refuse them before it runs any of their code.
#include <cstdlib>
#include <memory>
#include <stdexcept>

#include "gps_lander.hpp"
#include "touchdown/scenario/plugin.hpp"

namespace {

[[maybe_unused]] void must_not_run(touchdown::scenario::PluginRegistrar&) { std::abort(); }

[[maybe_unused]] void register_taken(touchdown::scenario::PluginRegistrar& r) {
  r.add("opencv-mls", "a second opencv-mls", [](const touchdown::scenario::MlsOptions&) {
    return std::make_unique<touchdown::test_plugin::GpsLander>("opencv-mls");
  });
}

[[maybe_unused]] void register_nothing(touchdown::scenario::PluginRegistrar&) {}

[[maybe_unused]] void register_throws(touchdown::scenario::PluginRegistrar&) {
  throw std::runtime_error("no licence file");
}

}  // namespace

#if TEST_PLUGIN_KIND == 1 || TEST_PLUGIN_KIND == 2
extern "C" __attribute__((visibility("default"))) const touchdown::scenario::PluginInfo* touchdown_plugin_info() {
  namespace ts = touchdown::scenario;
#if TEST_PLUGIN_KIND == 1
  static const ts::PluginInfo kInfo{
      ts::kPluginAbiVersion, "0.0.1",           ts::compiler_abi(), ts::standard_library_abi(),
      ts::plugin_layout(),   "another version", &must_not_run};
#else
  static const ts::PluginInfo kInfo{
      ts::kPluginAbiVersion + 41, TOUCHDOWN_VERSION, ts::compiler_abi(), ts::standard_library_abi(),
      ts::plugin_layout(),        "another ABI",     &must_not_run};
#endif
  return &kInfo;
}
#elif TEST_PLUGIN_KIND == 3
TOUCHDOWN_PLUGIN("takes a built-in name", register_taken)
#elif TEST_PLUGIN_KIND == 4
TOUCHDOWN_PLUGIN("registers nothing", register_nothing)
#elif TEST_PLUGIN_KIND == 5
TOUCHDOWN_PLUGIN("throws", register_throws)
#elif TEST_PLUGIN_KIND == 6
extern "C" __attribute__((visibility("default"))) int not_a_touchdown_plugin() { return 6; }
#endif
