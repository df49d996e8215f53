// libFuzzer target for the extrinsics YAML parser.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/terrain/extrinsics.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto e =
        touchdown::terrain::parse_extrinsics(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed pose is always a proper rigid transform.
    const double det = e.T_world_camera.linear().determinant();
    if (!(det > 0.99 && det < 1.01)) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
