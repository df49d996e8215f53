// libFuzzer target for the attitude JSON Lines parser (touchdown/pose/ground_truth.hpp, issue 33).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/ground_truth.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto samples =
        touchdown::pose::parse_attitude(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.jsonl");
    for (const auto& s : samples) {
      // What is read is what the tracker may use: finite unit vectors and a sigma in (0, 90].
      if (!s.g_camera.allFinite() || !s.g_body.allFinite() || !std::isfinite(s.t_s)) __builtin_trap();
      if (std::abs(s.g_camera.norm() - 1) > 1e-12 || std::abs(s.g_body.norm() - 1) > 1e-12) __builtin_trap();
      if (!(s.sigma_deg > 0 && s.sigma_deg <= 90) || s.line == 0) __builtin_trap();
    }
    // No frame twice.
    for (std::size_t i = 0; i < samples.size(); ++i) {
      for (std::size_t j = 0; j < i && samples.size() < 64; ++j) {
        if (samples[i].frame == samples[j].frame) __builtin_trap();
      }
    }
  } catch (const touchdown::Error&) {
  }
  return 0;
}
