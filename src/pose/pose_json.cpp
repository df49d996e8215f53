#include "touchdown/pose/pose_json.hpp"

#include <cstdio>

namespace touchdown::pose {

// One JSON line by hand: fixed decimals (nlohmann would print the binary
// value of a rounded double in full), q with w >= 0.
std::string pose_json(std::string_view frame_name, const PoseEstimate& e, double ms) {
  const std::string frame(frame_name);
  char buf[512];
  if (e.ok()) {
    const Eigen::Vector3d t = e.T_camera_body.translation();
    Eigen::Quaterniond q(e.T_camera_body.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": true, \"t\": [%.6f, %.6f, %.6f], \"q\": [%.7f, %.7f, %.7f, %.7f], "
                  "\"sigma\": [%.6f, %.6f], \"reproj_px\": %.3f, \"leds\": %d, \"blobs\": %d, \"ms\": %.3f, ",
                  frame.c_str(), t.x(), t.y(), t.z(), q.w(), q.x(), q.y(), q.z(), e.sigma_position_m,
                  e.sigma_rotation_rad, e.rms_px, e.points, e.blobs, ms);
    // The full 6×6 twist covariance, row-major (docs/formats.md).
    std::string out = buf;
    out += "\"covariance\": [";
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        std::snprintf(buf, sizeof(buf), "%s%.6e", r + c ? ", " : "", e.covariance(r, c));
        out += buf;
      }
    }
    return out + "]}";
  } else if (e.status == PoseStatus::Uncertain) {  // the figures that failed the gate
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": false, \"reason\": \"%s\", \"sigma\": [%.6f, %.6f], \"blobs\": %d, "
                  "\"ms\": %.3f}",
                  frame.c_str(), std::string(to_string(e.status)).c_str(), e.sigma_position_m, e.sigma_rotation_rad,
                  e.blobs, ms);
  } else {
    std::snprintf(buf, sizeof(buf),
                  "{\"frame\": \"%s\", \"ok\": false, \"reason\": \"%s\", \"blobs\": %d, \"ms\": %.3f}", frame.c_str(),
                  std::string(to_string(e.status)).c_str(), e.blobs, ms);
  }
  return buf;
}

}  // namespace touchdown::pose
