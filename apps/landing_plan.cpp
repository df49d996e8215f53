// landing_plan: the minimum-jerk landing trajectory onto a moving pad inside
// the visual safe flight corridor, from a problem file (docs/formats.md,
// "Landing problem"); a summary or one JSON object, and optionally the QP,
// an SVG of the plan and the sampled trajectory.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app_common.hpp"
#include "touchdown/core/xml.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"

namespace {

namespace td = touchdown;
namespace tp = touchdown::plan;
namespace fs = std::filesystem;
// Keys in the order documented (docs/cli.md), not sorted.
using Json = nlohmann::ordered_json;
using td::app::fixed;
using td::app::round3;

constexpr int kExitNotOk = 1;  // infeasible or no corridor: a result, but no trajectory to fly
// --samples: one ~220-byte row per millisecond, built in memory before it is
// written; a trajectory of 16 segments of up to 1000 s would take ~3.5 GB.
constexpr double kMaxSampledSeconds = 1000;
constexpr double kCsvBytesPerRow = 220;

Json matrix_json(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(std::move(row));
  }
  return rows;
}

Json vector_json(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

Json groups_json(const std::vector<tp::ConstraintGroup>& groups) {
  Json out = Json::array();
  for (const auto g : groups) out.push_back(tp::to_string(g));
  return out;
}

Json result_json(const tp::PlanResult& r, int order, double seconds) {
  Json j;
  j["status"] = tp::to_string(r.status);
  j["cost"] = r.cost;
  j["objective"] = r.objective;
  j["order"] = order;
  Json segments = Json::array();
  if (r.ok()) {
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      Json cps = Json::array();
      for (const auto& c : r.trajectory.control_points(k)) cps.push_back({c.x(), c.y(), c.z()});
      segments.push_back({{"duration", r.trajectory.duration(k)}, {"control_points", std::move(cps)}});
    }
  }
  j["segments"] = std::move(segments);
  Json corridor = Json::array();
  for (const auto& p : r.segment_polytopes) corridor.push_back({{"A", matrix_json(p.A)}, {"b", vector_json(p.b)}});
  j["corridor"] = std::move(corridor);
  j["time_allocation"] = {{"evaluations", r.evaluations}, {"ms", round3(r.allocation_ms)}};
  j["qp"] = {{"iterations", r.qp_iterations}, {"us", round3(r.qp_us)}};
  j["seconds"] = std::round(seconds * 1e6) / 1e6;
  if (r.status == tp::PlanStatus::Infeasible) j["conflicts"] = groups_json(r.conflicts);
  if (!r.ok()) j["message"] = r.message;
  return j;
}

std::string qp_json(const tp::QpProblem& qp) {
  Json j;
  j["P"] = matrix_json(qp.P);
  j["q"] = vector_json(qp.q);
  j["A_eq"] = matrix_json(qp.A_eq);
  j["b_eq"] = vector_json(qp.b_eq);
  j["A_in"] = matrix_json(qp.A_in);
  j["b_in"] = vector_json(qp.b_in);
  j["constant"] = qp.constant;
  j["variables"] = qp.variable_names();
  j["eq_groups"] = groups_json(qp.eq_groups);
  j["in_groups"] = groups_json(qp.in_groups);
  return j.dump() + "\n";
}

// Rows every 1 ms from t = 0 to the last whole millisecond of the trajectory.
std::string samples_csv(const tp::PiecewiseBezier& curve, const tp::PadMotion& pad) {
  std::string out = "t,px,py,pz,vx,vy,vz,ax,ay,az,world_vx,world_vy,world_vz,world_ax,world_ay,world_az\n";
  const auto n = static_cast<long>(std::floor(curve.total_duration() * 1000 + 1e-6));
  char buf[512];
  for (long i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / 1000;
    tp::KinematicState s;
    s.p = curve.evaluate(t, 0);
    s.v = curve.evaluate(t, 1);
    s.a = curve.evaluate(t, 2);
    const tp::KinematicState w = pad.to_world(t, s);
    std::snprintf(buf, sizeof(buf), "%.3f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                  t, s.p.x(), s.p.y(), s.p.z(), s.v.x(), s.v.y(), s.v.z(), s.a.x(), s.a.y(), s.a.z(), w.v.x(), w.v.y(),
                  w.v.z(), w.a.x(), w.a.y(), w.a.z());
    out += buf;
  }
  return out;
}

// ------------------------------------------------------------------ plot

// The vertices of a bounded H-polytope: every intersection of three of its
// planes that lies inside all faces (a polytope here has ~20 faces).
std::vector<Eigen::Vector3d> polytope_vertices(const tp::Polytope& p) {
  std::vector<Eigen::Vector3d> out;
  const int m = p.faces();
  for (int i = 0; i < m; ++i) {
    for (int j = i + 1; j < m; ++j) {
      for (int k = j + 1; k < m; ++k) {
        Eigen::Matrix3d A;
        A << p.A.row(i), p.A.row(j), p.A.row(k);
        if (std::abs(A.determinant()) < 1e-9) continue;
        const Eigen::Vector3d v = A.partialPivLu().solve(Eigen::Vector3d(p.b(i), p.b(j), p.b(k)));
        if (!v.allFinite() || ((p.A * v - p.b).array() > 1e-7 * std::max(1.0, v.norm())).any()) continue;
        if (std::none_of(out.begin(), out.end(), [&](const Eigen::Vector3d& u) { return (u - v).norm() < 1e-9; })) {
          out.push_back(v);
        }
      }
    }
  }
  return out;
}

// Andrew's monotone chain: the convex hull, counter-clockwise.
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (pts.size() < 3) return pts;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 1e-12) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 1e-12) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

// A "nice" tick step (1, 2 or 5 × 10^k) giving about `count` ticks over `span`.
double tick_step(double span, int count) {
  const double raw = span / count;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0}) {
    if (f * mag >= raw) return f * mag;
  }
  return 10 * mag;
}

std::string tick_label(double v, double step) {
  const int digits = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  return fixed(std::abs(v) < step * 1e-6 ? 0.0 : v, digits);
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  [[nodiscard]] double span() const { return hi - lo; }
  // Grows the range about its centre to at least `span`.
  void widen_to(double s) {
    if (span() >= s) return;
    const double c = (lo + hi) / 2;
    lo = c - s / 2;
    hi = c + s / 2;
  }
};

// One 2-D panel: maps data (u, v) to pixels; `flip_u` draws u decreasing to the right.
struct Panel {
  double x0, y0, w, h;  // pixels
  Range u, v;
  bool flip_u = false;
  [[nodiscard]] double px(double a) const {
    const double f = (a - u.lo) / u.span();
    return x0 + w * (flip_u ? 1 - f : f);
  }
  [[nodiscard]] double py(double b) const { return y0 + h - h * (b - v.lo) / v.span(); }
};

const char* kAxisColour[3] = {"#d62728", "#2ca02c", "#1f77b4"};  // x, y, z
constexpr const char* kTrajectory = "#1f3f9f";
constexpr const char* kRear = "#ff7f0e";
constexpr const char* kTouchdown = "#2ca02c";
constexpr const char* kFov = "#9467bd";
constexpr const char* kObstacle = "#6b6b6b";

class Svg {
 public:
  Svg() { os_ << std::fixed << std::setprecision(1); }
  std::ostringstream& os() { return os_; }
  void text(double x, double y, const std::string& s, const char* anchor = "middle", const char* extra = "") {
    os_ << "<text x='" << x << "' y='" << y << "' text-anchor='" << anchor << "'" << extra << ">" << s << "</text>\n";
  }
  void line(double x1, double y1, double x2, double y2, const char* style) {
    os_ << "<line x1='" << x1 << "' y1='" << y1 << "' x2='" << x2 << "' y2='" << y2 << "' " << style << "/>\n";
  }
  void polygon(const std::vector<Eigen::Vector2d>& pts, const char* style) {
    if (pts.size() < 3) return;
    os_ << "<polygon points='";
    for (const auto& p : pts) os_ << p.x() << "," << p.y() << " ";
    os_ << "' " << style << "/>\n";
  }
  void polyline(const std::vector<Eigen::Vector2d>& pts, const char* style) {
    os_ << "<polyline fill='none' points='";
    for (const auto& p : pts) os_ << p.x() << "," << p.y() << " ";
    os_ << "' " << style << "/>\n";
  }

 private:
  std::ostringstream os_;
};

// Frame, ticks, tick labels and axis names of a panel.
void draw_axes(Svg& svg, const Panel& p, const std::string& u_name, const std::string& v_name, int clip_id) {
  auto& os = svg.os();
  os << "<rect x='" << p.x0 << "' y='" << p.y0 << "' width='" << p.w << "' height='" << p.h
     << "' fill='none' stroke='black'/>\n";
  const double su = tick_step(p.u.span(), std::max(2, static_cast<int>(p.w / 70)));
  for (double t = std::ceil(p.u.lo / su) * su; t <= p.u.hi + 1e-9 * su; t += su) {
    const double x = p.px(t);
    svg.line(x, p.y0 + p.h, x, p.y0 + p.h + 4, "stroke='black'");
    svg.line(x, p.y0, x, p.y0 + p.h, "stroke='#e4e4e4'");
    svg.text(x, p.y0 + p.h + 16, tick_label(t, su));
  }
  const double sv = tick_step(p.v.span(), std::max(2, static_cast<int>(p.h / 45)));
  for (double t = std::ceil(p.v.lo / sv) * sv; t <= p.v.hi + 1e-9 * sv; t += sv) {
    const double y = p.py(t);
    svg.line(p.x0 - 4, y, p.x0, y, "stroke='black'");
    svg.line(p.x0, y, p.x0 + p.w, y, "stroke='#e4e4e4'");
    svg.text(p.x0 - 6, y + 4, tick_label(t, sv), "end");
  }
  svg.text(p.x0 + p.w / 2, p.y0 + p.h + 32, u_name);
  std::ostringstream rot;
  rot << std::fixed << std::setprecision(1) << " transform='rotate(-90 " << p.x0 - 38 << "," << p.y0 + p.h / 2 << ")'";
  svg.text(p.x0 - 38, p.y0 + p.h / 2, v_name, "middle", rot.str().c_str());
  os << "<clipPath id='clip" << clip_id << "'><rect x='" << p.x0 << "' y='" << p.y0 << "' width='" << p.w
     << "' height='" << p.h << "'/></clipPath>\n";
}

struct PlotInput {
  std::string title;
  const tp::PlanProblem* problem;
  const tp::PlanResult* result;
  tp::KinematicState goal;
};

std::string plot_svg(const PlotInput& in) {
  const tp::PlanProblem& pb = *in.problem;
  const tp::PlanResult& r = *in.result;
  const auto& o = pb.options;
  const bool have_curve = r.ok();

  // Geometry in the pad frame.
  std::vector<Eigen::Vector3d> curve;
  if (have_curve) {
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      for (int i = 0; i <= 200; ++i) curve.push_back(r.trajectory.evaluate_segment(k, i / 200.0));
    }
  }
  struct Shape {
    std::vector<Eigen::Vector3d> vertices;
    const char* colour;
    const char* style;
    bool field_of_view = false;
  };
  std::vector<Shape> shapes;  // drawn in this order
  std::optional<Eigen::Vector3d> camera_at;
  if (o.corridor && o.corridor->camera) {
    shapes.push_back({polytope_vertices(o.corridor->camera->pyramid()), kFov,
                      "fill-opacity='0.07' stroke-dasharray='5,3' stroke-width='1'", true});
    camera_at = o.corridor->camera->T_pad_camera.translation();
  }
  for (const auto& b : o.obstacles) {
    shapes.push_back({polytope_vertices(tp::Polytope::from_box(b)), kObstacle, "fill-opacity='0.55' stroke-width='1'"});
  }
  if (r.corridor.ok()) {
    shapes.push_back({polytope_vertices(r.corridor.rear), kRear, "fill-opacity='0.18' stroke-width='1.5'"});
    shapes.push_back({polytope_vertices(r.corridor.touchdown), kTouchdown, "fill-opacity='0.18' stroke-width='1.5'"});
  }
  constexpr double kPadHalf = 0.3;  // drawn pad: a 0.6 m square

  // Extent: everything but the field of view (which reaches far_m away; it is clipped).
  std::array<Range, 3> ext;
  auto add = [&](const Eigen::Vector3d& p) {
    for (int a = 0; a < 3; ++a) ext[static_cast<std::size_t>(a)].add(p(a));
  };
  add(pb.start.p);
  add(in.goal.p);
  add(Eigen::Vector3d(kPadHalf, kPadHalf, 0));
  add(Eigen::Vector3d(-kPadHalf, -kPadHalf, 0));
  for (const auto& p : curve) add(p);
  if (have_curve) {
    for (const auto& c : r.trajectory.all_control_points()) add(c);
  }
  for (const Shape& s : shapes) {
    if (s.field_of_view) continue;
    for (const auto& v : s.vertices) add(v);
  }
  if (camera_at) add(*camera_at);
  for (auto& e : ext) {
    const double pad = std::max(0.1 * e.span(), 0.2);
    e.lo -= pad;
    e.hi += pad;
    e.widen_to(1.0);
  }

  // Layout: three views side by side on one scale (pixels per metre).
  const double W = 1240, margin_l = 64, gap = 70, view_top = 70, max_view_h = 330;
  const double avail = W - margin_l - 2 * gap - 20;
  const double sx = ext[0].span(), sy = ext[1].span(), sz = ext[2].span();
  double scale = std::min(avail / (2 * sx + sy), max_view_h / std::max(sy, sz));
  // The rear view (y) is at least 160 px wide.
  if (sy * scale < 160) {
    ext[1].widen_to(160 / scale);
  }
  scale = std::min(avail / (2 * sx + ext[1].span()), max_view_h / std::max(ext[1].span(), sz));
  const double view_h = std::max(ext[1].span(), sz) * scale;
  Panel top{margin_l, view_top, sx * scale, view_h, ext[0], ext[1]};
  top.v.widen_to(view_h / scale);
  Panel side{top.x0 + top.w + gap, view_top, sx * scale, view_h, ext[0], ext[2]};
  side.v.widen_to(view_h / scale);
  Panel back{side.x0 + side.w + gap, view_top, ext[1].span() * scale, view_h, ext[1], ext[2], true};
  back.v.widen_to(view_h / scale);
  struct View {
    const Panel* panel;
    int a, b;  // data axes on u, v
    const char* name;
    const char* u_name;
    const char* v_name;
  };
  const std::array<View, 3> views = {View{&top, 0, 1, "top view (x-y)", "x [m] (forward)", "y [m] (left)"},
                                     View{&side, 0, 2, "side view (x-z)", "x [m] (forward)", "z [m] (up)"},
                                     View{&back, 1, 2, "rear view (y-z)", "\u2190 y [m] (left)", "z [m] (up)"}};

  const double time_top = view_top + view_h + 110, time_h = 230;
  const double legend_y = time_top + time_h + 70;
  const double H = legend_y + 60;
  Svg svg;
  auto& os = svg.os();
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H
     << "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
  svg.text(W / 2, 24, in.title, "middle", " font-size='16' font-weight='bold'");
  std::string sub = "pad frame (x forward, y left, z up; origin at the pad centre)";
  if (pb.pad.velocity.norm() > 0 || pb.pad.yaw_rate != 0) {
    sub += "; pad moving at " + fixed(pb.pad.velocity.norm(), 2) + " m/s, yaw rate " + fixed(pb.pad.yaw_rate, 3) +
           " rad/s";
  }
  svg.text(W / 2, 44, sub, "middle", " fill='#444'");

  int clip_id = 0;
  for (const View& view : views) {
    const Panel& p = *view.panel;
    svg.text(p.x0 + p.w / 2, p.y0 - 8, view.name, "middle", " font-weight='bold'");
    draw_axes(svg, p, view.u_name, view.v_name, clip_id);
    os << "<g clip-path='url(#clip" << clip_id << ")'>\n";
    ++clip_id;
    auto to_px = [&](const Eigen::Vector3d& q) { return Eigen::Vector2d(p.px(q(view.a)), p.py(q(view.b))); };
    for (const Shape& s : shapes) {
      std::vector<Eigen::Vector2d> pts;
      for (const auto& v : s.vertices) pts.push_back(to_px(v));
      const std::string style = std::string("fill='") + s.colour + "' stroke='" + s.colour + "' " + s.style;
      svg.polygon(convex_hull(pts), style.c_str());
    }
    // The pad: a square seen from above, a thick line from the side and the rear.
    if (view.b == 1) {
      svg.polygon({to_px({-kPadHalf, -kPadHalf, 0}), to_px({kPadHalf, -kPadHalf, 0}), to_px({kPadHalf, kPadHalf, 0}),
                   to_px({-kPadHalf, kPadHalf, 0})},
                  "fill='none' stroke='#222' stroke-width='2.5'");
    } else {
      const Eigen::Vector3d a = view.a == 0 ? Eigen::Vector3d(-kPadHalf, 0, 0) : Eigen::Vector3d(0, -kPadHalf, 0);
      const Eigen::Vector2d p0 = to_px(a), p1 = to_px(-a);
      svg.line(p0.x(), p0.y(), p1.x(), p1.y(), "stroke='#222' stroke-width='5'");
    }
    if (camera_at) {
      const Eigen::Vector2d c = to_px(*camera_at);
      os << "<rect x='" << c.x() - 4 << "' y='" << c.y() - 4 << "' width='8' height='8' fill='" << kFov << "'/>\n";
    }
    if (have_curve) {
      std::vector<Eigen::Vector2d> pts;
      for (const auto& q : curve) pts.push_back(to_px(q));
      svg.polyline(pts, (std::string("stroke='") + kTrajectory + "' stroke-width='2.2'").c_str());
      for (const auto& c : r.trajectory.all_control_points()) {
        const Eigen::Vector2d q = to_px(c);
        os << "<circle cx='" << q.x() << "' cy='" << q.y() << "' r='2.8' fill='white' stroke='" << kTrajectory
           << "' stroke-width='1.2'/>\n";
      }
    }
    const Eigen::Vector2d s = to_px(pb.start.p), g = to_px(in.goal.p);
    os << "<circle cx='" << s.x() << "' cy='" << s.y() << "' r='6' fill='#17a317' stroke='black'/>\n";
    os << "<path d='M" << g.x() - 6 << "," << g.y() << " L" << g.x() << "," << g.y() - 6 << " L" << g.x() + 6 << ","
       << g.y() << " L" << g.x() << "," << g.y() + 6 << " Z' fill='#d62728' stroke='black'/>\n";
    os << "</g>\n";
  }

  // Time plots: world-frame velocity and acceleration against the limits.
  const double tw = (W - margin_l - gap - 20) / 2;
  for (int j = 1; j <= 2; ++j) {
    Panel p{margin_l + (j - 1) * (tw + gap), time_top, tw, time_h, {}, {}};
    const double limit = j == 1 ? o.v_max : o.a_max;
    double T = have_curve ? r.trajectory.total_duration() : 0.0;
    for (const double d : o.durations) T += have_curve ? 0.0 : d;
    if (!(T > 0)) T = 1.0;
    p.u.add(0);
    p.u.add(T);
    std::vector<std::array<double, 4>> samples;  // t, x, y, z
    double peak = limit;
    if (have_curve) {
      const int n = 600;
      for (int i = 0; i <= n; ++i) {
        const double t = T * i / n;
        tp::KinematicState rel{r.trajectory.evaluate(t, 0), r.trajectory.evaluate(t, 1), r.trajectory.evaluate(t, 2)};
        const tp::KinematicState w = pb.pad.to_world(t, rel);
        const Eigen::Vector3d q = j == 1 ? w.v : w.a;
        samples.push_back({t, q.x(), q.y(), q.z()});
        peak = std::max(peak, q.cwiseAbs().maxCoeff());
      }
    }
    p.v.add(-1.15 * peak);
    p.v.add(1.15 * peak);
    const char* title = j == 1 ? "world-frame velocity" : "world-frame acceleration";
    svg.text(p.x0 + p.w / 2, p.y0 - 8, title, "middle", " font-weight='bold'");
    draw_axes(svg, p, "t [s]", j == 1 ? "v [m/s]" : "a [m/s\u00b2]", clip_id);
    os << "<g clip-path='url(#clip" << clip_id << ")'>\n";
    ++clip_id;
    svg.line(p.x0, p.py(0), p.x0 + p.w, p.py(0), "stroke='#999'");
    for (double sgn : {1.0, -1.0}) {
      svg.line(p.x0, p.py(sgn * limit), p.x0 + p.w, p.py(sgn * limit),
               "stroke='black' stroke-dasharray='7,4' stroke-width='1.3'");
    }
    if (have_curve) {
      for (int k = 1; k < r.trajectory.segments(); ++k) {
        const double x = p.px(r.trajectory.start_time(k));
        svg.line(x, p.y0, x, p.y0 + p.h, "stroke='#777' stroke-dasharray='2,3'");
      }
      for (int a = 0; a < 3; ++a) {
        std::vector<Eigen::Vector2d> pts;
        for (const auto& s : samples) pts.push_back({p.px(s[0]), p.py(s[static_cast<std::size_t>(a + 1)])});
        svg.polyline(pts, (std::string("stroke='") + kAxisColour[a] + "' stroke-width='1.8'").c_str());
      }
    } else {
      svg.text(p.x0 + p.w / 2, p.y0 + p.h / 2 - 10, "no trajectory (" + std::string(tp::to_string(r.status)) + ")",
               "middle", " fill='#a00' font-size='14'");
    }
    os << "</g>\n";
    svg.text(p.x0 + p.w - 4, p.py(limit) - 4, (j == 1 ? "\u00b1v_max = " : "\u00b1a_max = ") + fixed(limit, 2), "end");
  }

  // Legend.
  double lx = margin_l;
  auto swatch = [&](const std::string& shape, const std::string& label) {
    os << "<g transform='translate(" << lx << "," << legend_y << ")'>" << shape << "</g>\n";
    svg.text(lx + 26, legend_y + 4, label, "start");
    lx += 34 + 7.0 * static_cast<double>(label.size());
  };
  if (have_curve) {
    swatch(std::string("<line x1='0' y1='0' x2='20' y2='0' stroke='") + kTrajectory + "' stroke-width='2.2'/>",
           "trajectory");
    swatch(std::string("<circle cx='10' cy='0' r='2.8' fill='white' stroke='") + kTrajectory + "'/>", "control points");
  }
  swatch("<circle cx='10' cy='0' r='6' fill='#17a317' stroke='black'/>", "start");
  swatch("<path d='M4,0 L10,-6 L16,0 L10,6 Z' fill='#d62728' stroke='black'/>", "goal");
  const std::string box = "<rect x='0' y='-7' width='20' height='14' fill='";
  if (r.corridor.ok()) {
    swatch(box + kRear + "' fill-opacity='0.3' stroke='" + kRear + "'/>", "rear corridor");
    swatch(box + kTouchdown + "' fill-opacity='0.3' stroke='" + kTouchdown + "'/>", "touchdown corridor");
  }
  if (!o.obstacles.empty()) swatch(box + kObstacle + "' fill-opacity='0.55'/>", "obstacle");
  if (camera_at) {
    swatch(box + kFov + "' fill-opacity='0.12' stroke='" + kFov + "' stroke-dasharray='5,3'/><rect x='6' y='-4' " +
               "width='8' height='8' fill='" + kFov + "'/>",
           "camera + field of view");
  }
  swatch("<rect x='0' y='-5' width='20' height='10' fill='none' stroke='#222' stroke-width='2.5'/>", "pad");
  lx = margin_l;
  const double y2 = legend_y + 24;
  for (int a = 0; a < 3; ++a) {
    os << "<line x1='" << lx << "' y1='" << y2 << "' x2='" << lx + 20 << "' y2='" << y2 << "' stroke='"
       << kAxisColour[a] << "' stroke-width='1.8'/>\n";
    svg.text(lx + 26, y2 + 4, std::string("world ") + "xyz"[a], "start");
    lx += 90;
  }
  svg.line(lx, y2, lx + 20, y2, "stroke='black' stroke-dasharray='7,4' stroke-width='1.3'");
  svg.text(lx + 26, y2 + 4, "per-axis limit", "start");
  lx += 130;
  svg.line(lx, y2, lx + 20, y2, "stroke='#777' stroke-dasharray='2,3'");
  svg.text(lx + 26, y2 + 4, "segment boundary", "start");
  os << "</svg>\n";
  return os.str();
}

std::string summary(const std::string& path, const tp::PlanProblem& pb, const tp::PlanResult& r, double seconds) {
  std::ostringstream os;
  os << "landing_plan: " << path << ": " << tp::to_string(r.status) << "\n";
  if (r.ok()) {
    double sum = 0;
    std::string parts;
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      sum += r.trajectory.duration(k);
      parts += (k ? " + " : "") + fixed(r.trajectory.duration(k), 3);
    }
    os << "  cost          " << fixed(r.cost, 4) << " m^2/s^5 (integral of squared jerk); objective "
       << fixed(r.objective, 4) << " = cost + rho * sum T\n"
       << "  durations     " << parts << " = " << fixed(sum, 3) << " s (" << r.trajectory.segments()
       << " segments of order " << r.trajectory.order() << ")\n";
  } else if (!r.message.empty()) {
    os << "  message       " << r.message << "\n";
  }
  if (r.status == tp::PlanStatus::Infeasible) {
    std::string names;
    for (const auto g : r.conflicts) names += (names.empty() ? "" : ", ") + std::string(tp::to_string(g));
    os << "  conflicts     " << (names.empty() ? "none alone (no single group restores feasibility)" : names)
       << (names.empty() ? "" : " (feasible without it)") << "\n";
  }
  if (pb.options.corridor) {
    if (r.corridor.ok()) {
      os << "  corridor      rear " << r.corridor.rear.faces() << " faces, touchdown " << r.corridor.touchdown.faces()
         << " faces, " << r.corridor.dilations << " dilation" << (r.corridor.dilations == 1 ? "" : "s") << "\n";
    } else {
      os << "  corridor      " << tp::to_string(r.corridor.status) << "\n";
    }
  }
  if (r.status != tp::PlanStatus::NoCorridor) {  // else nothing was solved
    if (pb.options.durations.empty()) {
      os << "  time alloc    " << r.evaluations << " QPs in " << fixed(r.allocation_ms, 2) << " ms\n";
    } else {
      os << "  time alloc    off (fixed durations)\n";
    }
    os << "  final QP      " << r.qp_iterations << " iterations in " << fixed(r.qp_us, 1) << " us (cold start)\n";
  }
  os << "  total         " << fixed(seconds * 1000, 2) << " ms\n";
  return os.str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Plan a minimum-jerk landing onto a moving pad inside the visual safe flight corridor, from a problem YAML "
      "(docs/formats.md). Exit 0: planned; 1: infeasible or no corridor (the report still prints); 2: bad input.",
      "landing_plan"};
  std::string problem_path, qp_path, plot_path, samples_path;
  bool json = false;
  app.add_option("PROBLEM", problem_path, "landing problem YAML (data/plans/landing.yaml is an example)")->required();
  app.add_flag("--json", json, "print one JSON object on stdout instead of the summary");
  app.add_option("--export-qp", qp_path,
                 "write the QP at the chosen durations as JSON (P, q, A_eq, b_eq, A_in, b_in, constant, variables)")
      ->check(td::app::output_extension(".json"));
  app.add_option("--plot", plot_path,
                 "write an SVG: top/side/rear views with the corridor, obstacles and field of view, and the "
                 "world-frame velocity and acceleration against the limits")
      ->check(td::app::output_extension(".svg"));
  app.add_option("--samples", samples_path,
                 "write the trajectory every 1 ms as CSV (pad-frame position, velocity, acceleration; world-frame "
                 "velocity and acceleration); only when planned, for a trajectory of at most 1000 s")
      ->check(td::app::output_extension(".csv"));
  // PROBLEM's counts and sizes have their ranges in the file format
  // (docs/formats.md): order 5..20, segments 1..16, durations and time.min,
  // time.max in [0.001, 1000] s, time.max_evaluations 1..100000,
  // corridor.max_dilations 1..100.

  return td::app::run(app, argc, argv, [&]() -> int {
    tp::PlanProblem problem = tp::load_plan_problem(problem_path);
    problem.options.export_qp = !qp_path.empty();
    const auto t0 = std::chrono::steady_clock::now();
    tp::PlanResult r;
    try {
      r = tp::plan(problem.start, problem.goal, problem.pad, problem.options);
    } catch (const td::InvalidArgument& e) {
      // A start or goal outside the corridor: the file's values are at fault.
      throw td::InvalidArgument(problem_path + ": " + e.what());
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // Every output is rendered first, and their directories checked, so that
    // a bad path leaves no file behind.
    std::vector<std::pair<std::string, std::string>> outputs;
    if (!qp_path.empty() && r.status != tp::PlanStatus::NoCorridor) outputs.emplace_back(qp_path, qp_json(r.qp));
    if (!plot_path.empty()) {
      std::string title =
          "landing_plan: " + fs::path(problem_path).filename().string() + ": " + std::string(tp::to_string(r.status));
      if (r.status == tp::PlanStatus::Infeasible && !r.conflicts.empty()) {
        title += " (feasible without:";
        for (const auto g : r.conflicts) title += " " + std::string(tp::to_string(g));
        title += ")";
      }
      if (r.ok()) {
        title +=
            ", cost " + fixed(r.cost, 3) + " m\u00b2/s\u2075, T = " + fixed(r.trajectory.total_duration(), 2) + " s";
      }
      const PlotInput in{td::xml_escape(title), &problem, &r,
                         problem.goal ? *problem.goal : tp::default_goal(problem.options)};
      outputs.emplace_back(plot_path, plot_svg(in));
    }
    if (!samples_path.empty() && r.ok()) {
      // Refused before the rows are built, with what they would take.
      if (const double T = r.trajectory.total_duration(); T > kMaxSampledSeconds) {
        const double rows = std::floor(T * 1000) + 1;
        throw td::InvalidArgument("--samples: the trajectory lasts " + fixed(T, 1) +
                                  " s: " + std::to_string(static_cast<long long>(rows)) + " rows of 1 ms, ~" +
                                  td::app::gigabytes(rows * kCsvBytesPerRow) + " of CSV; the limit is " +
                                  fixed(kMaxSampledSeconds, 0) + " s (~" +
                                  td::app::gigabytes(kMaxSampledSeconds * 1000 * kCsvBytesPerRow) + ")");
      }
      outputs.emplace_back(samples_path, samples_csv(r.trajectory, problem.pad));
    }
    for (const auto& [path, text] : outputs) {
      const fs::path dir = fs::absolute(path).parent_path();
      if (!fs::is_directory(dir)) throw td::IoError(path + ": directory " + dir.string() + " does not exist");
    }
    for (const auto& [path, text] : outputs) td::app::write_text_atomically(path, text);

    if (json) {
      std::cout << result_json(r, problem.options.order, seconds).dump() << "\n";
    } else {
      std::cout << summary(problem_path, problem, r, seconds);
    }
    return r.ok() ? td::app::kExitOk : kExitNotOk;
  });
}
