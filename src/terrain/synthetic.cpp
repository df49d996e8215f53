#include "touchdown/terrain/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::terrain::synthetic {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// (along, across) coordinates of (x, y) for the shape's azimuth.
Eigen::Vector2d local(const Shape& s, double x, double y) {
  const double c = std::cos(deg_to_rad(s.azimuth_deg)), sn = std::sin(deg_to_rad(s.azimuth_deg));
  return {c * x + sn * y, -sn * x + c * y};
}

}  // namespace

void Shape::prepare() {
  rocks.clear();
  if (kind != ShapeKind::Rubble) return;
  Rng rng(rubble_seed, 0x7275626Cull);
  for (int k = 0; k < rubble_count; ++k) {
    Rock r;
    r.centre = {rng.uniform(-rubble_extent, rubble_extent), rng.uniform(-rubble_extent, rubble_extent)};
    r.radii = {rng.uniform(0.04, 0.15), rng.uniform(0.04, 0.15)};
    r.height = rng.uniform(0.25, 1.0) * rubble_max_height;
    rocks.push_back(r);
  }
}

double Shape::height(double x, double y) const {
  const Eigen::Vector2d p = local(*this, x, y);
  switch (kind) {
    case ShapeKind::Flat:
      return base_z;
    case ShapeKind::Incline:
      return base_z + std::tan(deg_to_rad(slope_deg)) * p.x();
    case ShapeKind::Step:
      return base_z + (p.x() > edge_offset ? step_height : 0.0);
    case ShapeKind::Plateau:
      return base_z + (std::abs(p.x()) < 0.5 * plateau_size.x() && std::abs(p.y()) < 0.5 * plateau_size.y()
                           ? plateau_height
                           : 0.0);
    case ShapeKind::Post:
      return base_z + ((Eigen::Vector2d(x, y) - post_xy).norm() < post_radius ? post_height : 0.0);
    case ShapeKind::Rubble: {
      double z = 0.0;
      for (const Rock& r : rocks) {
        const double u = (x - r.centre.x()) / r.radii.x(), v = (y - r.centre.y()) / r.radii.y();
        const double q = 1.0 - u * u - v * v;
        if (q > 0) z = std::max(z, r.height * std::sqrt(q));
      }
      return base_z + z;
    }
  }
  return base_z;
}

double Shape::distance_to_edge(double x, double y) const {
  const Eigen::Vector2d p = local(*this, x, y);
  switch (kind) {
    case ShapeKind::Flat:
    case ShapeKind::Incline:
      return kInf;
    case ShapeKind::Step:
      return std::abs(p.x() - edge_offset);
    case ShapeKind::Plateau: {
      const double dx = std::abs(p.x()) - 0.5 * plateau_size.x(), dy = std::abs(p.y()) - 0.5 * plateau_size.y();
      if (dx < 0 && dy < 0) return std::min(-dx, -dy);
      return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
    }
    case ShapeKind::Post:
      return std::abs((Eigen::Vector2d(x, y) - post_xy).norm() - post_radius);
    case ShapeKind::Rubble: {
      double d = kInf;
      for (const Rock& r : rocks) {
        d = std::min(d, std::abs((Eigen::Vector2d(x, y) - r.centre).norm() - r.radii.minCoeff()));
      }
      return std::max(0.0, d - 0.1);  // ellipse: a conservative bound
    }
  }
  return kInf;
}

Eigen::Isometry3d nadir_camera_pose(double x, double y, double height_m, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  // Optical frame: z forward (down in the world), x right, y down in the image.
  T.linear() = (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, height_m);
  return T;
}

PointCloud render_depth_scan(const Shape& shape, const DepthCamera& cam, const Eigen::Isometry3d& T_world_camera,
                             std::uint64_t seed) {
  if (cam.width <= 0 || cam.height <= 0 || !(cam.fx > 0) || !(cam.fy > 0)) {
    throw InvalidArgument("depth camera: width, height, fx and fy must be positive");
  }
  // Height range of the shape bounds the ray march.
  double zlo = shape.base_z, zhi = shape.base_z;
  switch (shape.kind) {
    case ShapeKind::Step:
      zhi += std::max(0.0, shape.step_height);
      zlo += std::min(0.0, shape.step_height);
      break;
    case ShapeKind::Plateau:
      zhi += std::max(0.0, shape.plateau_height);
      zlo += std::min(0.0, shape.plateau_height);
      break;
    case ShapeKind::Rubble:
      zhi += shape.rubble_max_height;
      break;
    case ShapeKind::Post:
      zhi += std::max(0.0, shape.post_height);
      zlo += std::min(0.0, shape.post_height);
      break;
    default:
      break;
  }
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d o = T_world_camera.translation();
  const std::size_t w = static_cast<std::size_t>(cam.width), h = static_cast<std::size_t>(cam.height);
  std::vector<double> depth(w * h, std::numeric_limits<double>::quiet_NaN());

  for (std::size_t v = 0; v < h; ++v) {
    for (std::size_t u = 0; u < w; ++u) {
      const Eigen::Vector3d ray_c((static_cast<double>(u) - cam.cx) / cam.fx,
                                  (static_cast<double>(v) - cam.cy) / cam.fy, 1.0);
      const Eigen::Vector3d d = R * ray_c;  // not unit: t is the optical depth
      if (d.z() >= -1e-9) continue;         // looks at or above the horizon
      auto f = [&](double t) {
        const Eigen::Vector3d p = o + t * d;
        return p.z() - shape.height(p.x(), p.y());
      };
      if (shape.kind == ShapeKind::Flat || shape.kind == ShapeKind::Incline) {
        // A plane n·p = base_z with n = (-slope·cos az, -slope·sin az, 1).
        const double az = deg_to_rad(shape.azimuth_deg);
        const double sl = shape.kind == ShapeKind::Incline ? std::tan(deg_to_rad(shape.slope_deg)) : 0.0;
        const Eigen::Vector3d n(-sl * std::cos(az), -sl * std::sin(az), 1.0);
        const double nd = n.dot(d);
        if (std::abs(nd) < 1e-12) continue;
        const double t = (shape.base_z - n.dot(o)) / nd;
        if (t >= cam.min_range && t <= cam.max_range) depth[v * w + u] = t;
        continue;
      }
      // March from where the ray drops below the highest point of the shape
      // to below the lowest, then bisect the first sign change.
      double t0 = std::max(0.0, (zhi - o.z()) / d.z());
      double t1 = (zlo - o.z()) / d.z() + 1e-6;
      t1 = std::min(t1, cam.max_range);
      if (t0 >= t1) continue;
      const double step = 0.003 / d.norm();
      double a = t0, fa = f(a);
      if (fa <= 0) {
        if (a >= cam.min_range) depth[v * w + u] = a;
        continue;
      }
      for (double b = std::min(a + step, t1);; b = std::min(b + step, t1)) {
        const double fb = f(b);
        if (fb <= 0) {
          for (int it = 0; it < 40; ++it) {  // bisect to well below a micrometre
            const double m = 0.5 * (a + b);
            if (f(m) > 0)
              a = m;
            else
              b = m;
          }
          const double t = 0.5 * (a + b);
          if (t >= cam.min_range && t <= cam.max_range) depth[v * w + u] = t;
          break;
        }
        a = b;
        if (b >= t1) break;
      }
    }
  }

  Rng rng(seed, 0x64657074ull);
  std::vector<double> noisy = depth;
  // Flying pixels: a pixel beside a depth jump returns a mix of both sides.
  if (cam.flying_pixels) {
    for (std::size_t v = 0; v < h; ++v) {
      for (std::size_t u = 0; u + 1 < w; ++u) {
        const double a = depth[v * w + u], b = depth[v * w + u + 1];
        if (std::isfinite(a) && std::isfinite(b) && std::abs(a - b) > 0.03 && rng.uniform() < 0.5) {
          const double mix = rng.uniform(0.2, 0.8);
          noisy[v * w + (a < b ? u + 1 : u)] = mix * a + (1 - mix) * b;
        }
      }
    }
  }
  PointCloud cloud;
  cloud.width = static_cast<std::uint32_t>(w);
  cloud.height = static_cast<std::uint32_t>(h);
  cloud.points.resize(w * h);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t v = 0; v < h; ++v) {
    for (std::size_t u = 0; u < w; ++u) {
      double z = noisy[v * w + u];
      const double r_drop = rng.uniform(), r_out = rng.uniform(), r_noise = rng.normal();
      if (!std::isfinite(z) || r_drop < cam.dropout_fraction) {
        cloud.points[v * w + u] = Eigen::Vector3f::Constant(nan);
        continue;
      }
      if (r_out < cam.outlier_fraction) {
        z = rng.uniform(cam.min_range, z);
      } else {
        z += r_noise * z * z * cam.subpixel / (cam.fx * cam.baseline);
      }
      cloud.points[v * w + u] =
          Eigen::Vector3f(static_cast<float>((static_cast<double>(u) - cam.cx) / cam.fx * z),
                          static_cast<float>((static_cast<double>(v) - cam.cy) / cam.fy * z), static_cast<float>(z));
    }
  }
  return cloud;
}

}  // namespace touchdown::terrain::synthetic
