#include "touchdown/pose/sim/trajectory.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/se3.hpp"

namespace touchdown::pose {

namespace {

bool fits(const CameraModel& camera, const Constellation& k, const Eigen::Isometry3d& T, double margin) {
  for (const Led& led : k.leds) {
    const Eigen::Vector3d p = T * led.p_body;
    if (p.z() < 0.05) return false;
    const Eigen::Vector2d uv = camera.project(p);
    if (!camera.in_image(uv, margin)) return false;
  }
  return true;
}

// Largest s in [0, 1] with ok(s) (bisection; ok assumed monotone), or −1
// when even ok(0) fails.
double largest_fitting(const std::function<bool(double)>& ok) {
  if (ok(1)) return 1;
  if (!ok(0)) return -1;
  double lo = 0, hi = 1;
  for (int i = 0; i < 30; ++i) {
    const double mid = (lo + hi) / 2;
    (ok(mid) ? lo : hi) = mid;
  }
  return lo;
}

// How the drone's body sits in the camera frame before yaw and tilt.
//   Facing: the constellation's facing side (Constellation::facing(), body
//     −z when it has no normals) toward the camera, body facing axis ≈
//     camera −z; yaw turns about the camera's axis.
//   Chase (the source paper): the camera on the ground vehicle looks back,
//     tilted up; the drone follows behind and above, level, heading toward
//     the vehicle (body x = the vehicle's forward direction); yaw is its
//     heading, roll and pitch its attitude.
struct Framing {
  Eigen::Matrix3d left = Eigen::Matrix3d::Identity(), right = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // the constellation's, body frame
  bool has_left = false, has_right = false;            // skip identity products: trajectories stay bit-identical

  static Framing of(const Constellation& k, const TrajectoryOptions& o) {
    Framing f;
    f.centroid = k.centroid();
    if (o.geometry == CameraGeometry::Chase) {
      // World: x forward (the vehicle's), z up. Camera axes in the world:
      // x right (world +y when looking back), z back and up by the tilt.
      const double t = deg_to_rad(o.camera_tilt_deg);
      Eigen::Matrix3d R_world_camera;
      R_world_camera.col(0) = Eigen::Vector3d(0, 1, 0);
      R_world_camera.col(2) = Eigen::Vector3d(-std::cos(t), 0, std::sin(t));
      R_world_camera.col(1) = R_world_camera.col(2).cross(R_world_camera.col(0));
      f.left = R_world_camera.transpose();
      f.has_left = true;
      return f;
    }
    const Eigen::Vector3d facing = k.facing();
    const Eigen::Vector3d down(0, 0, -1);
    if (facing.squaredNorm() > 0 && (facing - down).norm() > 1e-12) {
      f.right = Eigen::Quaterniond::FromTwoVectors(facing, down).toRotationMatrix();
      f.has_right = true;
    }
    return f;
  }

  // The drone with its constellation's centroid at distance d from the
  // camera in the direction of the normalised image offset (a, b), rotated
  // by yaw and tilted by (roll, pitch).
  [[nodiscard]] Eigen::Isometry3d pose(double d, double a, double b, double yaw, double roll, double pitch) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    Eigen::Matrix3d R =
        (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
    if (has_left) R = left * R;
    if (has_right) R = R * right;
    T.linear() = R;
    T.translation() = d * Eigen::Vector3d(a, b, 1).normalized() - R * centroid;
    return T;
  }
};

// Shrinks tilt, then lateral offset, until the constellation fits; throws
// when it cannot fit even centred and level.
Eigen::Isometry3d fitted_pose(const CameraModel& camera, const Constellation& k, const Framing& framing, double margin,
                              double d, double a, double b, double yaw, double roll, double pitch,
                              const Eigen::Isometry3d& jitter = Eigen::Isometry3d::Identity()) {
  auto drone_pose = [&](double dd, double aa, double bb, double y, double r, double p) {
    return framing.pose(dd, aa, bb, y, r, p);
  };
  const double tilt_scale = largest_fitting(
      [&](double s) { return fits(camera, k, drone_pose(d, 0, 0, yaw, s * roll, s * pitch) * jitter, margin); });
  if (tilt_scale < 0) {
    throw InvalidArgument("make_trajectory: the constellation does not fit in the " + std::to_string(camera.width) +
                          "x" + std::to_string(camera.height) + " image at " + std::to_string(d) +
                          " m (increase min_distance or reduce margin_px)");
  }
  const double lateral_scale = largest_fitting([&](double s) {
    return fits(camera, k, drone_pose(d, s * a, s * b, yaw, tilt_scale * roll, tilt_scale * pitch) * jitter, margin);
  });
  return drone_pose(d, lateral_scale * a, lateral_scale * b, yaw, tilt_scale * roll, tilt_scale * pitch) * jitter;
}

}  // namespace

bool TrajectoryOptions::validate(std::string* why) const {
  if (!(min_distance > 0) || !(max_distance >= min_distance) || !(max_distance <= kMaxTrajectoryDistance)) {
    return invalid(why, "min_distance, max_distance: need 0 < min_distance <= max_distance <= " +
                            std::to_string(static_cast<int>(kMaxTrajectoryDistance)) + " m");
  }
  if (!(fps > 0) || !std::isfinite(fps)) return invalid(why, "fps: must be positive [Hz]");
  if (!(margin_px >= 0) || !std::isfinite(margin_px)) return invalid(why, "margin_px: must be >= 0 px");
  if (!(camera_tilt_deg >= 0 && camera_tilt_deg <= 80)) return invalid(why, "camera_tilt_deg: must be in [0, 80] deg");
  return true;
}

std::vector<TrajectorySample> make_trajectory(TrajectoryKind kind, int frames, std::uint64_t seed,
                                              const CameraModel& camera, const Constellation& constellation,
                                              const TrajectoryOptions& o) {
  if (frames < 1 || frames > kMaxTrajectoryFrames) {
    throw InvalidArgument("make_trajectory: frames must be in 1.." + std::to_string(kMaxTrajectoryFrames) + ", got " +
                          std::to_string(frames));
  }
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("make_trajectory: " + why);
  if (!camera.validate(&why)) throw InvalidArgument("make_trajectory: camera: " + why);
  if (!constellation.validate(&why)) throw InvalidArgument("make_trajectory: constellation: " + why);

  Rng rng(seed, 0);
  const Framing framing = Framing::of(constellation, o);
  const bool chase = o.geometry == CameraGeometry::Chase;
  // Chase: the heading sways about the vehicle's direction (the same
  // draws as the facing geometry's free yaw, mapped into ±kChaseYaw).
  const double kChaseYaw = deg_to_rad(15);
  // Lateral offsets are fractions of the half field of view.
  const double half_u = std::min(camera.cx, camera.width - 1 - camera.cx) / camera.fx;
  const double half_v = std::min(camera.cy, camera.height - 1 - camera.cy) / camera.fy;
  std::vector<TrajectorySample> out(static_cast<std::size_t>(frames));
  const double two_pi = 2 * std::numbers::pi;

  if (kind == TrajectoryKind::Static) {
    const int holds = std::min(6, frames);
    struct Hold {
      Eigen::Isometry3d T;
      std::array<double, 6> amp, freq, phase;  // jitter per axis (x, y, z, roll, pitch, yaw)
    };
    std::vector<Hold> hold(static_cast<std::size_t>(holds));
    // Allowance for the jitter when fitting the hold pose.
    const double margin = o.margin_px + 8;
    for (int j = 0; j < holds; ++j) {
      const double d =
          holds == 1 ? o.min_distance : o.min_distance + (o.max_distance - o.min_distance) * j / (holds - 1);
      const double a = rng.uniform(-0.6, 0.6) * half_u, b = rng.uniform(-0.6, 0.6) * half_v;
      const double yaw_draw = rng.uniform(-std::numbers::pi, std::numbers::pi);
      const double yaw = chase ? kChaseYaw * yaw_draw / std::numbers::pi : yaw_draw;
      const double roll = deg_to_rad(rng.uniform(-6, 6)), pitch = deg_to_rad(rng.uniform(-6, 6));
      Hold& hj = hold[static_cast<std::size_t>(j)];
      hj.T = fitted_pose(camera, constellation, framing, margin, d, a, b, yaw, roll, pitch);
      for (std::size_t axis = 0; axis < 6; ++axis) {
        hj.amp[axis] = (axis < 3 ? 0.003 : deg_to_rad(0.5)) * rng.uniform(0.5, 1.0);  // a few mm, ~0.5°
        hj.freq[axis] = rng.uniform(0.7, 2.3);                                        // [Hz] hovering sway
        hj.phase[axis] = rng.uniform(0, two_pi);
      }
    }
    for (int i = 0; i < frames; ++i) {
      const double t = i / o.fps;
      const Hold& hj = hold[static_cast<std::size_t>(static_cast<long long>(i) * holds / frames)];
      Vector6d xi;
      for (std::size_t axis = 0; axis < 6; ++axis) {
        xi[static_cast<Eigen::Index>(axis)] = hj.amp[axis] * std::sin(two_pi * hj.freq[axis] * t + hj.phase[axis]);
      }
      Eigen::Isometry3d T = hj.T * se3_exp(xi);  // jitter in the body frame
      if (!fits(camera, constellation, T, o.margin_px)) T = hj.T;
      out[static_cast<std::size_t>(i)] = {t, T};
    }
    return out;
  }

  // Moving: distance d(u) = min + (max − min)(1 − cos 2πu)/2, u ∈ [0, 1].
  const double f_a = rng.uniform(0.35, 0.55), f_b = rng.uniform(0.25, 0.45);  // [Hz] lateral
  const double ph_a = rng.uniform(0, two_pi), ph_b = rng.uniform(0, two_pi);
  const double yaw0 = rng.uniform(-std::numbers::pi, std::numbers::pi);
  const double yaw_sign = rng.uniform() < 0.5 ? -1 : 1;
  const double yaw_rate = yaw_sign * deg_to_rad(rng.uniform(60, 120));      // [rad/s]
  const double f_r = rng.uniform(0.2, 0.35), f_p = rng.uniform(0.25, 0.4);  // [Hz] tilt
  const double ph_r = rng.uniform(0, two_pi), ph_p = rng.uniform(0, two_pi);
  const double tilt = deg_to_rad(20) / std::numbers::sqrt2;  // per axis: |tilt| <= 20°
  for (int i = 0; i < frames; ++i) {
    const double t = i / o.fps;
    const double u = frames > 1 ? static_cast<double>(i) / (frames - 1) : 0.0;
    const double d = o.min_distance + (o.max_distance - o.min_distance) * (1 - std::cos(two_pi * u)) / 2;
    const double a = 0.6 * half_u * std::sin(two_pi * f_a * t + ph_a);
    const double b = 0.6 * half_v * std::sin(two_pi * f_b * t + ph_b);
    const double roll = tilt * std::sin(two_pi * f_r * t + ph_r), pitch = tilt * std::sin(two_pi * f_p * t + ph_p);
    const double yaw = chase ? kChaseYaw * std::sin(yaw0 + yaw_rate * t) : yaw0 + yaw_rate * t;
    out[static_cast<std::size_t>(i)] = {
        t, fitted_pose(camera, constellation, framing, o.margin_px, d, a, b, yaw, roll, pitch)};
  }
  return out;
}

const Eigen::Isometry3d& motion_blur_start(std::span<const TrajectorySample> samples, std::size_t i) {
  const Eigen::Isometry3d& T = samples[i].T_camera_body;
  if (i == 0) return T;
  const Eigen::Isometry3d& prev = samples[i - 1].T_camera_body;
  // A jump between hold points is a cut, not motion to blur.
  const Vector6d xi = se3_log(prev.inverse() * T);
  return xi.head<3>().norm() > 0.1 || xi.tail<3>().norm() > deg_to_rad(10) ? T : prev;
}

}  // namespace touchdown::pose
