#include "touchdown/pose/camera.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::pose {

bool CameraModel::has_distortion() const {
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

namespace {
// Brown–Conrady on normalised coordinates (OpenCV's documented model).
Eigen::Vector2d distort_normalised(const std::array<double, 5>& k, const Eigen::Vector2d& xy) {
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  return {x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x),
          y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y};
}
}  // namespace

Eigen::Vector2d CameraModel::project(const Eigen::Vector3d& p) const {
  Eigen::Vector2d xy(p.x() / p.z(), p.y() / p.z());
  if (has_distortion()) xy = distort_normalised(distortion, xy);
  return {fx * xy.x() + cx, fy * xy.y() + cy};
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& uv) const {
  if (!has_distortion()) return uv;
  const Eigen::Vector2d target((uv.x() - cx) / fx, (uv.y() - cy) / fy);
  // Newton's method on distort(xy) = target with the analytic 2×2
  // Jacobian (quadratic convergence, also for wide-angle coefficients where
  // OpenCV-style fixed-point iteration converges slowly).
  const auto& k = distortion;
  Eigen::Vector2d xy = target;
  for (int i = 0; i < 20; ++i) {
    const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
    const double radial = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
    const double g = 2 * k[0] + r2 * (4 * k[1] + 6 * k[4] * r2);  // d radial / d(x or y) = g · (x or y)
    Eigen::Matrix2d J;
    J << radial + g * x * x + 2 * k[2] * y + 6 * k[3] * x, g * x * y + 2 * k[2] * x + 2 * k[3] * y,
        g * x * y + 2 * k[2] * x + 2 * k[3] * y, radial + g * y * y + 6 * k[2] * y + 2 * k[3] * x;
    const Eigen::Vector2d r = distort_normalised(k, xy) - target;
    const Eigen::Vector2d step = J.partialPivLu().solve(r);
    if (!step.allFinite()) break;
    xy -= step;
    if (step.squaredNorm() < 1e-30) break;
  }
  return {fx * xy.x() + cx, fy * xy.y() + cy};
}

bool CameraModel::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (width <= 0 || width > 32768) return fail("width: must be in 1..32768");
  if (height <= 0 || height > 32768) return fail("height: must be in 1..32768");
  if (!(fx > 0) || !std::isfinite(fx)) return fail("fx: focal length must be positive");
  if (!(fy > 0) || !std::isfinite(fy)) return fail("fy: focal length must be positive");
  if (!std::isfinite(cx) || cx < -width || cx > 2.0 * width) return fail("cx: principal point far outside the image");
  if (!std::isfinite(cy) || cy < -height || cy > 2.0 * height) return fail("cy: principal point far outside the image");
  for (double d : distortion) {
    if (!std::isfinite(d) || std::abs(d) > 100) return fail("distortion: coefficients must be finite and |k| <= 100");
  }
  if (!(depth_scale > 0) || !std::isfinite(depth_scale)) return fail("depth_scale: must be positive");
  return true;
}

CameraModel parse_camera(std::string_view yaml_text, std::string_view source) {
  return detail::parse_validated<CameraModel>(
      yaml_text, source, [](const detail::YamlReader& r, const YAML::Node& root, CameraModel& c) {
        r.only(root, "", {"width", "height", "fx", "fy", "cx", "cy", "distortion", "depth_scale"});
        c.width = r.integer(r.child(root, "", "width"), "width");
        c.height = r.integer(r.child(root, "", "height"), "height");
        c.fx = r.number(r.child(root, "", "fx"), "fx");
        c.fy = r.number(r.child(root, "", "fy"), "fy");
        c.cx = r.number(r.child(root, "", "cx"), "cx");
        c.cy = r.number(r.child(root, "", "cy"), "cy");
        if (root["distortion"]) {
          const auto d = r.numbers(root["distortion"], "distortion");
          if (d.size() != 4 && d.size() != 5) {
            r.fail(root["distortion"], "distortion",
                   "expected [k1, k2, p1, p2] or [k1, k2, p1, p2, k3], got " + std::to_string(d.size()) + " numbers");
          }
          c.distortion = {};
          for (std::size_t i = 0; i < d.size(); ++i) c.distortion[i] = d[i];
        }
        if (root["depth_scale"]) c.depth_scale = r.number(root["depth_scale"], "depth_scale");
      });
}

CameraModel load_camera(const std::filesystem::path& path) {
  return parse_camera(detail::read_text_file(path), path.string());
}

std::string camera_to_yaml(const CameraModel& c) {
  std::ostringstream os;
  os << "width: " << c.width << "\nheight: " << c.height << "\nfx: " << detail::format_exact(c.fx)
     << "\nfy: " << detail::format_exact(c.fy) << "\ncx: " << detail::format_exact(c.cx)
     << "\ncy: " << detail::format_exact(c.cy) << "\ndistortion: [";
  for (std::size_t i = 0; i < 5; ++i) os << (i ? ", " : "") << detail::format_exact(c.distortion[i]);
  os << "]\ndepth_scale: " << detail::format_exact(c.depth_scale) << "\n";
  return os.str();
}

}  // namespace touchdown::pose
