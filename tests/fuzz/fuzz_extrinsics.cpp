// libFuzzer target for the extrinsics YAML parser.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/terrain/extrinsics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto e =
        touchdown::terrain::parse_extrinsics(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed pose is always a proper rigid transform.
    for (const auto* T : {&e.T_world_camera, &e.T_body_camera}) {
      const double det = T->linear().determinant();
      if (!(det > 0.99 && det < 1.01) || !T->matrix().allFinite()) __builtin_trap();
    }
    // Warnings are one line each and name the file (the apps print them as is).
    for (const auto& w : e.warnings) {
      if (w.find('\n') != std::string::npos || w.rfind("fuzz.yaml", 0) != 0) __builtin_trap();
    }
  } catch (const touchdown::Error&) {
  }
  return 0;
}
