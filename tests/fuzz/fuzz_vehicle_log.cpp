// libFuzzer target for the vehicle log reader (mission/vehicle_log.hpp): a
// log either parses or throws ParseError; a parsed one samples finite
// motion anywhere (inside, before and long after it), exact or smoothed,
// and round-trips through its CSV.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/mission/vehicle_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using touchdown::mission::VehicleLog;
  // Exact rows, and smoothed (the missions' default window).
  for (const double smoothing : {0.0, 2.0}) {
    try {
      const VehicleLog log =
          VehicleLog::parse(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.csv", 1.0, smoothing);
      for (const double t : {-1.0, 0.0, 0.37 * log.duration(), log.duration(), log.duration() + 10}) {
        const auto m = log.sample(t);
        if (!m.position.allFinite() || !std::isfinite(m.yaw) || !std::isfinite(m.speed) || !std::isfinite(m.yaw_rate) ||
            !std::isfinite(m.acceleration)) {
          __builtin_trap();
        }
      }
      const VehicleLog again = VehicleLog::parse(log.to_csv(), "again.csv");
      if (again.rows().size() != log.rows().size()) __builtin_trap();
    } catch (const touchdown::ParseError&) {
    }
  }
  return 0;
}
