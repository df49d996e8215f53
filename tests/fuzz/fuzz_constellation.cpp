// libFuzzer target for the LED constellation YAML parser (constellation.hpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/constellation.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto k =
        touchdown::pose::parse_constellation(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed constellation is always valid, with a rigid marker pose ...
    std::string why;
    if (!k.validate(&why)) __builtin_trap();
    const double det = k.T_body_marker.linear().determinant();
    if (!(det > 0.99 && det < 1.01) || !k.T_body_marker.matrix().allFinite()) __builtin_trap();
    // ... and writes back to YAML that parses to the same LEDs.
    const auto again = touchdown::pose::parse_constellation(touchdown::pose::constellation_to_yaml(k), "again");
    if (again.leds.size() != k.leds.size()) __builtin_trap();
    for (std::size_t i = 0; i < k.leds.size(); ++i) {
      if (again.leds[i].p_body != k.leds[i].p_body || again.leds[i].color != k.leds[i].color) __builtin_trap();
    }
    if (again.T_body_marker.translation() != k.T_body_marker.translation()) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
