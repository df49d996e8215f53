// libFuzzer target for the camera YAML parser (camera.hpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/camera.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto c =
        touchdown::pose::parse_camera(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed camera is always valid ...
    std::string why;
    if (!c.validate(&why)) __builtin_trap();
    // ... and writes back to YAML that parses to the same values.
    const auto again = touchdown::pose::parse_camera(touchdown::pose::camera_to_yaml(c), "again");
    if (again.width != c.width || again.height != c.height || again.fx != c.fx || again.fy != c.fy ||
        again.cx != c.cx || again.cy != c.cy || again.distortion != c.distortion ||
        again.depth_scale != c.depth_scale) {
      __builtin_trap();
    }
    // Projection and undistortion of the principal ray stay finite.
    if (!c.project({0.0, 0.0, 1.0}).allFinite()) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
