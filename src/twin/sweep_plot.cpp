#include "touchdown/twin/sweep_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/format.hpp"
#include "core/svg_plot.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::twin {
namespace {

using detail::format_trimmed;
using detail::PlotAxis;
using detail::PlotFrame;
using detail::SvgLegend;
using detail::SvgWriter;

namespace palette = touchdown::detail::palette;
constexpr const char* kSafe = palette::kGreen;
constexpr const char* kUnsafe = palette::kRed;
constexpr const char* kStrike = palette::kOrange;
constexpr const char* kTipped = palette::kBrown;
constexpr const char* kInvalid = palette::kPurple;
constexpr const char* kUnobserved = "#f4b860";  // a light orange hatched in brown: unknown ground

// Attribute text: " fill='c'" and " stroke='c' stroke-width='w'".
std::string fill(std::string_view colour) { return " fill='" + std::string(colour) + "'"; }
std::string stroke(std::string_view colour, double width) {
  return " stroke='" + std::string(colour) + "' stroke-width='" + SvgWriter::number(width) + "'";
}

// Green (S = 0) through yellow to red (S at or above the threshold).
std::string score_colour(double s, double threshold) {
  const double t = std::clamp(s / threshold, 0.0, 1.0);
  const std::array<double, 3> g{42, 157, 58}, y{240, 200, 40}, r{214, 39, 40};
  std::array<double, 3> c{};
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    c[i] = t < 0.5 ? g[i] + (y[i] - g[i]) * 2 * t : y[i] + (r[i] - y[i]) * (2 * t - 1);
  }
  return detail::rgb_colour(static_cast<int>(c[0]), static_cast<int>(c[1]), static_cast<int>(c[2]));
}

// Terrain height: grey, lightest at the top; `g` in [90, 240].
std::string height_colour(int g) { return detail::rgb_colour(g, g, std::min(255, g + 15)); }

// The S(ψ) panel with its top-left corner at (ox, oy), `w` × `h` pixels.
void heading_panel(SvgWriter& svg, const SweepResult& r, double ox, double oy, double w, double h) {
  const double yaw_max_deg = rad_to_deg(r.yaw_max > 0 ? r.yaw_max : 2 * std::numbers::pi);
  const double thr = r.threshold.value();
  // y range: the threshold with room above it, and the scored S values up
  // to π/2 (a drone on its side); anything higher is an arrow at the top.
  double top = 1.25 * thr;
  for (const auto& hs : r.headings) {
    if (hs.scored()) top = std::max(top, std::min(hs.score, std::numbers::pi / 2) * 1.05);
  }
  PlotFrame f;
  f.left = ox + 70;
  f.right = ox + w - 200;
  f.top = oy + 40;
  f.bottom = oy + h - 45;
  f.x = PlotAxis{0, yaw_max_deg, detail::degree_step(yaw_max_deg), 1, "heading ψ [deg]", false, true};
  f.y = detail::fit_axis(0, top, 6, "final nutation N [rad]");
  f.y.decimals = 3;
  f.y.tick_marks = false;
  const double L = f.left, R = f.right, T = f.top, B = f.bottom, ymax = f.y.hi;
  auto X = [&](double deg) { return f.px(deg); };
  auto Y = [&](double v) { return f.py(std::min(v, ymax)); };
  const double band = T - 14;  // the "invalid" row above the axes

  // Headings over unobserved terrain: shaded columns.
  const double col = (R - L) / static_cast<double>(std::max<std::size_t>(1, r.headings.size()));
  for (const auto& hs : r.headings) {
    if (!hs.unobserved) continue;
    const double x = X(rad_to_deg(hs.yaw));
    svg.rect(std::max(L, x - col / 2), T, std::min(R, x + col / 2) - std::max(L, x - col / 2), B - T,
             fill(kUnobserved) + " fill-opacity='0.35'");
  }
  svg.axes(f);
  svg.text(L - 6, band + 4, "invalid", " text-anchor='end'" + fill(kInvalid));

  // Threshold.
  svg.line(L, Y(thr), R, Y(thr), " stroke='" + std::string(kUnsafe) + "' stroke-dasharray='6,4'");
  svg.text(R - 4, Y(thr) - 5,
           "safety threshold " + format_trimmed(thr, 3) + " rad (" + format_trimmed(rad_to_deg(thr), 1) + " deg)",
           " text-anchor='end'" + fill(kUnsafe));

  // Runs: settled ones at their nutation, the others in the invalid band;
  // runs of one heading are spread a little sideways so that they stay apparent.
  const int m = std::max(1, r.rounds_completed);
  for (const auto& run : r.runs) {
    const double x = X(rad_to_deg(run.conditions.heading)) + (run.run - (m - 1) / 2.0) * std::min(2.0, 12.0 / m);
    const RunResult& res = run.result;
    if (!res.ok()) {
      svg.square(x, band, 3, " fill='white'" + stroke(kInvalid, 1.5));
    } else if (res.nutation > ymax) {
      svg.triangle(x, T + 5, 4, fill(res.tipped ? kTipped : "#666"));
    } else if (res.tipped) {
      svg.cross(x, Y(res.nutation), 3.5, stroke(kTipped, 2));
    } else if (res.strike()) {
      svg.diamond(x, Y(res.nutation), 4, fill(kStrike));
    } else {
      svg.circle(x, Y(res.nutation), 2, fill("#888"));
    }
  }
  // S(ψ): a line through the scored headings, a dot per heading.
  std::vector<Eigen::Vector2d> line;
  for (const auto& hs : r.headings) {
    if (hs.scored()) line.emplace_back(X(rad_to_deg(hs.yaw)), Y(hs.score));
  }
  svg.polyline(line, std::string(" fill='none' stroke='") + palette::kBlue + "' stroke-width='1.5'");
  for (std::size_t j = 0; j < r.headings.size(); ++j) {
    const auto& hs = r.headings[j];
    if (!hs.scored()) continue;
    const double x = X(rad_to_deg(hs.yaw)), y = Y(hs.score);
    svg.circle(x, y, 4.5, fill(hs.safe ? kSafe : kUnsafe) + " stroke='white'");
    if (static_cast<int>(j) == r.best) {
      svg.circle(x, y, 9, fill("none") + stroke(r.safe ? kSafe : kUnsafe, 2));
      svg.text(x, y - 13,
               std::string(r.safe ? "land: " : "least bad: ") + format_trimmed(rad_to_deg(hs.yaw), 1) + " deg",
               " text-anchor='middle' font-weight='bold'");
    }
  }

  // Legend.
  SvgLegend legend(svg, R + 16, T + 4, 19);
  legend.entry("S(ψ), safe heading", [&](double x, double y) { svg.circle(x, y, 4.5, fill(kSafe)); });
  legend.entry("S(ψ), unsafe heading", [&](double x, double y) { svg.circle(x, y, 4.5, fill(kUnsafe)); });
  legend.entry(r.safe ? "chosen heading ψ*" : "lowest S (not safe)",
               [&](double x, double y) { svg.circle(x, y, 7, fill("none") + stroke(r.safe ? kSafe : kUnsafe, 2)); });
  legend.entry("run: final nutation", [&](double x, double y) { svg.circle(x, y, 2, fill("#888")); });
  legend.entry("run with a strike", [&](double x, double y) { svg.diamond(x, y, 4, fill(kStrike)); });
  legend.entry("run tipped over", [&](double x, double y) { svg.cross(x, y, 3.5, stroke(kTipped, 2)); });
  legend.entry("run beyond the axis", [&](double x, double y) { svg.triangle(x, y, 4, fill("#666")); });
  legend.entry("run invalid (not scored)",
               [&](double x, double y) { svg.square(x, y, 3, " fill='white'" + stroke(kInvalid, 1.5)); });
  legend.entry("over unobserved terrain",
               [&](double x, double y) { svg.rect(x - 6, y - 6, 12, 12, fill(kUnobserved) + " fill-opacity='0.5'"); });
  legend.entry("safety threshold", [&](double x, double y) {
    svg.line(x - 8, y, x + 8, y, " stroke='" + std::string(kUnsafe) + "' stroke-dasharray='4,3'");
  });
  // The verdict, wrapped to the legend's width.
  const double lx = legend.x();
  double ly = legend.y() + 8;
  const std::string verdict =
      r.safe ? "land at heading " + format_trimmed(rad_to_deg(r.headings[static_cast<std::size_t>(r.best)].yaw), 1) +
                   " deg"
             : "do not land: " + unsafe_summary(r);
  const std::string colour = r.safe ? "" : fill(kUnsafe);
  std::istringstream words(verdict);
  std::string word, text_line;
  while (words >> word) {
    if (!text_line.empty() && text_line.size() + word.size() > 30) {
      svg.text(lx, ly, text_line, colour);
      ly += 15;
      text_line.clear();
    }
    text_line += (text_line.empty() ? "" : " ") + word;
  }
  if (!text_line.empty()) svg.text(lx, ly, text_line, colour);
}

int most_runs(const SweepResult& r) {
  int m = 0;
  for (const auto& h : r.headings) m = std::max(m, h.runs);
  return m;
}

std::string title(const SweepResult& r, const SweepPlotLabels& labels) {
  return "Landing sweep: " + labels.terrain + ", " + labels.airframe + ", landing point (" +
         format_trimmed(r.landing_point.x(), 3) + ", " + format_trimmed(r.landing_point.y(), 3) + ") m, " +
         std::to_string(r.headings.size()) + " headings x " +
         // The decision mode flies no whole rounds: say how many landings.
         (r.rounds_completed > 0 ? std::to_string(r.rounds_completed) + " runs"
                                 : "up to " + std::to_string(most_runs(r)) + " runs (decision mode, " +
                                       std::to_string(r.landings()) + " landings)");
}

}  // namespace

std::string sweep_plot_svg(const SweepResult& r, const SweepPlotLabels& labels) {
  const double W = 900, H = 440;
  SvgWriter svg(W, H);
  svg.title(title(r, labels));
  heading_panel(svg, r, 0, 16, W, H - 16);
  return svg.finish();
}

std::string search_plot_svg(const SearchResult& search, const Eigen::Vector2d& requested, double radius,
                            const Airframe& af, const TerrainModel& terrain, const SweepPlotLabels& labels) {
  const SweepResult& r = search.sweep;
  const double W = 900, H1 = 440, H2 = 520, H = H1 + H2;
  SvgWriter svg(W, H);
  svg.title(title(r, labels));
  heading_panel(svg, r, 0, 16, W, H1 - 16);

  // ---- top view of the search ----------------------------------------------
  const double reach = af.footprint_radius();
  const double half = radius + reach + 0.1;
  const double size = H2 - 90, L = 70, T = H1 + 40;
  const double scale = size / (2 * half);
  auto PX = [&](double x) { return L + (x - (requested.x() - half)) * scale; };
  auto PY = [&](double y) { return T + ((requested.y() + half) - y) * scale; };
  svg.title("Landing-point search: candidates within " + format_trimmed(radius, 3) + " m of (" +
                format_trimmed(requested.x(), 3) + ", " + format_trimmed(requested.y(), 3) +
                "), coloured by their best S",
            H1 + 20);
  // Height map by sampling the terrain's top surface.
  const int n = 100;
  const double step = 2 * half / n;
  std::vector<double> z(static_cast<std::size_t>(n) * n, std::numeric_limits<double>::quiet_NaN());
  double zlo = std::numeric_limits<double>::max(), zhi = std::numeric_limits<double>::lowest();
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const auto t = terrain.top_z(requested.x() - half + (i + 0.5) * step, requested.y() - half + (j + 0.5) * step);
      if (!t) continue;
      z[static_cast<std::size_t>(j) * n + i] = *t;
      zlo = std::min(zlo, *t);
      zhi = std::max(zhi, *t);
    }
  }
  if (zhi < zlo) zlo = zhi = 0;
  const double zspan = std::max(zhi - zlo, 1e-3);
  svg.raw(std::string("<defs><pattern id='unk' width='6' height='6' patternUnits='userSpaceOnUse' "
                      "patternTransform='rotate(45)'><rect width='6' height='6' fill='") +
          kUnobserved + "'/><line x1='0' y1='0' x2='0' y2='6' stroke='" + std::string(palette::kBrown) +
          "' stroke-width='2'/></pattern></defs>\n");
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double v = z[static_cast<std::size_t>(j) * n + i];
      if (std::isnan(v)) continue;
      const double cx = requested.x() - half + (i + 0.5) * step, cy = requested.y() - half + (j + 0.5) * step;
      const bool unknown = terrain.unknown_near({cx, cy}, {cx, cy}, 0.0);
      const int g = static_cast<int>(90 + 150 * (v - zlo) / zspan);
      svg.rect(PX(cx - step / 2), PY(cy + step / 2), step * scale + 0.6, step * scale + 0.6,
               fill(unknown ? "url(#unk)" : height_colour(g)));
    }
  }
  svg.rect(L, T, size, size, " fill='none' stroke='black'");
  // Axes ticks in metres.
  const double tick = detail::nice_step(2 * half, 5);
  for (const double v : detail::ticks(requested.x() - half, requested.x() + half, tick)) {
    svg.text(PX(v), T + size + 16, format_trimmed(v, 2), " text-anchor='middle'");
  }
  for (const double v : detail::ticks(requested.y() - half, requested.y() + half, tick)) {
    svg.text(L - 6, PY(v) + 4, format_trimmed(v, 2), " text-anchor='end'");
  }
  svg.text(L + size / 2, T + size + 34, "x [m]", " text-anchor='middle'");
  svg.text(L - 44, T + size / 2, "y [m]", " text-anchor='middle'");
  // The search circle and the requested point.
  svg.circle(PX(requested.x()), PY(requested.y()), radius * scale,
             fill("none") + " stroke='" + palette::kBlue + "' stroke-dasharray='5,4'");
  svg.cross(PX(requested.x()), PY(requested.y()), 6, stroke("black", 1.5));
  // Candidates, their markers sized to the grid (the nearest neighbour of
  // the requested point is one spacing away).
  const double thr = r.threshold.value();
  double spacing = 2 * half;
  for (const auto& c : search.candidates) {
    const double d = (c.xy - requested).norm();
    if (d > 1e-9) spacing = std::min(spacing, d);
  }
  const double mr = std::clamp(0.38 * spacing * scale, 2.5, 7.0);
  for (const auto& c : search.candidates) {
    const double x = PX(c.xy.x()), y = PY(c.xy.y());
    if (!c.evaluated) {
      svg.circle(x, y, std::min(2.0, mr), fill("#999"));
    } else if (!c.covered || std::isnan(c.score)) {
      svg.circle(x, y, mr * 0.85, fill("white") + stroke("#555", 1.5));
    } else {
      svg.circle(x, y, mr, fill(score_colour(c.score, thr)) + stroke(c.safe ? "black" : kUnsafe, c.safe ? 1 : 2));
      if (!c.safe) svg.cross(x, y, mr * 0.55, stroke(kUnsafe, 1.5));
    }
  }
  // The chosen point: the airframe's footprint at the chosen heading.
  if (search.best >= 0 && r.best >= 0) {
    const auto& c = search.candidates[static_cast<std::size_t>(search.best)];
    const double yaw = r.headings[static_cast<std::size_t>(r.best)].yaw;
    const Eigen::Rotation2Dd rot(yaw);
    auto W2 = [&](const Eigen::Vector3d& body) -> Eigen::Vector2d { return c.xy + rot * body.head<2>(); };
    const char* colour = r.safe ? kSafe : kUnsafe;
    for (std::size_t i = 0; i < af.motor_count(); ++i) {
      const Capsule arm = af.arm(i);
      const Eigen::Vector2d a = W2(arm.a), b = W2(arm.b);
      svg.line(PX(a.x()), PY(a.y()), PX(b.x()), PY(b.y()), stroke(colour, std::max(2.0, 2 * arm.radius * scale)));
      svg.circle(PX(b.x()), PY(b.y()), af.prop_radius * scale, fill("none") + stroke(colour, 1.5));
    }
    const Box body = af.body_box();
    std::vector<Eigen::Vector2d> corners;
    for (const auto& s :
         {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
      const Eigen::Vector2d p = W2(Eigen::Vector3d(s.x() * body.half_extents.x(), s.y() * body.half_extents.y(), 0));
      corners.emplace_back(PX(p.x()), PY(p.y()));
    }
    svg.polygon(corners, fill(colour) + " fill-opacity='0.5' stroke='" + colour + "'");
    for (const auto& l : af.legs) {
      const Eigen::Vector2d p = c.xy + rot * l;
      svg.circle(PX(p.x()), PY(p.y()), 3, fill("black"));
    }
    const Eigen::Vector2d nose = c.xy + rot * Eigen::Vector2d(reach * 0.8, 0);
    svg.line(PX(c.xy.x()), PY(c.xy.y()), PX(nose.x()), PY(nose.y()),
             " stroke='black' stroke-width='2' marker-end='url(#arrow)'");
    svg.raw(
        "<defs><marker id='arrow' markerWidth='8' markerHeight='8' refX='6' refY='4' orient='auto'>"
        "<path d='M0,0 L8,4 L0,8 Z' fill='black'/></marker></defs>\n");
  }
  // Legend of the map.
  SvgLegend legend(svg, L + size + 30, T + 6, 20);
  legend.entry("requested point", [&](double x, double y) { svg.cross(x, y, 5, stroke("black", 1.5)); });
  legend.entry("candidate, safe (fill: best S)",
               [&](double x, double y) { svg.circle(x, y, 6, fill(kSafe) + " stroke='black'"); });
  legend.entry("candidate, unsafe", [&](double x, double y) {
    svg.circle(x, y, 6, fill(score_colour(0.5 * thr, thr)) + stroke(kUnsafe, 2.5));
    svg.cross(x, y, 4, stroke(kUnsafe, 1.5));
  });
  legend.entry("off the scan / not scored",
               [&](double x, double y) { svg.circle(x, y, 5, fill("white") + " stroke='#555'"); });
  legend.entry("not flown (a nearer point is safe)", [&](double x, double y) { svg.circle(x, y, 2, fill("#999")); });
  legend.entry("unobserved terrain", [&](double x, double y) { svg.rect(x - 6, y - 6, 12, 12, fill("url(#unk)")); });
  legend.entry(std::string(r.safe ? "chosen: " : "least bad: ") + "airframe at ψ*", [&](double x, double y) {
    svg.rect(x - 5, y - 5, 10, 10, fill(r.safe ? kSafe : kUnsafe) + " fill-opacity='0.5'");
  });
  // Colour bars: S from 0 to the threshold, and the terrain's height.
  const double lx = legend.x();
  double ly = legend.y() + 10;
  svg.text(lx, ly, "best S [rad]");
  ly += 8;
  for (int k = 0; k < 20; ++k) svg.rect(lx + k * 8, ly, 8.5, 12, fill(score_colour(thr * k / 19.0, thr)));
  svg.text(lx, ly + 26, "0");
  svg.text(lx + 160, ly + 26, format_trimmed(thr, 3) + " (threshold)", " text-anchor='end'");
  ly += 48;
  svg.text(lx, ly, "terrain height [m]");
  ly += 8;
  for (int k = 0; k < 20; ++k)
    svg.rect(lx + k * 8, ly, 8.5, 12, fill(height_colour(static_cast<int>(90 + 150 * k / 19.0))));
  svg.text(lx, ly + 26, format_trimmed(zlo, 3));
  svg.text(lx + 160, ly + 26, format_trimmed(zhi, 3), " text-anchor='end'");
  return svg.finish();
}

}  // namespace touchdown::twin
