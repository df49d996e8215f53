// libFuzzer target for the airframe YAML parser (twin/airframe.hpp).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/threshold.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto a =
        touchdown::twin::parse_airframe(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed airframe is always valid, with a finite positive mass and a
    // finite centre of mass and inertia ...
    std::string why;
    if (!a.validate(&why)) __builtin_trap();
    if (!(a.total_mass() > 0) || !std::isfinite(a.total_mass())) __builtin_trap();
    if (!a.centre_of_mass().allFinite() || !a.inertia_about_com().allFinite()) __builtin_trap();
    // ... whose safety threshold is a finite angle.
    const auto t = touchdown::twin::compute_safety_threshold(a);
    if (!std::isfinite(t.value())) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
