#pragma once
// Shared fixtures of the pose tests: constellations of each shape, random
// well-conditioned poses, noisy observations.
#include <cmath>
#include <filesystem>
#include <vector>

#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/se3.hpp"

namespace tp = touchdown::pose;

namespace touchdown::pose_test {

inline const tp::PinholeCamera kCamera{615.0, 612.0, 424.0, 240.0};

#ifdef TOUCHDOWN_SOURCE_DIR
/// The bundled F450 LED constellation (data/constellations/f450_leds.yaml).
inline tp::Constellation f450() {
  return tp::load_constellation(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/constellations/f450_leds.yaml");
}
/// The source paper's layout: six LEDs on a forward-facing front board
/// (data/constellations/front_board.yaml).
inline tp::Constellation front_board() {
  return tp::load_constellation(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/constellations/front_board.yaml");
}
/// The bundled RealSense D435 colour camera (data/cameras/d435_848x480.yaml).
inline tp::CameraModel d435() {
  return tp::load_camera(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/cameras/d435_848x480.yaml");
}
#endif

enum class Shape { NonPlanar, Planar, QuasiPlanar };

// An LED constellation on a drone (body frame, metres).
inline std::vector<Eigen::Vector3d> constellation(Shape shape, touchdown::Rng& rng, int n = 6) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    double z = 0;
    if (shape == Shape::NonPlanar) z = rng.uniform(-0.08, 0.08);
    if (shape == Shape::QuasiPlanar) z = rng.uniform(-0.003, 0.003);
    const double y = 0.15 * std::sin(a) + rng.uniform(-0.02, 0.02);  // drawn y first, as recorded
    p.emplace_back(0.2 * std::cos(a) + rng.uniform(-0.02, 0.02), y, z);
  }
  return p;
}

inline Eigen::Isometry3d random_pose(touchdown::Rng& rng) {
  tp::Vector6d xi;
  xi << rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 0, rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6),
      rng.uniform(-3, 3);
  Eigen::Isometry3d T = tp::se3_exp(xi);
  T.translation().z() += rng.uniform(0.6, 3.0);  // 0.6 - 3 m in front of the camera
  return T;
}

inline std::vector<Eigen::Vector2d> observe(const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3d>& p,
                                            touchdown::Rng& rng, double noise_px) {
  std::vector<Eigen::Vector2d> uv;
  for (const auto& q : p) uv.push_back(kCamera.project(T * q) + noise_px * normal_vector2(rng));
  return uv;
}

inline Eigen::Isometry3d perturb(const Eigen::Isometry3d& T, touchdown::Rng& rng) {
  tp::Vector6d d;
  for (int i = 0; i < 3; ++i) d[i] = rng.uniform(-0.05, 0.05);
  for (int i = 3; i < 6; ++i) d[i] = rng.uniform(-0.12, 0.12);  // about 7°
  return tp::se3_exp(d) * T;
}

}  // namespace touchdown::pose_test
