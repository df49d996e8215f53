// landing_plan --plot (docs/cli.md): top, side and rear views of the plan in
// the pad frame with the corridor, obstacles and field of view, and the
// world-frame velocity and acceleration against the limits.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/convex_hull.hpp"
#include "core/format.hpp"
#include "core/svg_plot.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/plan/report.hpp"

namespace touchdown::plan {

namespace {

using detail::format_fixed;

// The vertices of a bounded H-polytope: every intersection of three of its
// planes that lies inside all faces (a polytope here has ~20 faces).
std::vector<Eigen::Vector3d> polytope_vertices(const Polytope& p) {
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

// A panel of the figure: the pixel rectangle (x0, y0, w, h) showing data
// ranges u (across) and v (up), with nice ticks about every 70 px across and
// 45 px up; `flip_u` draws u decreasing to the right.
detail::PlotFrame panel(double x0, double y0, double w, double h, const Range& u, const Range& v, std::string u_title,
                        std::string v_title, bool flip_u = false) {
  detail::PlotFrame f;
  f.left = x0;
  f.top = y0;
  f.right = x0 + w;
  f.bottom = y0 + h;
  f.x.lo = u.lo;
  f.x.hi = u.hi;
  f.x.step = detail::nice_step(u.span(), std::max(2, static_cast<int>(w / 70)));
  f.x.title = std::move(u_title);
  f.x.reversed = flip_u;
  f.y.lo = v.lo;
  f.y.hi = v.hi;
  f.y.step = detail::nice_step(v.span(), std::max(2, static_cast<int>(h / 45)));
  f.y.title = std::move(v_title);
  return f;
}

namespace palette = detail::palette;
const char* kAxisColour[3] = {palette::kRed, palette::kGreen, palette::kBlue};  // x, y, z
constexpr const char* kTrajectory = palette::kBlue;
constexpr const char* kRear = palette::kOrange;
constexpr const char* kTouchdown = palette::kGreen;
constexpr const char* kFov = palette::kPurple;
constexpr const char* kObstacle = palette::kGrey;
const std::string kStartMark = std::string(" fill='") + palette::kGreen + "' stroke='black'";
const std::string kGoalMark = std::string(" fill='") + palette::kRed + "' stroke='black'";
constexpr const char* kLimitStyle = " stroke='black' stroke-dasharray='7,4' stroke-width='1.3'";
constexpr const char* kBoundaryStyle = " stroke='#777' stroke-dasharray='2,3'";

// Attribute text " fill='c' stroke='c'" (an outlined area in one colour).
std::string area(const char* colour) { return std::string(" fill='") + colour + "' stroke='" + colour + "'"; }

struct PlotInput {
  std::string title;
  const PlanProblem* problem;
  const PlanResult* result;
  KinematicState goal;
};

// Page layout of the plot [px]: three views side by side, two time plots
// below them, the legend at the bottom.
constexpr double kPlotWidth = 1240, kMarginLeft = 64, kGap = 70, kViewTop = 70, kMaxViewHeight = 330;
constexpr double kTimePlotHeight = 230;
constexpr double kPadHalf = 0.3;  // drawn pad: a 0.6 m square

// A polytope to draw: its vertices (drawn as their hull in each view).
struct Shape {
  std::vector<Eigen::Vector3d> vertices;
  const char* colour;
  const char* style;
  bool field_of_view = false;
};

// What the views show, in the pad frame.
struct Scene {
  bool have_curve = false;
  std::vector<Eigen::Vector3d> curve;
  std::vector<Shape> shapes;  // drawn in this order
  std::optional<Eigen::Vector3d> camera_at;
};

Scene plot_scene(const PlotInput& in) {
  const PlanResult& r = *in.result;
  const auto& o = in.problem->options;
  Scene scene;
  scene.have_curve = r.ok();
  if (scene.have_curve) {
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      for (int i = 0; i <= 200; ++i) scene.curve.push_back(r.trajectory.evaluate_segment(k, i / 200.0));
    }
  }
  if (o.corridor && o.corridor->camera) {
    scene.shapes.push_back({polytope_vertices(o.corridor->camera->pyramid()), kFov,
                            " fill-opacity='0.07' stroke-dasharray='5,3' stroke-width='1'", true});
    scene.camera_at = o.corridor->camera->T_pad_camera.translation();
  }
  for (const auto& b : o.obstacles) {
    scene.shapes.push_back(
        {polytope_vertices(Polytope::from_box(b)), kObstacle, " fill-opacity='0.55' stroke-width='1'"});
  }
  if (r.corridor.ok()) {
    scene.shapes.push_back({polytope_vertices(r.corridor.rear), kRear, " fill-opacity='0.18' stroke-width='1.5'"});
    scene.shapes.push_back(
        {polytope_vertices(r.corridor.touchdown), kTouchdown, " fill-opacity='0.18' stroke-width='1.5'"});
  }
  return scene;
}

// Extent: everything but the field of view (which reaches far_m away; it is clipped).
std::array<Range, 3> scene_extent(const Scene& scene, const PlotInput& in) {
  std::array<Range, 3> ext;
  auto add = [&](const Eigen::Vector3d& p) {
    for (int a = 0; a < 3; ++a) ext[static_cast<std::size_t>(a)].add(p(a));
  };
  add(in.problem->start.p);
  add(in.goal.p);
  add(Eigen::Vector3d(kPadHalf, kPadHalf, 0));
  add(Eigen::Vector3d(-kPadHalf, -kPadHalf, 0));
  for (const auto& p : scene.curve) add(p);
  if (scene.have_curve) {
    for (const auto& c : in.result->trajectory.all_control_points()) add(c);
  }
  for (const Shape& s : scene.shapes) {
    if (s.field_of_view) continue;
    for (const auto& v : s.vertices) add(v);
  }
  if (scene.camera_at) add(*scene.camera_at);
  for (auto& e : ext) {
    const double pad = std::max(0.1 * e.span(), 0.2);
    e.lo -= pad;
    e.hi += pad;
    e.widen_to(1.0);
  }
  return ext;
}

struct View {
  detail::PlotFrame frame;
  int a, b;  // data axes across and up
  const char* name;
};

struct ViewLayout {
  std::array<View, 3> views;
  double height;  // of each view [px]
};

// Layout: three views side by side on one scale (pixels per metre).
ViewLayout lay_out_views(std::array<Range, 3> ext) {
  const double avail = kPlotWidth - kMarginLeft - 2 * kGap - 20;
  const double sx = ext[0].span(), sy = ext[1].span(), sz = ext[2].span();
  double scale = std::min(avail / (2 * sx + sy), kMaxViewHeight / std::max(sy, sz));
  // The rear view (y) is at least 160 px wide.
  if (sy * scale < 160) {
    ext[1].widen_to(160 / scale);
  }
  scale = std::min(avail / (2 * sx + ext[1].span()), kMaxViewHeight / std::max(ext[1].span(), sz));
  const double view_h = std::max(ext[1].span(), sz) * scale;
  // Each view's vertical range grown to the common height: one scale in all three.
  Range vy = ext[1], vz = ext[2];
  vy.widen_to(view_h / scale);
  vz.widen_to(view_h / scale);
  const double top_x0 = kMarginLeft, side_x0 = top_x0 + sx * scale + kGap, back_x0 = side_x0 + sx * scale + kGap;
  return {{View{panel(top_x0, kViewTop, sx * scale, view_h, ext[0], vy, "x [m] (forward)", "y [m] (left)"), 0, 1,
                "top view (x-y)"},
           View{panel(side_x0, kViewTop, sx * scale, view_h, ext[0], vz, "x [m] (forward)", "z [m] (up)"), 0, 2,
                "side view (x-z)"},
           View{panel(back_x0, kViewTop, ext[1].span() * scale, view_h, ext[1], vz, "\u2190 y [m] (left)", "z [m] (up)",
                      true),
                1, 2, "rear view (y-z)"}},
          view_h};
}

// One view: the shapes, the pad, the camera, the trajectory, start and goal.
void draw_view(detail::SvgWriter& svg, const View& view, const Scene& scene, const PlotInput& in) {
  const detail::PlotFrame& p = view.frame;
  svg.text((p.left + p.right) / 2, p.top - 8, view.name, " text-anchor='middle' font-weight='bold'");
  svg.axes(p);
  svg.begin_clip(p.left, p.top, p.width(), p.height());
  auto to_px = [&](const Eigen::Vector3d& q) { return Eigen::Vector2d(p.px(q(view.a)), p.py(q(view.b))); };
  for (const Shape& s : scene.shapes) {
    std::vector<Eigen::Vector2d> pts;
    for (const auto& v : s.vertices) pts.push_back(to_px(v));
    svg.polygon(detail::convex_hull(pts), area(s.colour) + s.style);
  }
  // The pad: a square seen from above, a thick line from the side and the rear.
  if (view.b == 1) {
    svg.polygon({to_px({-kPadHalf, -kPadHalf, 0}), to_px({kPadHalf, -kPadHalf, 0}), to_px({kPadHalf, kPadHalf, 0}),
                 to_px({-kPadHalf, kPadHalf, 0})},
                " fill='none' stroke='#222' stroke-width='2.5'");
  } else {
    const Eigen::Vector3d a = view.a == 0 ? Eigen::Vector3d(-kPadHalf, 0, 0) : Eigen::Vector3d(0, -kPadHalf, 0);
    const Eigen::Vector2d p0 = to_px(a), p1 = to_px(-a);
    svg.line(p0.x(), p0.y(), p1.x(), p1.y(), " stroke='#222' stroke-width='5'");
  }
  if (scene.camera_at) {
    const Eigen::Vector2d c = to_px(*scene.camera_at);
    svg.square(c.x(), c.y(), 4, std::string(" fill='") + kFov + "'");
  }
  if (scene.have_curve) {
    std::vector<Eigen::Vector2d> pts;
    for (const auto& q : scene.curve) pts.push_back(to_px(q));
    svg.polyline(pts, std::string(" fill='none' stroke='") + kTrajectory + "' stroke-width='2.2'");
    for (const auto& c : in.result->trajectory.all_control_points()) {
      const Eigen::Vector2d q = to_px(c);
      svg.circle(q.x(), q.y(), 2.8, std::string(" fill='white' stroke='") + kTrajectory + "' stroke-width='1.2'");
    }
  }
  const Eigen::Vector2d s = to_px(in.problem->start.p), g = to_px(in.goal.p);
  svg.circle(s.x(), s.y(), 6, kStartMark);
  svg.diamond(g.x(), g.y(), 6, kGoalMark);
  svg.end_clip();
}

// Time plot j (1: velocity, 2: acceleration) in the world frame against
// its limit, with its top edge at `top`.
void draw_time_plot(detail::SvgWriter& svg, int j, double top, bool have_curve, const PlotInput& in) {
  const PlanProblem& pb = *in.problem;
  const PlanResult& r = *in.result;
  const auto& o = pb.options;
  const double tw = (kPlotWidth - kMarginLeft - kGap - 20) / 2;
  const double limit = j == 1 ? o.v_max : o.a_max;
  double T = have_curve ? r.trajectory.total_duration() : 0.0;
  for (const double d : o.durations) T += have_curve ? 0.0 : d;
  if (!(T > 0)) T = 1.0;
  Range t_range, v_range;
  t_range.add(0);
  t_range.add(T);
  std::vector<std::array<double, 4>> samples;  // t, x, y, z
  double peak = limit;
  if (have_curve) {
    const int n = 600;
    for (int i = 0; i <= n; ++i) {
      const double t = T * i / n;
      KinematicState rel{r.trajectory.evaluate(t, 0), r.trajectory.evaluate(t, 1), r.trajectory.evaluate(t, 2)};
      const KinematicState w = pb.pad.to_world(t, rel);
      const Eigen::Vector3d q = j == 1 ? w.v : w.a;
      samples.push_back({t, q.x(), q.y(), q.z()});
      peak = std::max(peak, q.cwiseAbs().maxCoeff());
    }
  }
  // Room above the limit line for its label.
  v_range.add(-1.25 * peak);
  v_range.add(1.25 * peak);
  const detail::PlotFrame p = panel(kMarginLeft + (j - 1) * (tw + kGap), top, tw, kTimePlotHeight, t_range, v_range,
                                    "t [s]", j == 1 ? "v [m/s]" : "a [m/s\u00b2]");
  const char* title = j == 1 ? "world-frame velocity" : "world-frame acceleration";
  svg.text((p.left + p.right) / 2, p.top - 8, title, " text-anchor='middle' font-weight='bold'");
  svg.axes(p);
  svg.begin_clip(p.left, p.top, p.width(), p.height());
  svg.line(p.left, p.py(0), p.right, p.py(0), " stroke='#999'");
  for (double sgn : {1.0, -1.0}) svg.line(p.left, p.py(sgn * limit), p.right, p.py(sgn * limit), kLimitStyle);
  if (have_curve) {
    for (int k = 1; k < r.trajectory.segments(); ++k) {
      const double x = p.px(r.trajectory.start_time(k));
      svg.line(x, p.top, x, p.bottom, kBoundaryStyle);
    }
    for (int a = 0; a < 3; ++a) {
      std::vector<Eigen::Vector2d> pts;
      for (const auto& s : samples) pts.emplace_back(p.px(s[0]), p.py(s[static_cast<std::size_t>(a + 1)]));
      svg.polyline(pts, std::string(" fill='none' stroke='") + kAxisColour[a] + "' stroke-width='1.8'");
    }
  } else {
    svg.text((p.left + p.right) / 2, (p.top + p.bottom) / 2 - 10,
             "no trajectory (" + std::string(to_string(r.status)) + ")",
             " text-anchor='middle' fill='#a00' font-size='14'");
  }
  svg.end_clip();
  svg.text(p.right - 4, p.py(limit) - 4, (j == 1 ? "\u00b1v_max = " : "\u00b1a_max = ") + format_fixed(limit, 2),
           " text-anchor='end'");
}

// Legend: what the views show, then what the time plots show.
void draw_legend(detail::SvgWriter& svg, double legend_y, const Scene& scene, const PlotInput& in) {
  detail::SvgLegend shown(svg, kMarginLeft, legend_y, 18, detail::SvgLegend::Flow::Row);
  auto box = [&](const char* colour, const std::string& more) {
    return [&svg, colour, more](double x, double y) { svg.rect(x - 10, y - 7, 20, 14, area(colour) + more); };
  };
  if (scene.have_curve) {
    shown.entry("trajectory", [&](double x, double y) {
      svg.line(x - 10, y, x + 10, y, std::string(" stroke='") + kTrajectory + "' stroke-width='2.2'");
    });
    shown.entry("control points", [&](double x, double y) {
      svg.circle(x, y, 2.8, std::string(" fill='white' stroke='") + kTrajectory + "'");
    });
  }
  shown.entry("start", [&](double x, double y) { svg.circle(x, y, 6, kStartMark); });
  shown.entry("goal", [&](double x, double y) { svg.diamond(x, y, 6, kGoalMark); });
  if (in.result->corridor.ok()) {
    shown.entry("rear corridor", box(kRear, " fill-opacity='0.3'"));
    shown.entry("touchdown corridor", box(kTouchdown, " fill-opacity='0.3'"));
  }
  if (!in.problem->options.obstacles.empty()) shown.entry("obstacle", box(kObstacle, " fill-opacity='0.55'"));
  if (scene.camera_at) {
    shown.entry("camera + field of view", [&](double x, double y) {
      svg.rect(x - 10, y - 7, 20, 14, area(kFov) + " fill-opacity='0.12' stroke-dasharray='5,3'");
      svg.square(x, y, 4, std::string(" fill='") + kFov + "'");
    });
  }
  shown.entry("pad", [&](double x, double y) {
    svg.rect(x - 10, y - 5, 20, 10, " fill='none' stroke='#222' stroke-width='2.5'");
  });
  detail::SvgLegend plotted(svg, kMarginLeft, legend_y + 24, 18, detail::SvgLegend::Flow::Row);
  for (int a = 0; a < 3; ++a) {
    plotted.entry(std::string("world ") + "xyz"[a], [&](double x, double y) {
      svg.line(x - 10, y, x + 10, y, std::string(" stroke='") + kAxisColour[a] + "' stroke-width='1.8'");
    });
  }
  plotted.entry("per-axis limit", [&](double x, double y) { svg.line(x - 10, y, x + 10, y, kLimitStyle); });
  plotted.entry("segment boundary", [&](double x, double y) { svg.line(x - 10, y, x + 10, y, kBoundaryStyle); });
}

std::string draw_plot(const PlotInput& in) {
  const PlanProblem& pb = *in.problem;
  const Scene scene = plot_scene(in);
  const ViewLayout layout = lay_out_views(scene_extent(scene, in));

  const double time_top = kViewTop + layout.height + 110;
  const double legend_y = time_top + kTimePlotHeight + 70;
  const double H = legend_y + 50;
  detail::SvgWriter svg(kPlotWidth, H);
  svg.title(in.title);
  std::string sub = "pad frame (x forward, y left, z up; origin at the pad centre)";
  if (pb.pad.velocity.norm() > 0 || pb.pad.yaw_rate != 0) {
    sub += "; pad moving at " + format_fixed(pb.pad.velocity.norm(), 2) + " m/s, yaw rate " +
           format_fixed(rad_to_deg(pb.pad.yaw_rate), 2) + " deg/s";
  }
  svg.text(kPlotWidth / 2, 38, sub, " text-anchor='middle' fill='#444'");

  for (const View& view : layout.views) draw_view(svg, view, scene, in);
  // Time plots: world-frame velocity and acceleration against the limits.
  for (int j = 1; j <= 2; ++j) draw_time_plot(svg, j, time_top, scene.have_curve, in);
  draw_legend(svg, legend_y, scene, in);
  return svg.finish();
}

}  // namespace

std::string plot_svg(const PlanProblem& problem, const PlanResult& result, const KinematicState& goal,
                     const std::string& title) {
  return draw_plot(PlotInput{title, &problem, &result, goal});
}

}  // namespace touchdown::plan
