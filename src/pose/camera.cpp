#include "touchdown/pose/camera.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <sstream>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"

namespace touchdown::pose {

using detail::format_general;

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

namespace {

// touchdown's own camera YAML (docs/formats.md, "Camera YAML").
void read_touchdown_camera(const detail::YamlReader& r, const YAML::Node& root, CameraModel& c) {
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
}

// ---- calibration files of other tools ------------------------------------------------
//
// OpenCV: cv::FileStorage YAML as written by OpenCV's camera calibration
// sample and tutorial (samples/cpp/calibration.cpp, "Camera calibration
// With OpenCV"): `camera_matrix` and `distortion_coefficients` as
// `!!opencv-matrix {rows, cols, dt, data}`, `image_width`, `image_height`.
// ROS: camera_calibration_parsers' YAML (wiki.ros.org/camera_calibration_parsers,
// sensor_msgs/CameraInfo): the same names with `{rows, cols, data}` plus
// `camera_name`, `distortion_model`, `rectification_matrix`, `projection_matrix`.
// Both describe OpenCV's pinhole + Brown–Conrady model, our CameraModel.

enum class CameraFormat { Touchdown, OpenCv, Ros };

bool has_any(const YAML::Node& map, std::initializer_list<const char*> keys) {
  return std::any_of(keys.begin(), keys.end(), [&](const char* k) { return static_cast<bool>(map[k]); });
}

// By content, never by file name: ROS's own keys, else OpenCV's (or the
// FileStorage header), else ours (whose reader also reports a non-mapping).
CameraFormat detect_format(const YAML::Node& root, bool filestorage_header) {
  if (!root.IsMap()) return CameraFormat::Touchdown;
  if (has_any(root, {"distortion_model", "camera_name", "rectification_matrix", "projection_matrix"})) {
    return CameraFormat::Ros;
  }
  if (filestorage_header || has_any(root, {"camera_matrix", "cameraMatrix", "distortion_coefficients", "distCoeffs",
                                           "image_width", "image_height"})) {
    return CameraFormat::OpenCv;
  }
  return CameraFormat::Touchdown;
}

struct Matrix {
  int rows = 0, cols = 0;
  std::vector<double> data;  // row-major
};

// {rows, cols, data} (OpenCV adds dt, the element type: any is read as a
// number), or a plain list of numbers (FileStorage's std::vector<double>) as 1xN.
Matrix read_matrix(const detail::YamlReader& r, const YAML::Node& n, const std::string& key) {
  Matrix m;
  if (n.IsSequence()) {
    m.data = r.numbers(n, key);
    m.rows = 1;
    m.cols = static_cast<int>(m.data.size());
    return m;
  }
  if (!n.IsMap()) r.fail(n, key, "expected a matrix {rows, cols, data} or a list of numbers");
  const std::string prefix = key + ".";
  r.only(n, prefix, {"rows", "cols", "dt", "data"});
  m.rows = r.integer(r.child(n, prefix, "rows"), prefix + "rows");
  m.cols = r.integer(r.child(n, prefix, "cols"), prefix + "cols");
  if (m.rows < 0 || m.rows > 64 || m.cols < 0 || m.cols > 64) r.fail(n, key, "rows and cols must be in 0..64");
  const YAML::Node data = r.child(n, prefix, "data");
  m.data = r.numbers(data, prefix + "data");
  const auto expected = static_cast<std::size_t>(m.rows) * static_cast<std::size_t>(m.cols);
  if (m.data.size() != expected) {
    r.fail(data, prefix + "data",
           "rows x cols = " + std::to_string(m.rows) + "x" + std::to_string(m.cols) + " needs " +
               std::to_string(expected) + " numbers, got " + std::to_string(m.data.size()));
  }
  return m;
}

// The node of `name` or of its alias (both given: an error); null when neither.
YAML::Node aliased(const detail::YamlReader& r, const YAML::Node& root, const char* name, const char* alias,
                   std::string& used) {
  if (root[name] && root[alias]) r.fail(root[alias], alias, std::string("given together with ") + name);
  used = root[alias] ? alias : name;
  return root[alias] ? root[alias] : root[name];
}

void read_camera_matrix(const detail::YamlReader& r, const YAML::Node& root, CameraFormat format, CameraModel& c) {
  std::string key;
  const YAML::Node node = aliased(r, root, "camera_matrix", "cameraMatrix", key);
  if (!node) {
    r.fail(root, "camera_matrix",
           format == CameraFormat::Ros ? "missing (a ROS camera_info file gives the intrinsics as camera_matrix)"
                                       : "missing (an OpenCV calibration file gives the intrinsics as camera_matrix "
                                         "or cameraMatrix)");
  }
  const Matrix m = read_matrix(r, node, key);
  const bool flat9 = m.rows == 1 && m.cols == 9;
  if (!(m.rows == 3 && m.cols == 3) && !flat9) {
    r.fail(node, key, "expected a 3x3 matrix, got " + std::to_string(m.rows) + "x" + std::to_string(m.cols));
  }
  const auto& k = m.data;  // [fx s cx; 0 fy cy; 0 0 1]
  constexpr double kTol = 1e-9;
  if (std::abs(k[3]) > kTol || std::abs(k[6]) > kTol || std::abs(k[7]) > kTol || std::abs(k[8] - 1) > kTol) {
    r.fail(node, key,
           "expected [fx, 0, cx; 0, fy, cy; 0, 0, 1], got rows 2-3 [" + format_general(k[3]) + ", " +
               format_general(k[4]) + ", " + format_general(k[5]) + "; " + format_general(k[6]) + ", " +
               format_general(k[7]) + ", " + format_general(k[8]) + "]");
  }
  if (!(k[0] > 0)) r.fail(node, key, "fx = K[0][0] must be positive, got " + format_general(k[0]));
  if (!(k[4] > 0)) r.fail(node, key, "fy = K[1][1] must be positive, got " + format_general(k[4]));
  if (std::abs(k[1]) > kTol * k[0]) {
    r.fail(node, key,
           "skew K[0][1] = " + format_general(k[1]) +
               " is not supported (the pinhole model has none; OpenCV and ROS calibrate without skew)");
  }
  c.fx = k[0];
  c.cx = k[2];
  c.fy = k[4];
  c.cy = k[5];
}

void read_distortion(const detail::YamlReader& r, const YAML::Node& root, CameraFormat format, CameraModel& c) {
  static constexpr const char* kNames[] = {"k1", "k2", "p1", "p2", "k3", "k4", "k5",
                                           "k6", "s1", "s2", "s3", "s4", "tx", "ty"};
  std::string model = "plumb_bob";
  if (format == CameraFormat::Ros && root["distortion_model"]) {
    const YAML::Node n = root["distortion_model"];
    model = r.text(n, "distortion_model");
    if (model == "equidistant" || model == "fisheye" || model == "kannala_brandt") {
      r.fail(n, "distortion_model",
             model + " (fisheye) is not supported: touchdown models plumb_bob (k1, k2, p1, p2, k3)");
    }
    if (model != "plumb_bob" && model != "rational_polynomial") {
      r.fail(n, "distortion_model", "unknown model '" + model + "' (expected plumb_bob or rational_polynomial)");
    }
  }
  if (root["fisheye_model"] && r.integer(root["fisheye_model"], "fisheye_model") != 0) {
    r.fail(root["fisheye_model"], "fisheye_model",
           "the fisheye model (cv::fisheye) is not supported: touchdown models k1, k2, p1, p2, k3");
  }
  std::string key;
  const YAML::Node node = aliased(r, root, "distortion_coefficients", "distCoeffs", key);
  c.distortion = {};
  if (!node) {
    if (format == CameraFormat::Ros) r.fail(root, "distortion_coefficients", "missing");
    return;  // OpenCV: none
  }
  const Matrix m = read_matrix(r, node, key);
  if (m.rows != 1 && m.cols != 1 && !m.data.empty()) {
    r.fail(node, key, "expected a 1xN or Nx1 vector, got " + std::to_string(m.rows) + "x" + std::to_string(m.cols));
  }
  const std::size_t n = m.data.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    r.fail(node, key,
           "expected 4, 5, 8, 12 or 14 coefficients (k1, k2, p1, p2[, k3[, k4, k5, k6[, s1, s2, s3, s4[, tx, ty]]]]), "
           "got " +
               std::to_string(n));
  }
  if (model == "plumb_bob" && format == CameraFormat::Ros && n > 5) {
    r.fail(node, key, "plumb_bob has 5 coefficients (k1, k2, p1, p2, k3), got " + std::to_string(n));
  }
  if (model == "rational_polynomial" && n != 8) {
    r.fail(node, key,
           "rational_polynomial has 8 coefficients (k1, k2, p1, p2, k3, k4, k5, k6), got " + std::to_string(n));
  }
  // Terms beyond k3 that are zero leave OpenCV's model equal to ours
  // (denominator 1 + k4 r² + k5 r⁴ + k6 r⁶ = 1, no thin-prism or tilt term).
  for (std::size_t i = 5; i < n; ++i) {
    if (m.data[i] == 0) continue;
    const char* what = i < 8    ? "the rational model (k4, k5, k6; OpenCV's CALIB_RATIONAL_MODEL, ROS "
                                  "rational_polynomial)"
                       : i < 12 ? "the thin-prism model (s1..s4; CALIB_THIN_PRISM_MODEL)"
                                : "the tilted-sensor model (tx, ty; CALIB_TILTED_MODEL)";
    r.fail(node, key,
           std::string(kNames[i]) + " = " + format_general(m.data[i]) + ": " + what +
               " is not supported; touchdown models k1, k2, p1, p2, k3 (recalibrate without it)");
  }
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 5); ++i) c.distortion[i] = m.data[i];
}

// ROS: intrinsics of a binned or cropped image are not those of the file.
void refuse_binning_and_roi(const detail::YamlReader& r, const YAML::Node& root, const CameraModel& c) {
  for (const char* key : {"binning_x", "binning_y"}) {
    if (root[key] && r.integer(root[key], key) > 1) {
      r.fail(root[key], key, "binned images are not supported (camera_matrix is for the unbinned image)");
    }
  }
  const YAML::Node roi = root["roi"];
  if (!roi) return;
  if (!roi.IsMap()) r.fail(roi, "roi", "expected a mapping");
  auto value = [&](const char* k) { return roi[k] ? r.integer(roi[k], std::string("roi.") + k) : 0; };
  const int x = value("x_offset"), y = value("y_offset"), w = value("width"), h = value("height");
  const bool whole = x == 0 && y == 0 && ((w == 0 && h == 0) || (w == c.width && h == c.height));
  if (!whole) r.fail(roi, "roi", "a region of interest is not supported (camera_matrix is for the full image)");
}

void read_calibration_file(const detail::YamlReader& r, const YAML::Node& root, CameraFormat format, CameraModel& c) {
  const char* name = format == CameraFormat::Ros ? "a ROS camera_info file" : "an OpenCV calibration file";
  for (const char* own : {"width", "height", "fx", "fy", "cx", "cy", "distortion"}) {
    if (root[own]) {
      r.fail(root[own], own,
             std::string("a key of touchdown's camera YAML in ") + name +
                 " (its camera_matrix, image_width and image_height give the camera): use one format");
    }
  }
  for (const char* key : {"image_width", "image_height"}) {
    if (!root[key]) {
      r.fail(root, key,
             std::string("missing: ") + name +
                 " must give the image size it was calibrated at (image_width and image_height)");
    }
  }
  c.width = r.integer(root["image_width"], "image_width");
  c.height = r.integer(root["image_height"], "image_height");
  if (c.width <= 0 || c.width > 32768) r.fail(root["image_width"], "image_width", "must be in 1..32768");
  if (c.height <= 0 || c.height > 32768) r.fail(root["image_height"], "image_height", "must be in 1..32768");
  read_camera_matrix(r, root, format, c);
  read_distortion(r, root, format, c);
  refuse_binning_and_roi(r, root, c);
  // Ours, optional: calibration files carry no depth unit.
  if (root["depth_scale"]) c.depth_scale = r.number(root["depth_scale"], "depth_scale");
}

}  // namespace

CameraModel parse_camera(std::string_view yaml_text, std::string_view source) {
  // cv::FileStorage opens its YAML with "%YAML:1.0", a directive yaml-cpp
  // refuses; made a comment, it keeps every line number.
  std::string text(yaml_text);
  const bool filestorage_header = text.rfind("%YAML:", 0) == 0;
  if (filestorage_header) text[0] = '#';
  return detail::parse_validated<CameraModel>(text, source,
                                              [&](const detail::YamlReader& r, const YAML::Node& root, CameraModel& c) {
                                                const CameraFormat format = detect_format(root, filestorage_header);
                                                if (format == CameraFormat::Touchdown) {
                                                  read_touchdown_camera(r, root, c);
                                                } else {
                                                  read_calibration_file(r, root, format, c);
                                                }
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

namespace {

// The depth_scale under which a median of `raw` units is plausible, as a hint.
std::string depth_scale_hint(double raw, double depth_scale, double min_m, double max_m) {
  static const struct {
    double scale;
    const char* unit;
  } kUnits[] = {{0.001, "16-bit depth in millimetres needs depth_scale: 0.001"},
                {0.0001, "depth in 0.1 mm (RealSense D405) needs depth_scale: 0.0001"},
                {0.01, "depth in centimetres needs depth_scale: 0.01"},
                {1.0, "depth in metres needs depth_scale: 1"}};
  for (const auto& u : kUnits) {
    const double z = raw * u.scale;
    if (u.scale != depth_scale && z >= min_m && z <= max_m) return u.unit;
  }
  return "depth_scale is metres per unit of the 16-bit depth image (millimetres: 0.001)";
}

}  // namespace

DepthScaleCheck check_depth_scale(const DepthImageView& depth, double depth_scale, double min_m, double max_m,
                                  int min_samples) {
  DepthScaleCheck c;
  if (depth.data == nullptr || depth.width <= 0 || depth.height <= 0) return c;
  constexpr int kGrid = 64;
  const int step_x = std::max(1, (depth.width + kGrid - 1) / kGrid);
  const int step_y = std::max(1, (depth.height + kGrid - 1) / kGrid);
  std::vector<std::uint16_t> v;
  v.reserve(static_cast<std::size_t>(kGrid) * kGrid);
  for (int y = step_y / 2; y < depth.height; y += step_y) {
    const std::uint16_t* row = depth.row(y);
    for (int x = step_x / 2; x < depth.width; x += step_x) {
      if (row[x] != 0) v.push_back(row[x]);
    }
  }
  c.samples = static_cast<int>(v.size());
  if (v.empty()) return c;
  c.median_raw = upper_median_in_place(std::span(v));
  c.median_m = c.median_raw * depth_scale;
  c.conclusive = c.samples >= min_samples;
  if (!c.conclusive) return c;
  c.plausible = c.median_m >= min_m && c.median_m <= max_m;
  if (!c.plausible) {
    c.message = "depth_scale: " + format_general(depth_scale) + " m per unit puts the median depth at " +
                format_general(c.median_m) + " m (" + format_general(c.median_raw) + " units, " +
                std::to_string(c.samples) + " pixels sampled), outside the plausible " + format_general(min_m) + ".." +
                format_general(max_m) + " m; " + depth_scale_hint(c.median_raw, depth_scale, min_m, max_m);
  }
  return c;
}

}  // namespace touchdown::pose
