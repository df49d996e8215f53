// libFuzzer target for the ground-truth JSON Lines parser (touchdown/pose/ground_truth.hpp).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/ground_truth.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto samples =
        touchdown::pose::parse_ground_truth(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.jsonl");
    for (const auto& s : samples) {
      // A parsed pose is always a finite proper rigid transform.
      const double det = s.T_camera_body.linear().determinant();
      if (!(det > 0.99 && det < 1.01)) __builtin_trap();
      if (!s.T_camera_body.matrix().allFinite() || !std::isfinite(s.t_s)) __builtin_trap();
      // What we parsed writes back to a line that parses again.
      const auto again = touchdown::pose::parse_ground_truth(touchdown::pose::ground_truth_to_json(s), "again");
      if (again.size() != 1 || again[0].frame != s.frame || again[0].t_s != s.t_s ||
          again[0].leds_visible != s.leds_visible) {
        __builtin_trap();
      }
    }
  } catch (const touchdown::Error&) {
  }
  return 0;
}
