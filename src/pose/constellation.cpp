#include "touchdown/pose/constellation.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/format.hpp"
#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/rotation.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::pose {

bool Led::emits_toward(const Eigen::Vector3d& camera_body, double margin_rad) const {
  if (!has_normal()) return true;
  const Eigen::Vector3d to_camera = camera_body - p_body;
  const double d = to_camera.norm();
  if (!(d > 0)) return false;
  const double angle = std::acos(std::clamp(normal.dot(to_camera) / d, -1.0, 1.0));
  return angle <= deg_to_rad(half_angle_deg) + margin_rad;
}

Eigen::Vector3d Constellation::facing() const {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& l : leds) s += l.normal;
  const double n = s.norm();
  return n > 1e-9 ? Eigen::Vector3d(s / n) : Eigen::Vector3d::Zero();
}

Eigen::Isometry3d Constellation::default_marker_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  return T;
}

Eigen::Vector3d Constellation::centroid() const {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& l : leds) c += l.p_body;
  return leds.empty() ? c : Eigen::Vector3d(c / static_cast<double>(leds.size()));
}

double Constellation::mean_absolute_deviation() const {
  if (leds.empty()) return 0;
  const Eigen::Vector3d c = centroid();
  double s = 0;
  for (const auto& l : leds) s += (l.p_body - c).norm();
  return s / static_cast<double>(leds.size());
}

double Constellation::radius() const {
  const Eigen::Vector3d c = centroid();
  double r = 0;
  for (const auto& l : leds) r = std::max(r, (l.p_body - c).norm());
  return r;
}

namespace {
// What is wrong with an emission half-angle [deg], or "" if nothing. Below
// 3.2 degrees it is taken for radians (π rad is 180°): no LED on a pose
// board is that narrow, and a cone that narrow would hide it from almost
// every view, so a value in radians would silently lose the board.
std::string half_angle_problem(double deg) {
  if (!(deg > 0 && deg < 180)) return "must be in (0, 180) degrees, got " + detail::format_exact(deg);
  if (deg < 3.2) {
    return "is " + detail::format_exact(deg) + " degrees, a cone no LED board uses: radians? (" +
           detail::format_exact(deg) + " rad = " + detail::format_exact(std::round(rad_to_deg(deg) * 10) / 10) +
           " degrees)";
  }
  return "";
}

// Eigenvalues (ascending) of the LEDs' scatter matrix about the centroid.
Eigen::Vector3d scatter_eigenvalues(const Constellation& k) {
  const Eigen::Vector3d c = k.centroid();
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const auto& l : k.leds) S += (l.p_body - c) * (l.p_body - c).transpose();
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S, Eigen::EigenvaluesOnly).eigenvalues();
}
}  // namespace

bool Constellation::planar(double tolerance) const {
  if (leds.size() < 4) return true;
  // Smallest eigenvalue = sum of squared distances to the best plane.
  return scatter_eigenvalues(*this)(0) <= tolerance * tolerance * static_cast<double>(leds.size());
}

bool Constellation::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (leds.size() < 4) return fail("leds: need at least 4 LEDs for a pose, got " + std::to_string(leds.size()));
  if (leds.size() > kMaxLeds) {
    return fail("leds: at most " + std::to_string(kMaxLeds) + " LEDs are supported, got " +
                std::to_string(leds.size()));
  }
  for (std::size_t i = 0; i < leds.size(); ++i) {
    if (!leds[i].p_body.allFinite()) return fail("leds[" + std::to_string(i) + "].xyz: not finite");
    if (leds[i].color == LedColor::Unknown)
      return fail("leds[" + std::to_string(i) + "].color: must be a colour class");
    const Eigen::Vector3d& n = leds[i].normal;
    if (!n.allFinite() || (leds[i].has_normal() && std::abs(n.norm() - 1) > 1e-6))
      return fail("leds[" + std::to_string(i) + "].normal: must be a unit vector (or zero: omnidirectional)");
    if (const std::string p = half_angle_problem(leds[i].half_angle_deg); !p.empty())
      return fail("leds[" + std::to_string(i) + "].half_angle_deg: " + p);
    for (std::size_t j = 0; j < i; ++j) {
      if ((leds[i].p_body - leds[j].p_body).norm() < 1e-3) {
        return fail("leds[" + std::to_string(i) + "]: duplicates leds[" + std::to_string(j) + "] (closer than 1 mm)");
      }
    }
  }
  // Collinear: all the spread along one axis (second eigenvalue ~ 0).
  const Eigen::Vector3d ev = scatter_eigenvalues(*this);
  if (ev(1) <= 1e-6 * ev(2) || ev(1) < 1e-8)
    return fail("leds: the LEDs are collinear: the pose about their line is unobservable");
  return true;
}

Constellation parse_constellation(std::string_view yaml_text, std::string_view source) {
  return detail::parse_validated<Constellation>(
      yaml_text, source, [](const detail::YamlReader& r, const YAML::Node& root, Constellation& k) {
        r.only(root, "", {"name", "leds", "marker"});
        const auto leds = r.child(root, "", "leds");
        if (!leds.IsSequence())
          r.fail(leds, "leds", "expected a list of {xyz: [x, y, z], color: red|green|blue|white}");
        for (std::size_t i = 0; i < leds.size(); ++i) {
          const std::string key = "leds[" + std::to_string(i) + "]";
          r.only(leds[i], key + ".", {"xyz", "color", "normal", "half_angle_deg"});
          const auto xyz = r.vec3(r.child(leds[i], key + ".", "xyz"), key + ".xyz");
          Led led;
          led.p_body = {xyz[0], xyz[1], xyz[2]};
          if (leds[i]["normal"]) {
            const auto n = r.vec3(leds[i]["normal"], key + ".normal");
            const Eigen::Vector3d v(n[0], n[1], n[2]);
            if (!(v.norm() > 1e-9)) r.fail(leds[i]["normal"], key + ".normal", "zero length: give the emission axis");
            led.normal = v.normalized();
          }
          if (leds[i]["half_angle_deg"]) {
            const YAML::Node h = leds[i]["half_angle_deg"];
            if (!led.has_normal())
              r.fail(h, key + ".half_angle_deg", "needs a normal (an LED without one shines everywhere)");
            led.half_angle_deg = r.number(h, key + ".half_angle_deg");
            if (const std::string p = half_angle_problem(led.half_angle_deg); !p.empty())
              r.fail(h, key + ".half_angle_deg", p);
          }
          if (leds[i]["color"]) {
            const auto name = r.text(leds[i]["color"], key + ".color");
            // Unknown is a detection outcome, never an LED's colour.
            LedColor c = LedColor::Unknown;
            try {
              c = from_string<LedColor>(name);
            } catch (const InvalidArgument&) {
            }
            if (c == LedColor::Unknown)
              r.fail(leds[i]["color"], key + ".color", "'" + name + "' is not red, green, blue or white");
            led.color = c;
          }
          k.leds.push_back(led);
        }
        if (root["marker"]) {
          const auto m = root["marker"];
          r.only(m, "marker.", {"xyz", "rpy_deg"});
          Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
          if (m["xyz"]) {
            const auto xyz = r.vec3(m["xyz"], "marker.xyz");
            T.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
          }
          if (m["rpy_deg"]) {
            const auto rpy = r.vec3(m["rpy_deg"], "marker.rpy_deg");
            T.linear() = rotation_from_rpy(deg_to_rad(rpy[0]), deg_to_rad(rpy[1]), deg_to_rad(rpy[2]));
          } else {
            T.linear() = Constellation::default_marker_pose().linear();
          }
          k.T_body_marker = T;
        }
      });
}

Constellation front_board_constellation() {
  Constellation k;
  const Eigen::Vector3d fwd(1, 0, 0);
  k.leds = {{{0.140, 0.095, 0.055}, LedColor::Red, fwd, 70},    {{0.150, -0.030, 0.070}, LedColor::Red, fwd, 70},
            {{0.135, 0.060, -0.060}, LedColor::Red, fwd, 70},   {{0.145, -0.100, 0.040}, LedColor::Green, fwd, 70},
            {{0.155, 0.010, -0.070}, LedColor::Green, fwd, 70}, {{0.138, -0.075, -0.050}, LedColor::Green, fwd, 70}};
  k.T_body_marker = Eigen::Isometry3d::Identity();
  k.T_body_marker.linear() = rotation_from_rpy(deg_to_rad(90.0), 0.0, deg_to_rad(90.0));
  k.T_body_marker.translation() = Eigen::Vector3d(0.14, 0, -0.16);
  return k;
}

Constellation default_constellation() {
  Constellation k;
  const Eigen::Vector3d down(0, 0, -1);
  k.leds = {{{0.0849, 0.0849, -0.030}, LedColor::Red, down},     {{0.0849, -0.0849, -0.030}, LedColor::Red, down},
            {{-0.0849, -0.0849, -0.030}, LedColor::Green, down}, {{-0.0849, 0.0849, -0.030}, LedColor::Green, down},
            {{0.090, -0.040, -0.110}, LedColor::Blue, down},     {{-0.090, 0.030, -0.110}, LedColor::White, down}};
  k.T_body_marker = Constellation::default_marker_pose();
  k.T_body_marker.translation() = Eigen::Vector3d(0, 0, -0.045);
  return k;
}

Constellation load_constellation(const std::filesystem::path& path) {
  return parse_constellation(detail::read_text_file(path), path.string());
}

std::string constellation_to_yaml(const Constellation& k) {
  using detail::format_exact;
  std::ostringstream os;
  os << "leds:\n";
  for (const auto& l : k.leds) {
    os << "  - {xyz: [" << format_exact(l.p_body.x()) << ", " << format_exact(l.p_body.y()) << ", "
       << format_exact(l.p_body.z()) << "], color: " << to_string(l.color);
    if (l.has_normal()) {
      os << ", normal: [" << format_exact(l.normal.x() + 0.0) << ", " << format_exact(l.normal.y() + 0.0) << ", "
         << format_exact(l.normal.z() + 0.0) << "], half_angle_deg: " << format_exact(l.half_angle_deg);
    }
    os << "}\n";
  }
  const Eigen::Vector3d t = k.T_body_marker.translation();
  // The one rpy convention of every touchdown file (core/rotation.hpp).
  const Eigen::Vector3d rpy = rpy_from_rotation(k.T_body_marker.linear());
  os << "marker: {xyz: [" << format_exact(t.x()) << ", " << format_exact(t.y()) << ", " << format_exact(t.z())
     << "], rpy_deg: [" << format_exact(rad_to_deg(rpy.x()) + 0.0) << ", " << format_exact(rad_to_deg(rpy.y()) + 0.0)
     << ", " << format_exact(rad_to_deg(rpy.z()) + 0.0) << "]}\n";
  return os.str();
}

}  // namespace touchdown::pose
