// libFuzzer target for the landing scenario reader (scenario/scenario.hpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/scenario/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace scn = touchdown::scenario;
  try {
    const auto s = scn::parse_scenario(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed scenario is always valid ...
    std::string why;
    if (!s.validate(&why)) __builtin_trap();
    // ... and reads back exactly from what the writers make of it.
    if (!(scn::parse_scenario(scn::to_yaml(s), "fuzz.yaml") == s)) __builtin_trap();
    if (!(scn::parse_scenario(scn::to_json(s), "fuzz.json") == s)) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
