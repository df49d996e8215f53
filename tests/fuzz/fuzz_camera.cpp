// libFuzzer target for the camera file parser (camera.hpp): touchdown's
// camera YAML, OpenCV calibration files and ROS camera_info YAML (the
// seeds hold one of each), and the depth_scale check on the same bytes
// taken as a 16-bit depth image.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/camera.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace tp = touchdown::pose;
  try {
    const auto c = tp::parse_camera(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // A parsed camera is always valid ...
    std::string why;
    if (!c.validate(&why)) __builtin_trap();
    // ... and writes back to touchdown's YAML that parses to the same values.
    const auto again = tp::parse_camera(tp::camera_to_yaml(c), "again");
    if (again.width != c.width || again.height != c.height || again.fx != c.fx || again.fy != c.fy ||
        again.cx != c.cx || again.cy != c.cy || again.distortion != c.distortion ||
        again.depth_scale != c.depth_scale) {
      __builtin_trap();
    }
    // Projection and undistortion of the principal ray stay finite.
    if (!c.project({0.0, 0.0, 1.0}).allFinite()) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  // The bytes as a depth image 16 pixels wide: the median is one of its
  // nonzero pixels, and an implausible verdict always says why.
  std::vector<std::uint16_t> pixels(size / 2);
  if (!pixels.empty()) std::memcpy(pixels.data(), data, pixels.size() * 2);
  const int width = 16, height = static_cast<int>(pixels.size() / 16);
  const touchdown::DepthImageView view{pixels.data(), width, height, width};
  const auto check = tp::check_depth_scale(view, 0.001, 0.05, 50.0, 1);
  if (check.samples > 0 && !(check.median_raw >= 1 && check.median_raw <= 65535)) __builtin_trap();
  if (!check.plausible && check.message.empty()) __builtin_trap();
  return 0;
}
