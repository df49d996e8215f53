#include "touchdown/terrain/extrinsics.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>
#include <vector>

#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::terrain {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

[[noreturn]] void key_fail(std::string_view source, const YAML::Node& node, const std::string& key,
                           const std::string& what) {
  std::string where(source);
  if (node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
  throw ParseError(where + ": key '" + key + "': " + what);
}

double as_number(std::string_view source, const YAML::Node& node, const std::string& key) {
  if (!node.IsScalar()) key_fail(source, node, key, "expected a number");
  double v = 0;
  if (!detail::parse_double(detail::trim(node.Scalar()), v) || !std::isfinite(v)) {
    key_fail(source, node, key, "'" + node.Scalar() + "' is not a finite number");
  }
  return v;
}

std::vector<double> as_numbers(std::string_view source, const YAML::Node& node, const std::string& key) {
  std::vector<double> out;
  if (!node.IsSequence()) key_fail(source, node, key, "expected a list of numbers");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node item = node[i];
    if (item.IsSequence()) {  // matrix given as rows
      for (std::size_t j = 0; j < item.size(); ++j) out.push_back(as_number(source, item[j], key));
    } else {
      out.push_back(as_number(source, item, key));
    }
  }
  return out;
}

Eigen::Vector3d as_vec3(std::string_view source, const YAML::Node& node, const std::string& key) {
  const auto v = as_numbers(source, node, key);
  if (v.size() != 3) key_fail(source, node, key, "expected 3 numbers, got " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

// Reads one pose map: {xyz, rpy} or {matrix}. `prefix` is "" or "body.".
Eigen::Isometry3d parse_pose(std::string_view source, const YAML::Node& map, const std::string& prefix,
                             bool allow_body) {
  if (!map.IsMap()) key_fail(source, map, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1),
                             "expected a mapping with xyz/rpy or matrix");
  bool have_xyz = false, have_rpy = false, have_matrix = false;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    if (key == "xyz") {
      xyz = as_vec3(source, kv.second, prefix + key);
      have_xyz = true;
    } else if (key == "rpy") {
      rpy = as_vec3(source, kv.second, prefix + key) * kDeg;
      have_rpy = true;
    } else if (key == "matrix") {
      const auto v = as_numbers(source, kv.second, prefix + key);
      if (v.size() != 16) key_fail(source, kv.second, prefix + key, "expected 16 numbers (row-major 4x4), got " + std::to_string(v.size()));
      Eigen::Matrix4d m;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<std::size_t>(4 * r + c)];
      if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
        key_fail(source, kv.second, prefix + key, "last row must be 0 0 0 1");
      }
      const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
      const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
      if (err > 1e-3 || R.determinant() < 0) {
        key_fail(source, kv.second, prefix + key, "top-left 3x3 is not a rotation (orthonormality error " +
                                                       std::to_string(err) + ", det " + std::to_string(R.determinant()) + ")");
      }
      // Re-orthonormalise hand-typed rotations (few decimals).
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
      T.linear() = svd.matrixU() * svd.matrixV().transpose();
      T.translation() = m.topRightCorner<3, 1>();
      have_matrix = true;
    } else if (key == "body" && allow_body) {
      continue;
    } else {
      key_fail(source, kv.first, prefix + key, "unknown key (expected xyz, rpy, matrix" +
                                                   std::string(allow_body ? ", body)" : ")"));
    }
  }
  if (have_matrix && (have_xyz || have_rpy)) {
    key_fail(source, map, prefix + "matrix", "give either matrix or xyz/rpy, not both");
  }
  if (!have_matrix && !have_xyz && !have_rpy) {
    key_fail(source, map, prefix.empty() ? "xyz" : prefix + "xyz", "missing: expected xyz/rpy or matrix");
  }
  if (!have_matrix) T = pose_from_xyz_rpy(xyz, rpy);
  return T;
}

}  // namespace

Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Isometry3d pose_from_xyz_rpy(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation_from_rpy(rpy_rad.x(), rpy_rad.y(), rpy_rad.z());
  T.translation() = xyz;
  return T;
}

Extrinsics parse_extrinsics(std::string_view yaml_text, std::string_view source) {
  const YAML::Node root = detail::load_yaml(yaml_text, source);
  if (!root.IsMap()) throw ParseError(std::string(source) + ": expected a YAML mapping with xyz/rpy or matrix");
  Extrinsics e;
  try {
    e.T_world_camera = parse_pose(source, root, "", true);
    if (const YAML::Node body = root["body"]) e.T_body_camera = parse_pose(source, body, "body.", false);
  } catch (const YAML::Exception& ex) {
    throw ParseError(std::string(source) + ":" + std::to_string(ex.mark.line + 1) + ": " + ex.msg);
  }
  return e;
}

Extrinsics load_extrinsics(const std::filesystem::path& path) {
  return parse_extrinsics(detail::read_text_file(path), path.string());
}

std::string format_extrinsics(const Extrinsics& e, bool with_body) {
  auto pose = [](std::ostringstream& os, const Eigen::Isometry3d& T, const char* indent) {
    const Eigen::Matrix3d R = T.linear();
    // Inverse of R = Rz(y)Ry(p)Rx(r).
    const double pitch = std::atan2(-R(2, 0), std::hypot(R(0, 0), R(1, 0)));
    double roll = std::atan2(R(2, 1), R(2, 2));
    double yaw = std::atan2(R(1, 0), R(0, 0));
    if (std::abs(R(2, 0)) > 1.0 - 1e-12) {  // gimbal lock: only yaw - roll is defined
      roll = 0.0;
      yaw = std::atan2(-R(0, 1), R(1, 1));
    }
    os << std::setprecision(17);
    auto v = [](double x) { return x + 0.0; };  // no "-0"
    os << indent << "xyz: [" << v(T.translation().x()) << ", " << v(T.translation().y()) << ", "
       << v(T.translation().z()) << "]\n";
    os << indent << "rpy: [" << v(roll / kDeg) << ", " << v(pitch / kDeg) << ", " << v(yaw / kDeg) << "]\n";
  };
  std::ostringstream os;
  os << "# camera pose in the world (T_world_camera); rpy in degrees, R = Rz(yaw) Ry(pitch) Rx(roll)\n";
  pose(os, e.T_world_camera, "");
  if (with_body) {
    os << "body:  # camera pose in the drone body frame (T_body_camera)\n";
    pose(os, e.T_body_camera, "  ");
  }
  return os.str();
}

}  // namespace touchdown::terrain
