// Visual safe flight corridor (see the header for the construction).
//
// What this file follows:
//  - obstacle subtraction: exact box algebra (a box meeting an obstacle is
//    replaced by its up-to-six slabs beside it, then boxes inside others are
//    dropped), which leaves exactly the maximal empty boxes;
//  - Chebyshev ball: the textbook LP max r s.t. a_i·c + r ≤ b_i (Boyd &
//    Vandenberghe, Convex Optimization, §8.5.1), solved exactly by vertex
//    enumeration (the optimum of a bounded LP over a pointed polyhedron is
//    attained at a vertex, where 4 independent constraints are tight);
//  - redundant faces: face i is redundant when max a_i·x over the other
//    faces is ≤ b_i (the standard LP test), again by vertex enumeration;
//  - the split / deflate / dilate / FoV / radius steps of the guidance
//    paper's Algorithm 1, as described in the header.
// The polytopes here have ~20 faces at most, so brute-force enumeration
// (C(26, 4) ≈ 15k 4×4 solves) is fast enough and has no failure modes.
#include "touchdown/plan/corridor.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::plan {
namespace {

using detail::format_general;

// Half-width of the cube (centred at the origin) that bounds every LP, so
// that unbounded polytopes still have an optimal vertex.
constexpr double kCube = 1e6;
// Feasibility tolerance of a candidate vertex (scaled by |b_i| for large offsets).
constexpr double kFeasible = 1e-9;
// A square system with |det| below this is treated as singular and skipped.
constexpr double kSingular = 1e-10;
// Chebyshev radius above which two parts are considered to overlap.
constexpr double kOverlap = 1e-6;
// Tolerance of the start/goal containment tests.
constexpr double kContain = 1e-9;

double feasible_tol(double b) { return kFeasible * std::max(1.0, std::abs(b)); }

// The rows of `p` followed by the six faces of the bounding cube.
struct Rows {
  std::vector<Eigen::Vector3d> a;
  std::vector<double> b;
};

Rows rows_with_cube(const Polytope& p) {
  Rows r;
  const int m = p.faces();
  r.a.reserve(static_cast<std::size_t>(m) + 6);
  r.b.reserve(static_cast<std::size_t>(m) + 6);
  for (int i = 0; i < m; ++i) {
    r.a.emplace_back(p.A.row(i).transpose());
    r.b.push_back(p.b(i));
  }
  for (int k = 0; k < 3; ++k) {
    for (double s : {1.0, -1.0}) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n(k) = s;
      r.a.push_back(n);
      r.b.push_back(kCube);
    }
  }
  return r;
}

void check_polytope(const Polytope& p, const char* what) {
  if (p.A.rows() != p.b.size()) {
    throw InvalidArgument(std::string(what) + ": A has " + std::to_string(p.A.rows()) + " rows but b has " +
                          std::to_string(p.b.size()));
  }
  if (!p.A.allFinite() || !p.b.allFinite()) throw InvalidArgument(std::string(what) + ": must be finite");
}

// The reason a camera is invalid ("field: what", field relative to the
// camera), or "" when it is valid.
std::string camera_problem(const CameraFov& c) {
  const double pi = std::numbers::pi;
  if (!(c.horizontal_fov_rad > 0 && c.horizontal_fov_rad < pi)) {
    return "fov_deg: horizontal field of view must be in (0, 180) deg, got " +
           format_general(rad_to_deg(c.horizontal_fov_rad)) + " deg";
  }
  if (!(c.vertical_fov_rad > 0 && c.vertical_fov_rad < pi)) {
    return "fov_deg: vertical field of view must be in (0, 180) deg, got " +
           format_general(rad_to_deg(c.vertical_fov_rad)) + " deg";
  }
  if (!(c.near_m >= 0 && std::isfinite(c.near_m) && c.far_m > c.near_m && std::isfinite(c.far_m))) {
    return "range: need 0 <= near < far (finite), got near " + format_general(c.near_m) + " m, far " +
           format_general(c.far_m) + " m";
  }
  if (!c.T_pad_camera.matrix().allFinite()) return "T_pad_camera: must be finite";
  const Eigen::Matrix3d R = c.T_pad_camera.linear();
  if (!((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6)) {
    return "T_pad_camera: rotation must be orthonormal";
  }
  return {};
}

void check_obstacles(std::span<const Box> obstacles) {
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const Box& o = obstacles[i];
    const std::string field = "obstacles[" + std::to_string(i) + "]";
    if (o.min.hasNaN() || o.max.hasNaN()) throw InvalidArgument(field + ": must not be NaN");
    if ((o.min.array() > o.max.array()).any()) throw InvalidArgument(field + ": min must not exceed max");
  }
}

// True when a and b share a part of positive volume (their interiors meet).
bool interiors_meet(const Box& a, const Box& b) {
  for (int k = 0; k < 3; ++k) {
    if (!(std::min(a.max(k), b.max(k)) > std::max(a.min(k), b.min(k)))) return false;
  }
  return true;
}

bool box_inside(const Box& inner, const Box& outer) {
  return (inner.min.array() >= outer.min.array()).all() && (inner.max.array() <= outer.max.array()).all();
}

// Strictly inside `o` grown by `r` on every side.
bool inside_grown(const Box& o, double r, const Eigen::Vector3d& p) {
  return (p.array() > o.min.array() - r).all() && (p.array() < o.max.array() + r).all();
}

Polytope part_polytope(const Box& box, const std::optional<Polytope>& fov, double radius) {
  Polytope p = Polytope::from_box(box);
  if (fov) p.intersect(*fov);
  p.shrink(radius);
  return remove_redundant_faces(p);
}

bool overlap(const Polytope& a, const Polytope& b) {
  Polytope both = a;
  both.intersect(b);
  return chebyshev_ball(both).radius > kOverlap;
}

}  // namespace

// ---------------------------------------------------------------- Box

bool Box::contains(const Eigen::Vector3d& p, double tolerance) const {
  return (p.array() >= min.array() - tolerance).all() && (p.array() <= max.array() + tolerance).all();
}

double Box::volume() const {
  const Eigen::Vector3d e = max - min;
  if (!(e.x() > 0 && e.y() > 0 && e.z() > 0)) return 0;
  return e.x() * e.y() * e.z();
}

// ---------------------------------------------------------------- Polytope

bool Polytope::contains(const Eigen::Vector3d& p, double tolerance) const {
  for (Eigen::Index i = 0; i < b.size(); ++i) {
    if (A.row(i).dot(p) > b(i) + tolerance) return false;
  }
  return true;
}

void Polytope::add(const Eigen::Vector3d& n, double d) {
  const double len = n.norm();
  if (!std::isfinite(len) || !(len > 0)) throw InvalidArgument("polytope.add: normal must be non-zero and finite");
  if (!std::isfinite(d)) throw InvalidArgument("polytope.add: offset must be finite, got " + format_general(d));
  const Eigen::Index m = b.size();
  A.conservativeResize(m + 1, Eigen::NoChange);
  b.conservativeResize(m + 1);
  A.row(m) = (n / len).transpose();
  b(m) = d / len;
}

void Polytope::intersect(const Polytope& other) {
  const Eigen::Index m = b.size();
  const Eigen::Index k = other.b.size();
  A.conservativeResize(m + k, Eigen::NoChange);
  b.conservativeResize(m + k);
  if (k > 0) {
    A.bottomRows(k) = other.A;
    b.tail(k) = other.b;
  }
}

void Polytope::shrink(double distance) { b.array() -= distance; }

Polytope Polytope::from_box(const Box& box) {
  Polytope p;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(k);
    p.add(e, box.max(k));
    p.add(-e, -box.min(k));
  }
  return p;
}

// ---------------------------------------------------------------- LPs

ChebyshevBall chebyshev_ball(const Polytope& polytope) {
  check_polytope(polytope, "chebyshev_ball: polytope");
  // LP in (c, r): max r s.t. a_i·c + r ≤ b_i, by vertex enumeration over
  // every 4-subset of the faces and the bounding cube's faces. The feasible
  // set is pointed (the cube rows have rank 4) and r is bounded above, so
  // the optimum is attained at a vertex. Every accepted vertex is feasible
  // (within kFeasible), so the result is a valid ball even if a
  // near-singular optimal vertex were skipped.
  const Rows rows = rows_with_cube(polytope);
  const int n = static_cast<int>(rows.b.size());
  double best = -std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> optimal;  // distinct optimal centres
  Eigen::Matrix4d M;
  Eigen::Vector4d rhs;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      for (int k = j + 1; k < n; ++k) {
        for (int l = k + 1; l < n; ++l) {
          const int idx[4] = {i, j, k, l};
          for (int q = 0; q < 4; ++q) {
            const auto s = static_cast<std::size_t>(idx[q]);
            M.block<1, 3>(q, 0) = rows.a[s].transpose();
            M(q, 3) = 1;
            rhs(q) = rows.b[s];
          }
          if (!(std::abs(M.determinant()) > kSingular)) continue;
          const Eigen::Vector4d x = M.partialPivLu().solve(rhs);
          const Eigen::Vector3d c = x.head<3>();
          const double r = x(3);
          if (!std::isfinite(r) || r < best - kFeasible) continue;
          bool ok = true;
          for (std::size_t t = 0; t < rows.b.size() && ok; ++t) {
            ok = rows.a[t].dot(c) + r <= rows.b[t] + feasible_tol(rows.b[t]);
          }
          if (!ok) continue;
          if (r > best + kFeasible) {
            best = r;
            optimal.clear();
          }
          bool seen = false;
          for (const auto& o : optimal) seen = seen || (o - c).norm() < 1e-7;
          if (!seen) optimal.push_back(c);
        }
      }
    }
  }
  ChebyshevBall ball;
  if (optimal.empty()) return ball;  // cannot happen (the cube alone has a vertex); radius −1
  // The optimal set can be a whole face (e.g. a long box); the mean of its
  // vertices is optimal too (convexity) and central, and is the centre for
  // symmetric shapes.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& o : optimal) c += o;
  c /= static_cast<double>(optimal.size());
  double r = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < rows.b.size(); ++t) r = std::min(r, rows.b[t] - rows.a[t].dot(c));
  ball.centre = c;
  ball.radius = r;
  return ball;
}

Polytope remove_redundant_faces(const Polytope& polytope, double tolerance) {
  check_polytope(polytope, "remove_redundant_faces: polytope");
  if (!(tolerance >= 0) || !std::isfinite(tolerance)) {
    throw InvalidArgument("remove_redundant_faces.tolerance: must be >= 0, got " + format_general(tolerance));
  }
  // An empty polytope (every face "redundant" over an empty set): as is.
  if (chebyshev_ball(polytope).radius < -tolerance) return polytope;
  const Rows rows = rows_with_cube(polytope);
  const int m = polytope.faces();
  const int n = static_cast<int>(rows.b.size());
  // Greedy, in order: face i is tested against the faces still kept, so of
  // two identical faces the second is dropped and the first kept (dropping a
  // redundant face does not change the polytope, so later tests stay valid).
  std::vector<char> kept(static_cast<std::size_t>(n), 1);
  Eigen::Matrix3d M;
  Eigen::Vector3d rhs;
  for (int f = 0; f < m; ++f) {
    const auto fs = static_cast<std::size_t>(f);
    kept[fs] = 0;
    // max a_f·x over the kept faces and the cube: vertex enumeration over 3-subsets.
    double best = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i) {
      if (!kept[static_cast<std::size_t>(i)]) continue;
      for (int j = i + 1; j < n; ++j) {
        if (!kept[static_cast<std::size_t>(j)]) continue;
        for (int k = j + 1; k < n; ++k) {
          if (!kept[static_cast<std::size_t>(k)]) continue;
          const int idx[3] = {i, j, k};
          for (int q = 0; q < 3; ++q) {
            const auto s = static_cast<std::size_t>(idx[q]);
            M.row(q) = rows.a[s].transpose();
            rhs(q) = rows.b[s];
          }
          if (!(std::abs(M.determinant()) > kSingular)) continue;
          const Eigen::Vector3d x = M.partialPivLu().solve(rhs);
          const double v = rows.a[fs].dot(x);
          if (!std::isfinite(v) || v <= best) continue;
          bool ok = true;
          for (int t = 0; t < n && ok; ++t) {
            const auto ts = static_cast<std::size_t>(t);
            if (kept[ts]) ok = rows.a[ts].dot(x) <= rows.b[ts] + feasible_tol(rows.b[ts]);
          }
          if (ok) best = v;
        }
      }
    }
    if (!(best <= polytope.b(f) + tolerance)) kept[fs] = 1;
  }
  Polytope out;
  for (int f = 0; f < m; ++f) {
    if (kept[static_cast<std::size_t>(f)]) {
      out.A.conservativeResize(out.A.rows() + 1, Eigen::NoChange);
      out.b.conservativeResize(out.b.size() + 1);
      out.A.row(out.A.rows() - 1) = polytope.A.row(f);
      out.b(out.b.size() - 1) = polytope.b(f);
    }
  }
  return out;
}

// ---------------------------------------------------------------- camera

Polytope CameraFov::pyramid() const {
  if (const std::string why = camera_problem(*this); !why.empty()) throw InvalidArgument("camera." + why);
  // Camera frame: |x| ≤ z tan(h/2), |y| ≤ z tan(v/2), near ≤ z ≤ far. A
  // camera-frame half-space n·p_c ≤ d with p_c = Rᵀ(p − t) is, in the pad
  // frame, (R n)·p ≤ d + (R n)·t.
  const double th = std::tan(horizontal_fov_rad / 2);
  const double tv = std::tan(vertical_fov_rad / 2);
  const Eigen::Matrix3d R = T_pad_camera.linear();
  const Eigen::Vector3d t = T_pad_camera.translation();
  Polytope p;
  auto add_camera = [&](const Eigen::Vector3d& n_cam, double d) {
    const Eigen::Vector3d n = R * n_cam;
    p.add(n, d + n.dot(t));
  };
  add_camera({1, 0, -th}, 0);
  add_camera({-1, 0, -th}, 0);
  add_camera({0, 1, -tv}, 0);
  add_camera({0, -1, -tv}, 0);
  add_camera({0, 0, -1}, -near_m);
  add_camera({0, 0, 1}, far_m);
  return p;
}

// ---------------------------------------------------------------- options

bool CorridorOptions::validate(std::string* why) const {
  if (!(h_touchdown > 0 && std::isfinite(h_touchdown))) {
    return invalid(why, "corridor.h_touchdown: must be > 0 and finite, got " + format_general(h_touchdown));
  }
  if (!(deflate >= 0 && std::isfinite(deflate))) {
    return invalid(why, "corridor.deflate: must be >= 0 and finite, got " + format_general(deflate));
  }
  if (!(dilate > 0 && std::isfinite(dilate))) {
    return invalid(why, "corridor.dilate: must be > 0 and finite, got " + format_general(dilate));
  }
  if (max_dilations < 1)
    return invalid(why, "corridor.max_dilations: must be >= 1, got " + std::to_string(max_dilations));
  if (!(radius >= 0 && std::isfinite(radius))) {
    return invalid(why, "corridor.radius: must be >= 0 and finite, got " + format_general(radius));
  }
  if (!(margin >= 0 && std::isfinite(margin))) {
    return invalid(why, "corridor.margin: must be >= 0 and finite, got " + format_general(margin));
  }
  if (margin < radius) {  // the free box shrunk by the radius would exclude the start and the goal
    return invalid(why,
                   "corridor.margin: must be >= corridor.radius (the free box around start and goal is shrunk by "
                   "the drone radius), got " +
                       format_general(margin) + " < " + format_general(radius));
  }
  if (camera) {
    if (const std::string w = camera_problem(*camera); !w.empty()) return invalid(why, "corridor.camera." + w);
  }
  return true;
}

std::vector<Polytope> Corridor::per_segment(int segments) const {
  if (segments < 2) throw InvalidArgument("segments: must be >= 2, got " + std::to_string(segments));
  std::vector<Polytope> out(static_cast<std::size_t>(segments - 1), rear);
  out.push_back(touchdown);
  return out;
}

// ---------------------------------------------------------------- free space

std::vector<Box> free_pieces(const Box& free_box, std::span<const Box> obstacles, int max_boxes) {
  if (max_boxes < 1) throw InvalidArgument("max_boxes: must be >= 1, got " + std::to_string(max_boxes));
  if (free_box.min.hasNaN() || free_box.max.hasNaN()) throw InvalidArgument("free_box: must not be NaN");
  check_obstacles(obstacles);
  // Exact box algebra: each box meeting an obstacle (positive-volume
  // intersection) is replaced by its slabs on the six sides of the obstacle,
  // then boxes inside others are dropped; the result is every maximal empty box.
  std::vector<Box> boxes;
  if (free_box.volume() > 0) boxes.push_back(free_box);
  std::vector<Box> next;
  for (const Box& o : obstacles) {
    next.clear();
    for (const Box& b : boxes) {
      if (!interiors_meet(b, o)) {
        next.push_back(b);
        continue;
      }
      for (int k = 0; k < 3; ++k) {
        Box below = b;
        below.max(k) = std::min(b.max(k), o.min(k));
        if (below.volume() > 0) next.push_back(below);
        Box above = b;
        above.min(k) = std::max(b.min(k), o.max(k));
        if (above.volume() > 0) next.push_back(above);
      }
    }
    // Drop boxes inside another (of identical boxes, keep the first).
    boxes.clear();
    for (std::size_t i = 0; i < next.size(); ++i) {
      bool dominated = false;
      for (std::size_t j = 0; j < next.size() && !dominated; ++j) {
        if (i == j || !box_inside(next[i], next[j])) continue;
        // Identical boxes: keep the one with the lower index.
        dominated = !box_inside(next[j], next[i]) || j < i;
      }
      if (!dominated) boxes.push_back(next[i]);
    }
    if (boxes.size() > static_cast<std::size_t>(max_boxes)) {
      throw InvalidArgument("free_pieces: more than max_boxes = " + std::to_string(max_boxes) + " free boxes");
    }
  }
  return boxes;
}

// ---------------------------------------------------------------- corridor

Corridor build_corridor(const Eigen::Vector3d& start, const Eigen::Vector3d& goal, std::span<const Box> obstacles,
                        const CorridorOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!start.allFinite()) throw InvalidArgument("start: must be finite");
  if (!goal.allFinite()) throw InvalidArgument("goal: must be finite");
  check_obstacles(obstacles);
  const double r = options.radius;
  const double hT = options.h_touchdown;

  Corridor out;
  auto fail = [&](CorridorStatus status, std::string message) {
    out.status = status;
    out.message = std::move(message);
    return out;
  };

  // 1. Free box: bounding box of start and goal grown by the margin, never below the pad plane.
  out.free_box.min = start.cwiseMin(goal).array() - options.margin;
  out.free_box.max = start.cwiseMax(goal).array() + options.margin;
  out.free_box.min.z() = 0;

  // 2. Blocked start/goal: below the pad plane plus the radius, inside an
  //    obstacle grown by the radius, or outside the FoV shrunk by the radius.
  std::optional<Polytope> fov;
  std::optional<Polytope> fov_shrunk;
  if (options.camera) {
    fov = options.camera->pyramid();
    fov_shrunk = *fov;
    fov_shrunk->shrink(r);
  }
  auto blocked = [&](const Eigen::Vector3d& p, const char* name) -> std::string {
    if (p.z() <= r) return std::string(name) + " is below the pad plane plus the drone radius";
    for (std::size_t i = 0; i < obstacles.size(); ++i) {
      if (inside_grown(obstacles[i], r, p)) {
        return std::string(name) + " is inside obstacles[" + std::to_string(i) + "] grown by the drone radius";
      }
    }
    if (fov_shrunk && !fov_shrunk->contains(p, kContain)) {
      return std::string(name) + " is outside the camera's field of view (shrunk by the drone radius)";
    }
    return {};
  };
  if (std::string w = blocked(start, "start"); !w.empty()) return fail(CorridorStatus::StartBlocked, std::move(w));
  if (std::string w = blocked(goal, "goal"); !w.empty()) return fail(CorridorStatus::GoalBlocked, std::move(w));

  // 3. Free pieces, those containing the start (rear candidates) and the goal (touchdown candidates).
  const std::vector<Box> pieces = free_pieces(out.free_box, obstacles);
  std::vector<Box> rear_pieces;
  std::vector<Box> touch_pieces;
  for (const Box& p : pieces) {
    if (p.contains(start, kContain)) rear_pieces.push_back(p);
    if (p.contains(goal, kContain)) touch_pieces.push_back(p);
  }
  if (rear_pieces.empty()) return fail(CorridorStatus::NoConnection, "no free piece contains the start");
  if (touch_pieces.empty()) return fail(CorridorStatus::NoConnection, "no free piece contains the goal");

  // canLand: a pair joins start and goal when the whole pieces (with the FoV,
  // shrunk by the radius) contain the start resp. the goal and overlap. The
  // dilated parts are subsets of their pieces, so no other pair can ever work.
  struct Pair {
    const Box* rear;
    const Box* touch;
  };
  std::vector<Pair> pairs;
  for (const Box& bs : rear_pieces) {
    const Polytope ps = part_polytope(bs, fov, r);
    if (!ps.contains(start, kContain)) continue;
    for (const Box& bg : touch_pieces) {
      const Polytope pg = part_polytope(bg, fov, r);
      if (!pg.contains(goal, kContain)) continue;
      if (overlap(ps, pg)) pairs.push_back({&bs, &bg});
    }
  }
  if (pairs.empty()) {
    return fail(CorridorStatus::NoConnection,
                "no pair of free pieces containing the start and the goal (with the drone radius) overlaps");
  }

  // 4. Split at h_T, deflate, dilate k = 1, 2, ... steps; the first k with a
  //    connecting pair wins, of those the pair with the largest boxes.
  for (int k = 1; k <= options.max_dilations; ++k) {
    const double dz = static_cast<double>(k) * options.dilate;
    double best_volume = -1;
    for (const Pair& pr : pairs) {
      const Box& bs = *pr.rear;
      const Box& bg = *pr.touch;
      // Rear: z ≥ h_T − k ε_d, but low enough to hold the start with its
      // radius (the approach may start below the split), within the piece.
      Box rb = bs;
      rb.min.z() = std::max(bs.min.z(), std::min(hT - dz, start.z() - r));
      // Touchdown: z ≤ h_T + k ε_d, but high enough to hold the goal with
      // its radius (the goal is usually at h_T, on the split plane), within
      // the piece; x/y faces move inward by `deflate`, never past the pad
      // centre and never so far that the goal (with its radius) leaves.
      Box tb = bg;
      tb.max.z() = std::min(bg.max.z(), std::max(hT + dz, goal.z() + r));
      for (int a = 0; a < 2; ++a) {
        tb.min(a) = std::max(bg.min(a), std::min({bg.min(a) + options.deflate, 0.0, goal(a) - r}));
        tb.max(a) = std::min(bg.max(a), std::max({bg.max(a) - options.deflate, 0.0, goal(a) + r}));
      }
      const double volume = rb.volume() + tb.volume();
      if (!(volume > best_volume)) continue;
      Polytope rear = part_polytope(rb, fov, r);
      if (!rear.contains(start, kContain)) continue;
      Polytope touch = part_polytope(tb, fov, r);
      if (!touch.contains(goal, kContain)) continue;
      if (!overlap(rear, touch)) continue;
      best_volume = volume;
      out.rear = std::move(rear);
      out.touchdown = std::move(touch);
      out.rear_piece = bs;
      out.touchdown_piece = bg;
    }
    if (best_volume >= 0) {
      out.dilations = k;
      out.status = CorridorStatus::Ok;
      out.message.clear();
      return out;
    }
  }
  return fail(CorridorStatus::NoOverlap, "the rear and touchdown parts do not overlap after " +
                                             std::to_string(options.max_dilations) + " dilations of " +
                                             format_general(options.dilate) + " m");
}

}  // namespace touchdown::plan
