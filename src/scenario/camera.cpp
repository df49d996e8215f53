// The downward camera's options (camera.hpp): validation, intrinsics and
// the mounting on the body. The renderer itself is in render.cpp.
#include "touchdown/scenario/camera.hpp"

#include <cmath>
#include <string>

#include "core/format.hpp"
#include "scenario/render_internal.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::scenario {

namespace {

// Option values in messages: six decimals, trailing zeros trimmed.
std::string num(double v) { return touchdown::detail::format_trimmed(v, 6); }

}  // namespace

bool CameraOptions::validate(std::string* why) const {
  if (width < 16 || width > 4096) return invalid(why, "width: " + std::to_string(width) + " px is outside [16, 4096]");
  if (height < 16 || height > 4096) {
    return invalid(why, "height: " + std::to_string(height) + " px is outside [16, 4096]");
  }
  if (!(hfov_deg > 10 && hfov_deg < 170)) {
    return invalid(why, "hfov_deg: " + num(hfov_deg) + " deg is outside (10, 170)");
  }
  if (!(tilt_deg >= 0 && tilt_deg <= 80)) return invalid(why, "tilt_deg: " + num(tilt_deg) + " deg is outside [0, 80]");
  if (!(rate_hz > 0 && rate_hz <= 100)) return invalid(why, "rate_hz: " + num(rate_hz) + " Hz is outside (0, 100]");
  if (!(exposure_s >= 0 && exposure_s <= 0.2)) {
    return invalid(why, "exposure_s: " + num(exposure_s) + " s is outside [0, 0.2]");
  }
  if (!offset_body.allFinite()) return invalid(why, "offset_body: must be finite");
  return true;
}

double CameraOptions::fx() const { return 0.5 * width / std::tan(0.5 * deg_to_rad(hfov_deg)); }

Eigen::Matrix3d CameraOptions::K() const {
  // Pixel centres at integer coordinates (OpenCV's convention), so the
  // image centre is ((w − 1)/2, (h − 1)/2).
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = fx();
  k(0, 2) = 0.5 * (width - 1);
  k(1, 2) = 0.5 * (height - 1);
  return k;
}

Eigen::Isometry3d CameraOptions::T_body_camera() const {
  // Columns = camera axes in the body frame at nadir: x right = −y body,
  // y down = −x body (image up = forward), z = −z body (looking down).
  Eigen::Matrix3d nadir;
  nadir << 0, -1, 0, -1, 0, 0, 0, 0, -1;
  // Rotating about the camera's x axis by +tilt leans z towards body +x:
  // z' = nadir · (0, −sin, cos) = (sin, 0, −cos).
  const Eigen::Matrix3d R =
      nadir * Eigen::AngleAxisd(deg_to_rad(tilt_deg), Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = offset_body;
  return T;
}

}  // namespace touchdown::scenario
