// The renderer's meshes and polygon clipping (render_mesh.hpp).
#include "scenario/render_mesh.hpp"

#include <algorithm>
#include <cmath>

#include "touchdown/core/random.hpp"

namespace touchdown::scenario::render_detail {

Mesh tessellate(const Solid& s, std::uint64_t seed) {
  Mesh m;
  m.bgr = s.bgr;
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> quads_as_tris;
  auto add_tri = [&](int a, int b, int c) { quads_as_tris.push_back({a, b, c}); };
  auto add_quad = [&](int a, int b, int c, int d) {
    add_tri(a, b, c);
    add_tri(a, c, d);
  };
  constexpr int kSides = 16;
  switch (s.shape) {
    case Solid::Shape::Box: {
      const Eigen::Vector3d h = 0.5 * s.size;
      for (int i = 0; i < 8; ++i)
        v.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
      add_quad(0, 1, 3, 2), add_quad(4, 5, 7, 6), add_quad(0, 1, 5, 4);
      add_quad(2, 3, 7, 6), add_quad(0, 2, 6, 4), add_quad(1, 3, 7, 5);
      break;
    }
    case Solid::Shape::Cylinder:
    case Solid::Shape::Cone: {
      const double r = s.size.x(), hz = 0.5 * s.size.z();
      const bool cone = s.shape == Solid::Shape::Cone;
      for (int i = 0; i < kSides; ++i) {
        const double a = 2 * kPi * i / kSides;
        v.emplace_back(r * std::cos(a), r * std::sin(a), -hz);
        if (!cone) v.emplace_back(r * std::cos(a), r * std::sin(a), hz);
      }
      const int bottom = static_cast<int>(v.size());
      v.emplace_back(0, 0, -hz);
      v.emplace_back(0, 0, hz);
      const int step = cone ? 1 : 2;
      for (int i = 0; i < kSides; ++i) {
        const int a = i * step, b = ((i + 1) % kSides) * step;
        add_tri(bottom, a, b);
        if (cone) {
          add_tri(a, b, bottom + 1);
        } else {
          add_tri(bottom + 1, a + 1, b + 1);
          add_quad(a, b, b + 1, a + 1);
        }
      }
      break;
    }
    case Solid::Shape::Sphere:
    case Solid::Shape::Capsule: {
      // UV sphere (8 stacks, 12 slices); a capsule splits it at the equator.
      const double r = s.size.x(), hl = s.shape == Solid::Shape::Capsule ? 0.5 * s.size.z() : 0.0;
      constexpr int kStacks = 8, kSlices = 12;
      std::vector<double> ring_z, ring_r;
      for (int i = 1; i < kStacks; ++i) {
        const double phi = kPi * i / kStacks, z = r * std::cos(phi), rr = r * std::sin(phi);
        if (i == kStacks / 2 && hl > 0) {
          ring_z.push_back(hl), ring_r.push_back(rr);
          ring_z.push_back(-hl), ring_r.push_back(rr);
        } else {
          ring_z.push_back(z + (z > 0 ? hl : -hl)), ring_r.push_back(rr);
        }
      }
      for (std::size_t k = 0; k < ring_z.size(); ++k) {
        for (int j = 0; j < kSlices; ++j) {
          const double a = 2 * kPi * j / kSlices;
          v.emplace_back(ring_r[k] * std::cos(a), ring_r[k] * std::sin(a), ring_z[k]);
        }
      }
      const int top = static_cast<int>(v.size());
      v.emplace_back(0, 0, r + hl);
      v.emplace_back(0, 0, -r - hl);
      const int rings = static_cast<int>(ring_z.size());
      for (int j = 0; j < kSlices; ++j) {
        const int jn = (j + 1) % kSlices;
        add_tri(top, j, jn);
        add_tri(top + 1, (rings - 1) * kSlices + j, (rings - 1) * kSlices + jn);
        for (int k = 0; k + 1 < rings; ++k)
          add_quad(k * kSlices + j, k * kSlices + jn, (k + 1) * kSlices + jn, (k + 1) * kSlices + j);
      }
      break;
    }
  }
  // Every primitive is convex and centred on its origin: wind each triangle
  // so that its normal points away from the origin.
  for (auto& t : quads_as_tris) {
    const Eigen::Vector3d n = (v[static_cast<std::size_t>(t[1])] - v[static_cast<std::size_t>(t[0])])
                                  .cross(v[static_cast<std::size_t>(t[2])] - v[static_cast<std::size_t>(t[0])]);
    const Eigen::Vector3d c =
        v[static_cast<std::size_t>(t[0])] + v[static_cast<std::size_t>(t[1])] + v[static_cast<std::size_t>(t[2])];
    if (n.squaredNorm() < 1e-24) continue;  // degenerate (zero-size solid)
    if (n.dot(c) < 0) std::swap(t[1], t[2]);
    m.tri.push_back(t);
  }
  for (const auto& p : v) m.v.push_back(s.pose * p);
  Rng rng(seed);
  for (std::size_t i = 0; i < m.tri.size(); ++i) m.tint.push_back(static_cast<float>(rng.uniform(0.93, 1.07)));
  Eigen::Vector3d lo = m.v.front(), hi = m.v.front();
  for (const auto& p : m.v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  m.centre = 0.5 * (lo + hi);
  for (const auto& p : m.v) m.radius = std::max(m.radius, (p - m.centre).norm());
  return m;
}

// ---- polygon clipping (Sutherland–Hodgman) ----

void clip_near(const std::vector<Eigen::Vector3d>& in, std::vector<Eigen::Vector3d>& out) {
  out.clear();
  const std::size_t n = in.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = in[i];
    const Eigen::Vector3d& b = in[(i + 1) % n];
    const bool ia = a.z() >= kNear, ib = b.z() >= kNear;
    if (ia) out.push_back(a);
    if (ia != ib) out.push_back(a + (b - a) * ((kNear - a.z()) / (b.z() - a.z())));
  }
}

void clip_rect(std::vector<Eigen::Vector2d>& poly, std::vector<Eigen::Vector2d>& tmp, double x0, double y0, double x1,
               double y1) {
  auto pass = [&](int axis, double bound, bool keep_above) {
    tmp.clear();
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = poly[i];
      const Eigen::Vector2d& b = poly[(i + 1) % n];
      const bool ia = keep_above ? a[axis] >= bound : a[axis] <= bound;
      const bool ib = keep_above ? b[axis] >= bound : b[axis] <= bound;
      if (ia) tmp.push_back(a);
      if (ia != ib) tmp.push_back(a + (b - a) * ((bound - a[axis]) / (b[axis] - a[axis])));
    }
    poly.swap(tmp);
  };
  pass(0, x0, true);
  pass(0, x1, false);
  pass(1, y0, true);
  pass(1, y1, false);
}

double shoelace(const std::vector<Eigen::Vector2d>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d& q = p[(i + 1) % p.size()];
    a += p[i].x() * q.y() - q.x() * p[i].y();
  }
  return 0.5 * std::abs(a);
}

}  // namespace touchdown::scenario::render_detail
