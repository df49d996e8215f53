#include "contacts.hpp"

#include <ccd/ccd.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace touchdown::twin::detail {
namespace {

// Keeps contacts of one primitive distinct: a sphere resting on a vertex
// touches six triangles at the same point.
void push_unique(std::vector<Contact>& out, std::size_t first, const Contact& c) {
  for (std::size_t i = first; i < out.size(); ++i) {
    if ((out[i].position - c.position).squaredNorm() < 1e-6 && out[i].normal.dot(c.normal) > 0.995) {
      if (c.depth > out[i].depth) out[i] = c;
      return;
    }
  }
  out.push_back(c);
}

// Closest points of segments p1-q1 and p2-q2 (Ericson, Real-Time Collision
// Detection, sec. 5.1.9); returns the squared distance.
double closest_segment_segment(const Eigen::Vector3d& p1, const Eigen::Vector3d& q1, const Eigen::Vector3d& p2,
                               const Eigen::Vector3d& q2, Eigen::Vector3d& c1, Eigen::Vector3d& c2) {
  const Eigen::Vector3d d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  constexpr double eps = 1e-18;
  if (a <= eps && e <= eps) {
    s = t = 0;
  } else if (a <= eps) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= eps) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > eps ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  c1 = p1 + d1 * s;
  c2 = p2 + d2 * t;
  return (c1 - c2).squaredNorm();
}

// ---- libccd adapters (support and centre functions of convex shapes) ----

// A terrain triangle: its vertices where the terrain model keeps them.
struct Tri {
  const Eigen::Vector3d* v[3];
};
struct DiskShape {
  Eigen::Vector3d c, n;
  double r, h;
  double reach;  // radius of the sphere about c holding the disk: hypot(r, h)
};
struct BoxShape {
  Eigen::Vector3d c;
  Eigen::Matrix3d axes;  // columns
  Eigen::Vector3d half;
  double reach;  // |half|
};

Eigen::Vector3d to_eigen(const ccd_vec3_t* v) { return {v->v[0], v->v[1], v->v[2]}; }
void to_ccd(const Eigen::Vector3d& e, ccd_vec3_t* v) {
  v->v[0] = e.x();
  v->v[1] = e.y();
  v->v[2] = e.z();
}

void tri_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* t = static_cast<const Tri*>(obj);
  const Eigen::Vector3d d = to_eigen(dir);
  int best = 0;
  for (int k = 1; k < 3; ++k) {
    if (t->v[k]->dot(d) > t->v[best]->dot(d)) best = k;
  }
  to_ccd(*t->v[best], out);
}
void tri_center(const void* obj, ccd_vec3_t* out) {
  const auto* t = static_cast<const Tri*>(obj);
  to_ccd((*t->v[0] + *t->v[1] + *t->v[2]) / 3.0, out);
}
void disk_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* s = static_cast<const DiskShape*>(obj);
  const Eigen::Vector3d d = to_eigen(dir);
  const double dn = d.dot(s->n);
  Eigen::Vector3d p = s->c + (dn >= 0 ? s->h : -s->h) * s->n;
  const Eigen::Vector3d radial = d - dn * s->n;
  const double len = radial.norm();
  if (len > 1e-12) p += s->r * radial / len;
  to_ccd(p, out);
}
void disk_center(const void* obj, ccd_vec3_t* out) { to_ccd(static_cast<const DiskShape*>(obj)->c, out); }
void box_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* b = static_cast<const BoxShape*>(obj);
  const Eigen::Vector3d d = to_eigen(dir);
  Eigen::Vector3d p = b->c;
  for (int k = 0; k < 3; ++k) p += (b->axes.col(k).dot(d) >= 0 ? 1.0 : -1.0) * b->half[k] * b->axes.col(k);
  to_ccd(p, out);
}
void box_center(const void* obj, ccd_vec3_t* out) { to_ccd(static_cast<const BoxShape*>(obj)->c, out); }

// Exact separation tests that spare MPR most triangles it would find apart
// (MPR on a separated pair costs as much as on a touching one): the
// shape's own axes (a disk's normal, a box's three face normals), then the
// sphere that holds the shape. `margin` keeps every pair that MPR might
// still call touching (its tolerance is 1e-6) with MPR, so the contacts
// are the same as without the tests.
constexpr double kSeparationMargin = 1e-5;
bool separated_on_axis(const Tri& t, const Eigen::Vector3d& axis, double centre, double half) {
  const double a = t.v[0]->dot(axis), b = t.v[1]->dot(axis), c = t.v[2]->dot(axis);
  return std::min({a, b, c}) > centre + half + kSeparationMargin ||
         std::max({a, b, c}) < centre - half - kSeparationMargin;
}
bool beyond_reach(const Tri& t, const Eigen::Vector3d& centre, double reach) {
  const double r = reach + kSeparationMargin;
  return (closest_point_on_triangle(centre, *t.v[0], *t.v[1], *t.v[2]) - centre).squaredNorm() > r * r;
}
bool separated_on_own_axes(const DiskShape& s, const Tri& t) { return separated_on_axis(t, s.n, s.n.dot(s.c), s.h); }
bool separated_on_own_axes(const BoxShape& s, const Tri& t) {
  for (int k = 0; k < 3; ++k) {
    if (separated_on_axis(t, s.axes.col(k), s.axes.col(k).dot(s.c), s.half[k])) return true;
  }
  return false;
}

double extent_along(const DiskShape& s, const Eigen::Vector3d& n) {
  const double c = std::min(1.0, std::abs(n.dot(s.n)));
  return s.r * std::sqrt(std::max(0.0, 1.0 - c * c)) + s.h * c;
}
double extent_along(const BoxShape& s, const Eigen::Vector3d& n) {
  return (s.axes.transpose() * n).cwiseAbs().dot(s.half);
}

template <typename Shape>
void collide_convex(const TerrainModel& terrain, const Shape& shape, const Eigen::AlignedBox3d& aabb,
                    ccd_support_fn support, ccd_center_fn center, Scratch& scratch, std::vector<Contact>& out) {
  candidate_triangles(terrain, aabb, scratch);
  const std::size_t first = out.size();
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = support;
  ccd.center1 = center;
  ccd.support2 = tri_support;
  ccd.center2 = tri_center;
  ccd.max_iterations = 100;
  ccd.mpr_tolerance = 1e-6;
  for (std::uint32_t t : scratch.triangles) {
    const Tri tri{{&terrain.vertex(t, 0), &terrain.vertex(t, 1), &terrain.vertex(t, 2)}};
    // Exact separation tests before MPR, cheapest first (the outcome does
    // not depend on their order): the shape's own axes, the shape's extent
    // along the triangle's normal against its plane, the holding sphere.
    const Eigen::Vector3d& n = terrain.normal(t);
    if (separated_on_own_axes(shape, tri) || std::abs(n.dot(shape.c - *tri.v[0])) > extent_along(shape, n) ||
        beyond_reach(tri, shape.c, shape.reach)) {
      continue;
    }
    ccd_real_t depth;
    ccd_vec3_t dir, pos;
    if (ccdMPRPenetration(&shape, &tri, &ccd, &depth, &dir, &pos) != 0) continue;
    if (!(depth > 0) || !std::isfinite(depth)) continue;
    Contact c;
    c.position = to_eigen(&pos);
    c.normal = to_eigen(&dir).normalized();
    // A touching (zero-depth) pair can leave MPR without a direction.
    if (!c.position.allFinite() || !c.normal.allFinite() || !(c.normal.squaredNorm() > 0.5)) continue;
    // Orient from the terrain into the part.
    if (c.normal.dot(shape.c - c.position) < 0) c.normal = -c.normal;
    c.depth = depth;
    push_unique(out, first, c);
  }
}

}  // namespace

void candidate_triangles(const TerrainModel& terrain, const Eigen::AlignedBox3d& box, Scratch& scratch) {
  scratch.triangles.clear();
  if (box.min().z() > scratch.z_top) return;
  if (scratch.height_field != nullptr) {
    scratch.height_field->triangles_overlapping(box, scratch.triangles);
  } else {
    terrain.triangles_overlapping(box, scratch.triangles);
  }
}

void merge_patch_contacts(std::vector<Contact>& out, std::size_t first, double distance, double cos_angle) {
  if (out.size() - first < 2) return;
  // Deepest first, ties in the order found: an insertion sort (a part has
  // a handful of contacts, and std::stable_sort allocates: no allocation
  // per step, tests/twin/landing_allocation_test.cpp).
  for (std::size_t k = first + 1; k < out.size(); ++k) {
    const Contact c = out[k];
    std::size_t m = k;
    for (; m > first && out[m - 1].depth < c.depth; --m) out[m] = out[m - 1];
    out[m] = c;
  }
  std::size_t kept = first;
  const double d2 = distance * distance;
  for (std::size_t k = first; k < out.size(); ++k) {
    bool merged = false;
    for (std::size_t m = first; m < kept && !merged; ++m) {
      merged = (out[m].position - out[k].position).squaredNorm() <= d2 && out[m].normal.dot(out[k].normal) >= cos_angle;
      if (merged) out[m].weight += out[k].weight * out[k].depth / out[m].depth;
    }
    if (!merged) out[kept++] = out[k];
  }
  out.resize(kept);
}

Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c) {
  // Voronoi-region walk (Ericson, sec. 5.1.5).
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

double closest_segment_triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Vector3d& on_segment,
                                Eigen::Vector3d& on_triangle) {
  // Does the segment cross the triangle? (Möller–Trumbore)
  const Eigen::Vector3d d = p1 - p0, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) > 1e-15) {
    const Eigen::Vector3d s = p0 - a;
    const double u = s.dot(h) / det;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det, t = e2.dot(q) / det;
    if (u >= 0 && v >= 0 && u + v <= 1 && t >= 0 && t <= 1) {
      on_segment = on_triangle = p0 + t * d;
      return 0.0;
    }
  }
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](const Eigen::Vector3d& ps, const Eigen::Vector3d& pt) {
    const double d2 = (ps - pt).squaredNorm();
    if (d2 < best) {
      best = d2;
      on_segment = ps;
      on_triangle = pt;
    }
  };
  consider(p0, closest_point_on_triangle(p0, a, b, c));
  consider(p1, closest_point_on_triangle(p1, a, b, c));
  const Eigen::Vector3d* v[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d cs, ct;
    closest_segment_segment(p0, p1, *v[k], *v[(k + 1) % 3], cs, ct);
    consider(cs, ct);
  }
  return best;
}

void collide_sphere(const TerrainModel& terrain, const Eigen::Vector3d& centre, double radius, Scratch& scratch,
                    std::vector<Contact>& out) {
  const Eigen::Vector3d r = Eigen::Vector3d::Constant(radius);
  candidate_triangles(terrain, Eigen::AlignedBox3d(centre - r, centre + r), scratch);
  const std::size_t first = out.size();
  for (std::uint32_t t : scratch.triangles) {
    const Eigen::Vector3d &a = terrain.vertex(t, 0), &b = terrain.vertex(t, 1), &c = terrain.vertex(t, 2);
    const Eigen::Vector3d q = closest_point_on_triangle(centre, a, b, c);
    const Eigen::Vector3d delta = centre - q;
    const double d2 = delta.squaredNorm();
    if (d2 >= radius * radius) continue;
    const double dist = std::sqrt(d2);
    Contact ct;
    ct.position = q;
    ct.normal = dist > 1e-9 ? Eigen::Vector3d(delta / dist) : terrain.normal(t);
    ct.depth = radius - dist;
    push_unique(out, first, ct);
  }
}

void collide_capsule(const TerrainModel& terrain, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                     Scratch& scratch, std::vector<Contact>& out) {
  Eigen::AlignedBox3d box(a.cwiseMin(b), a.cwiseMax(b));
  box.min().array() -= radius;
  box.max().array() += radius;
  candidate_triangles(terrain, box, scratch);
  const std::size_t first = out.size();
  for (std::uint32_t t : scratch.triangles) {
    const Eigen::Vector3d &v0 = terrain.vertex(t, 0), &v1 = terrain.vertex(t, 1), &v2 = terrain.vertex(t, 2);
    const Eigen::Vector3d& n = terrain.normal(t);
    // The segment's closest point, plus both end caps so that a capsule
    // lying on one large triangle rests on two points.
    Eigen::Vector3d ps, pt;
    const double d2 = closest_segment_triangle(a, b, v0, v1, v2, ps, pt);
    auto add = [&](const Eigen::Vector3d& on_seg, const Eigen::Vector3d& on_tri, double dist2) {
      if (dist2 >= radius * radius) return;
      const double dist = std::sqrt(dist2);
      Contact c;
      c.position = on_tri;
      if (dist > 1e-9) {
        c.normal = (on_seg - on_tri) / dist;
        c.depth = radius - dist;
      } else {  // the axis pierces the triangle: push out along the face normal
        c.normal = n;
        const double below = std::max(0.0, -std::min((a - v0).dot(n), (b - v0).dot(n)));
        c.depth = radius + below;
      }
      push_unique(out, first, c);
    };
    add(ps, pt, d2);
    for (const Eigen::Vector3d* end : {&a, &b}) {
      const Eigen::Vector3d q = closest_point_on_triangle(*end, v0, v1, v2);
      add(*end, q, (*end - q).squaredNorm());
    }
  }
}

void collide_disk(const TerrainModel& terrain, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                  double radius, double half_thickness, Scratch& scratch, std::vector<Contact>& out) {
  const DiskShape s{centre, axis.normalized(), radius, half_thickness, std::hypot(radius, half_thickness)};
  // AABB of a disk: radius·sqrt(1 - n_i²) + h·|n_i| per axis.
  const Eigen::Array3d n2 = s.n.array().square();
  const Eigen::Vector3d ext = (radius * (1.0 - n2).max(0.0).sqrt() + half_thickness * s.n.array().abs()).matrix();
  collide_convex(terrain, s, Eigen::AlignedBox3d(centre - ext, centre + ext), disk_support, disk_center, scratch, out);
}

void collide_box(const TerrainModel& terrain, const Eigen::Vector3d& centre, const Eigen::Matrix3d& axes,
                 const Eigen::Vector3d& half_extents, Scratch& scratch, std::vector<Contact>& out) {
  const BoxShape s{centre, axes, half_extents, half_extents.norm()};
  const Eigen::Vector3d ext = axes.cwiseAbs() * half_extents;
  const Eigen::AlignedBox3d aabb(centre - ext, centre + ext);
  // One MPR point per triangle does not hold a box resting on a face: the
  // points move with the portal from step to step and may all fall on one
  // side, so the box rocks and never comes to rest. Points fixed to either
  // body do: the box's corners inside the terrain and the terrain's
  // vertices inside the box.
  std::vector<Contact>& found = scratch.contacts;
  found.clear();
  candidate_triangles(terrain, aabb, scratch);
  // A corner inside the terrain solid leaves through the nearest face it is
  // behind (its projection inside the triangle, no deeper than the box's
  // smallest half extent).
  const double max_depth = half_extents.minCoeff();
  bool corner_in[8] = {false, false, false, false, false, false, false, false};  // bit i: + along axis i
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d sign((k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0);
    const Eigen::Vector3d corner = centre + axes * sign.cwiseProduct(half_extents);
    Contact best;
    best.depth = std::numeric_limits<double>::infinity();
    for (std::uint32_t t : scratch.triangles) {
      const Eigen::Vector3d &a = terrain.vertex(t, 0), &b = terrain.vertex(t, 1), &c = terrain.vertex(t, 2);
      const Eigen::Vector3d& n = terrain.normal(t);
      const double d = (corner - a).dot(n);
      if (d >= 0 || -d > max_depth || -d >= best.depth) continue;
      const Eigen::Vector3d on_plane = corner - d * n;
      if ((closest_point_on_triangle(on_plane, a, b, c) - on_plane).squaredNorm() > 1e-12) continue;
      best.position = corner;
      best.normal = n;
      best.depth = -d;
    }
    if (std::isfinite(best.depth)) {
      found.push_back(best);
      corner_in[k] = true;
    }
  }
  // Whether the corners inside the terrain already hold a terrain point
  // `q` (box frame) pushing through face axis `f`: it lies inside the hull
  // of their projections onto that face, which is the whole face (4 of its
  // corners inside) or half of it (3). Such points would only repeat the
  // corners' support, and picking among them (level ground under a level
  // face has dozens, all about as deep) would change from step to step.
  auto covered = [&](const Eigen::Vector3d& q, int f) {
    const int a = (f + 1) % 3, b = (f + 2) % 3;
    bool in[2][2] = {{false, false}, {false, false}};
    int count = 0;
    for (int k = 0; k < 8; ++k) {
      if (!corner_in[k]) continue;
      const int sa = (k >> a) & 1, sb = (k >> b) & 1;
      count += !in[sa][sb];
      in[sa][sb] = true;
    }
    if (count == 4) return true;
    if (count < 3) return false;
    for (int sa = 0; sa < 2; ++sa) {
      for (int sb = 0; sb < 2; ++sb) {
        if (in[sa][sb]) continue;  // the missing corner: covered on the far side of its diagonal
        const double ma = sa ? 1.0 : -1.0, mb = sb ? 1.0 : -1.0;
        return ma * q[a] / half_extents[a] + mb * q[b] / half_extents[b] <= 0;
      }
    }
    return false;
  };
  // A terrain vertex inside the box pushes it out through the nearest of
  // the faces that look at the terrain there (outward normal against the
  // vertex normal): a vertex of level ground just inside the bottom face
  // near a side face belongs to the bottom face, not the side.
  auto& vn = scratch.vertex_normals;
  vn.clear();
  for (std::uint32_t t : scratch.triangles) {
    const Eigen::Vector3d &a = terrain.vertex(t, 0), &b = terrain.vertex(t, 1), &c = terrain.vertex(t, 2);
    const Eigen::Vector3d n = (b - a).cross(c - a);  // area-weighted
    for (int k = 0; k < 3; ++k) vn.emplace_back(terrain.vertex_index(t, k), n);
  }
  std::sort(vn.begin(), vn.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t i = 0; i < vn.size();) {
    const std::uint32_t v = vn[i].first;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (; i < vn.size() && vn[i].first == v; ++i) normal += vn[i].second;
    const Eigen::Vector3d p = terrain.mesh().vertices[v].cast<double>();
    const Eigen::Vector3d q = axes.transpose() * (p - centre);
    const Eigen::Vector3d slack = half_extents - q.cwiseAbs();
    if (!(slack.array() > 0).all() || !(normal.squaredNorm() > 0)) continue;
    normal.normalize();
    int face = -1;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d outward = (q[k] >= 0 ? 1.0 : -1.0) * axes.col(k);
      if (outward.dot(normal) < -0.2 && (face < 0 || slack[k] < slack[face])) face = k;
    }
    if (face < 0 || covered(q, face)) continue;
    Contact c;
    c.position = p;
    c.normal = -(q[face] >= 0 ? 1.0 : -1.0) * axes.col(face);
    c.depth = slack[face];
    found.push_back(c);
  }
  if (found.empty()) {
    collide_convex(terrain, s, aabb, box_support, box_center, scratch, found);
  }
  // At most 8, spread over the contact area by their positions alone
  // (farthest-point sampling from the point farthest from the centroid):
  // choosing by depth would swap points of nearly equal depth from step to
  // step along a resting edge, and the box would rock. The deepest point
  // joins them when it is deeper than every chosen one by more than 0.1 mm.
  constexpr std::size_t kMax = kMaxBoxContacts;
  if (found.size() <= kMax) {
    out.insert(out.end(), found.begin(), found.end());
    return;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Contact& c : found) centroid += c.position;
  centroid /= static_cast<double>(found.size());
  std::vector<double>& gap = scratch.gap;
  std::vector<bool>& taken = scratch.taken;
  gap.assign(found.size(), std::numeric_limits<double>::infinity());
  taken.assign(found.size(), false);
  double deepest_taken = 0;
  auto take = [&](std::size_t i) {
    taken[i] = true;
    deepest_taken = std::max(deepest_taken, found[i].depth);
    out.push_back(found[i]);
    for (std::size_t k = 0; k < found.size(); ++k) {
      gap[k] = std::min(gap[k], (found[k].position - found[i].position).squaredNorm());
    }
  };
  std::size_t first_pick = 0;
  for (std::size_t k = 1; k < found.size(); ++k) {
    if ((found[k].position - centroid).squaredNorm() > (found[first_pick].position - centroid).squaredNorm()) {
      first_pick = k;
    }
  }
  take(first_pick);
  for (std::size_t n = 1; n < kMax; ++n) {
    std::size_t next = found.size();
    for (std::size_t k = 0; k < found.size(); ++k) {
      if (!taken[k] && (next == found.size() || gap[k] > gap[next])) next = k;
    }
    if (n + 1 == kMax) {  // the last place: the deepest, if it is clearly deeper
      std::size_t deepest = found.size();
      for (std::size_t k = 0; k < found.size(); ++k) {
        if (!taken[k] && (deepest == found.size() || found[k].depth > found[deepest].depth)) deepest = k;
      }
      if (deepest < found.size() && found[deepest].depth > deepest_taken + 1e-4) next = deepest;
    }
    if (next == found.size()) break;
    take(next);
  }
}

}  // namespace touchdown::twin::detail
