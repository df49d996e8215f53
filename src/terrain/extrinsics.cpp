#include "touchdown/terrain/extrinsics.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::terrain {
namespace {

// Numbers of a flat list, or of a list of rows (a matrix written row by row).
std::vector<double> flat_numbers(const detail::YamlReader& r, const YAML::Node& node, const std::string& key) {
  if (!node.IsSequence()) r.fail(node, key, "expected a list of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node item = node[i];
    if (item.IsSequence()) {
      for (std::size_t j = 0; j < item.size(); ++j) out.push_back(r.number(item[j], key));
    } else {
      out.push_back(r.number(item, key));
    }
  }
  return out;
}

Eigen::Vector3d vec3(const detail::YamlReader& r, const YAML::Node& node, const std::string& key) {
  const auto v = r.vec3(node, key);
  return {v[0], v[1], v[2]};
}

// Reads one pose map: {xyz, rpy_deg} or {matrix}. `prefix` is "" or
// "body.". `rpy` is the key's earlier name (also degrees), still read. The
// rotation is required: a missing one is never taken for the identity
// (issue 11: an xyz-only file put the terrain above the camera).
Eigen::Isometry3d parse_pose(const detail::YamlReader& r, const YAML::Node& map, const std::string& prefix,
                             bool allow_body, std::vector<std::string>& warnings) {
  if (allow_body) {
    r.only(map, prefix, {"xyz", "rpy_deg", "rpy", "matrix", "body"});
  } else {
    r.only(map, prefix, {"xyz", "rpy_deg", "rpy", "matrix"});
  }
  const YAML::Node xyz = map["xyz"], matrix = map["matrix"];
  const bool legacy = static_cast<bool>(map["rpy"]);
  if (legacy && map["rpy_deg"]) r.fail(map["rpy"], prefix + "rpy", "give rpy_deg only (rpy is its earlier name)");
  const std::string rpy_name = legacy ? "rpy" : "rpy_deg";
  const YAML::Node rpy = map[rpy_name];
  const std::string rpy_key = prefix + rpy_name;
  if (matrix && (xyz || rpy)) r.fail(map, prefix + "matrix", "give either matrix or xyz/rpy_deg, not both");
  if (!matrix) {
    const Eigen::Vector3d t = xyz ? vec3(r, xyz, prefix + "xyz") : Eigen::Vector3d::Zero();
    if (!rpy) {
      r.fail(map, rpy_key,
             "missing: the camera's rotation is required (rpy_deg: [roll, pitch, yaw] in degrees, or a 4x4 "
             "matrix); a camera looking straight down is rpy_deg: [180, 0, 0]");
    }
    const Eigen::Vector3d deg = vec3(r, rpy, rpy_key);
    if (std::string w = r.radians_warning(rpy, rpy_key, {deg.x(), deg.y(), deg.z()}); !w.empty()) {
      warnings.push_back(std::move(w));
    }
    return pose_from_xyz_rpy(t, deg.unaryExpr(&deg_to_rad));
  }
  const std::string key = prefix + "matrix";
  const auto v = flat_numbers(r, matrix, key);
  if (v.size() != 16) r.fail(matrix, key, "expected 16 numbers (row-major 4x4), got " + std::to_string(v.size()));
  Eigen::Matrix4d m;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) m(row, col) = v[static_cast<std::size_t>(4 * row + col)];
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) r.fail(matrix, key, "last row must be 0 0 0 1");
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (err > 1e-3 || R.determinant() < 0) {
    r.fail(matrix, key,
           "top-left 3x3 is not a rotation (orthonormality error " + std::to_string(err) + ", det " +
               std::to_string(R.determinant()) + ")");
  }
  // Re-orthonormalise hand-typed rotations (few decimals).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * svd.matrixV().transpose();
  T.translation() = m.topRightCorner<3, 1>();
  return T;
}

}  // namespace

Extrinsics parse_extrinsics(std::string_view yaml_text, std::string_view source) {
  const YAML::Node root = detail::load_yaml(yaml_text, source);
  if (!root.IsMap()) throw ParseError(std::string(source) + ": expected a YAML mapping with xyz/rpy_deg or matrix");
  const detail::YamlReader r{source};
  Extrinsics e;
  try {
    e.T_world_camera = parse_pose(r, root, "", true, e.warnings);
    if (const YAML::Node body = root["body"]) e.T_body_camera = parse_pose(r, body, "body.", false, e.warnings);
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
    const Eigen::Vector3d rpy = rpy_from_rotation(T.linear());
    const double roll = rpy.x(), pitch = rpy.y(), yaw = rpy.z();
    auto v = [](double x) { return detail::format_general(x, 17); };  // 17 digits read back exactly; no "-0"
    os << indent << "xyz: [" << v(T.translation().x()) << ", " << v(T.translation().y()) << ", "
       << v(T.translation().z()) << "]\n";
    os << indent << "rpy_deg: [" << v(rad_to_deg(roll)) << ", " << v(rad_to_deg(pitch)) << ", " << v(rad_to_deg(yaw))
       << "]\n";
  };
  std::ostringstream os;
  os << "# camera pose in the world (T_world_camera); rpy_deg = [roll, pitch, yaw] in degrees, R = Rz(yaw) Ry(pitch) "
        "Rx(roll)\n";
  pose(os, e.T_world_camera, "");
  if (with_body) {
    os << "body:  # camera pose in the drone body frame (T_body_camera)\n";
    pose(os, e.T_body_camera, "  ");
  }
  return os.str();
}

}  // namespace touchdown::terrain
