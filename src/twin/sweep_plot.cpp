#include "touchdown/twin/sweep_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include "touchdown/core/units.hpp"
#include "touchdown/core/xml.hpp"

namespace touchdown::twin {
namespace {

// Shortest decimal form of v with at most `decimals` places ("0.25", "30").
std::string num(double v, int decimals = 3) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  return s == "-0" ? "0" : s;
}

// A tick step of 1, 2, 2.5 or 5 × 10^k giving about `target` intervals.
double nice_step(double span, int target) {
  const double raw = span / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 2.5, 5.0}) {
    if (m * p >= raw * 0.999) return m * p;
  }
  return 10 * p;
}

// Heading ticks: the smallest of these steps giving at most 8 intervals.
double heading_step(double yaw_max_deg) {
  for (const double s : {5.0, 10.0, 15.0, 30.0, 45.0, 60.0, 90.0}) {
    if (yaw_max_deg / s <= 8.0 + 1e-9) return s;
  }
  return 90.0;
}

constexpr const char* kSafe = "#2a9d3a";
constexpr const char* kUnsafe = "#d62728";
constexpr const char* kStrike = "#ff7f0e";
constexpr const char* kTipped = "#7a0000";
constexpr const char* kInvalid = "#7b3fa0";
constexpr const char* kUnobserved = "#f4b860";

// Marker shapes, centred at (x, y).
void diamond(std::ostream& os, double x, double y, double r, const char* fill) {
  os << "<path d='M" << num(x, 1) << "," << num(y - r, 1) << " L" << num(x + r, 1) << "," << num(y, 1) << " L"
     << num(x, 1) << "," << num(y + r, 1) << " L" << num(x - r, 1) << "," << num(y, 1) << " Z' fill='" << fill
     << "'/>\n";
}
void cross(std::ostream& os, double x, double y, double r, const char* stroke, double width = 2) {
  os << "<path d='M" << num(x - r, 1) << "," << num(y - r, 1) << " L" << num(x + r, 1) << "," << num(y + r, 1) << " M"
     << num(x - r, 1) << "," << num(y + r, 1) << " L" << num(x + r, 1) << "," << num(y - r, 1) << "' stroke='" << stroke
     << "' stroke-width='" << width << "'/>\n";
}
void square(std::ostream& os, double x, double y, double r, const char* stroke) {
  os << "<rect x='" << num(x - r, 1) << "' y='" << num(y - r, 1) << "' width='" << num(2 * r, 1) << "' height='"
     << num(2 * r, 1) << "' fill='white' stroke='" << stroke << "' stroke-width='1.5'/>\n";
}
void up_arrow(std::ostream& os, double x, double y, double r, const char* fill) {
  os << "<path d='M" << num(x, 1) << "," << num(y - r, 1) << " L" << num(x + r, 1) << "," << num(y + r, 1) << " L"
     << num(x - r, 1) << "," << num(y + r, 1) << " Z' fill='" << fill << "'/>\n";
}
void circle(std::ostream& os, double x, double y, double r, const std::string& fill, const std::string& extra = "") {
  os << "<circle cx='" << num(x, 1) << "' cy='" << num(y, 1) << "' r='" << num(r, 1) << "' fill='" << fill << "'"
     << extra << "/>\n";
}
void text(std::ostream& os, double x, double y, const std::string& s, const std::string& extra = "") {
  os << "<text x='" << num(x, 1) << "' y='" << num(y, 1) << "'" << extra << ">" << xml_escape(s) << "</text>\n";
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
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", static_cast<int>(c[0]), static_cast<int>(c[1]),
                static_cast<int>(c[2]));
  return buf;
}

// The S(ψ) panel with its top-left corner at (ox, oy), `w` × `h` pixels.
void heading_panel(std::ostream& os, const SweepResult& r, double ox, double oy, double w, double h) {
  const double L = ox + 70, R = ox + w - 200, T = oy + 40, B = oy + h - 45;  // axes box
  const double yaw_max_deg = rad_to_deg(r.yaw_max > 0 ? r.yaw_max : 2 * std::numbers::pi);
  const double thr = r.threshold.value();
  // y range: the threshold with room above it, and the scored S values up
  // to π/2 (a drone on its side); anything higher is an arrow at the top.
  double top = 1.25 * thr;
  for (const auto& hs : r.headings) {
    if (hs.scored()) top = std::max(top, std::min(hs.score, std::numbers::pi / 2) * 1.05);
  }
  const double ystep = nice_step(top, 6);
  const double ymax = std::ceil(top / ystep - 1e-9) * ystep;
  auto X = [&](double deg) { return L + (R - L) * deg / yaw_max_deg; };
  auto Y = [&](double v) { return B - (B - T) * std::min(v, ymax) / ymax; };
  const double band = T - 14;  // the "invalid" row above the axes

  // Headings over unobserved terrain: shaded columns.
  const double col = (R - L) / static_cast<double>(std::max<std::size_t>(1, r.headings.size()));
  for (const auto& hs : r.headings) {
    if (!hs.unobserved) continue;
    const double x = X(rad_to_deg(hs.yaw));
    os << "<rect x='" << num(std::max(L, x - col / 2), 1) << "' y='" << num(T, 1) << "' width='"
       << num(std::min(R, x + col / 2) - std::max(L, x - col / 2), 1) << "' height='" << num(B - T, 1) << "' fill='"
       << kUnobserved << "' fill-opacity='0.35'/>\n";
  }
  // Grid and ticks.
  for (double v = 0; v <= ymax + 1e-9; v += ystep) {
    os << "<line x1='" << num(L, 1) << "' y1='" << num(Y(v), 1) << "' x2='" << num(R, 1) << "' y2='" << num(Y(v), 1)
       << "' stroke='#e5e5e5'/>\n";
    text(os, L - 6, Y(v) + 4, num(v, 3), " text-anchor='end'");
  }
  const double xstep = heading_step(yaw_max_deg);
  for (double d = 0; d <= yaw_max_deg + 1e-9; d += xstep) {
    os << "<line x1='" << num(X(d), 1) << "' y1='" << num(B, 1) << "' x2='" << num(X(d), 1) << "' y2='" << num(B + 5, 1)
       << "' stroke='black'/>\n";
    text(os, X(d), B + 18, num(d, 1), " text-anchor='middle'");
  }
  os << "<rect x='" << num(L, 1) << "' y='" << num(T, 1) << "' width='" << num(R - L, 1) << "' height='"
     << num(B - T, 1) << "' fill='none' stroke='black'/>\n";
  text(os, (L + R) / 2, B + 36, "heading ψ [deg]", " text-anchor='middle'");
  os << "<text x='" << num(ox + 18, 1) << "' y='" << num((T + B) / 2, 1) << "' transform='rotate(-90 "
     << num(ox + 18, 1) << "," << num((T + B) / 2, 1) << ")' text-anchor='middle'>final nutation N [rad]</text>\n";
  text(os, L - 6, band + 4, "invalid", " text-anchor='end' fill='" + std::string(kInvalid) + "'");

  // Threshold.
  os << "<line x1='" << num(L, 1) << "' y1='" << num(Y(thr), 1) << "' x2='" << num(R, 1) << "' y2='" << num(Y(thr), 1)
     << "' stroke='" << kUnsafe << "' stroke-dasharray='6,4'/>\n";
  text(os, R - 4, Y(thr) - 5, "safety threshold " + num(thr, 3) + " rad (" + num(rad_to_deg(thr), 1) + " deg)",
       " text-anchor='end' fill='" + std::string(kUnsafe) + "'");

  // Runs: settled ones at their nutation, the others in the invalid band;
  // runs of one heading are spread a little sideways so that they stay apparent.
  const int m = std::max(1, r.rounds_completed);
  for (const auto& run : r.runs) {
    const double x = X(rad_to_deg(run.conditions.heading)) + (run.run - (m - 1) / 2.0) * std::min(2.0, 12.0 / m);
    const RunResult& res = run.result;
    if (!res.ok()) {
      square(os, x, band, 3, kInvalid);
    } else if (res.nutation > ymax) {
      up_arrow(os, x, T + 5, 4, res.tipped ? kTipped : "#666");
    } else if (res.tipped) {
      cross(os, x, Y(res.nutation), 3.5, kTipped);
    } else if (res.strike()) {
      diamond(os, x, Y(res.nutation), 4, kStrike);
    } else {
      circle(os, x, Y(res.nutation), 2, "#888");
    }
  }
  // S(ψ): a line through the scored headings, a dot per heading.
  os << "<polyline fill='none' stroke='#1f5fbf' stroke-width='1.5' points='";
  for (const auto& hs : r.headings) {
    if (hs.scored()) os << num(X(rad_to_deg(hs.yaw)), 1) << "," << num(Y(hs.score), 1) << " ";
  }
  os << "'/>\n";
  for (std::size_t j = 0; j < r.headings.size(); ++j) {
    const auto& hs = r.headings[j];
    if (!hs.scored()) continue;
    const double x = X(rad_to_deg(hs.yaw)), y = Y(hs.score);
    circle(os, x, y, 4.5, hs.safe ? kSafe : kUnsafe, " stroke='white'");
    if (static_cast<int>(j) == r.best) {
      circle(os, x, y, 9, "none", std::string(" stroke='") + (r.safe ? kSafe : kUnsafe) + "' stroke-width='2'");
      text(os, x, y - 13, std::string(r.safe ? "land: " : "least bad: ") + num(rad_to_deg(hs.yaw), 1) + " deg",
           " text-anchor='middle' font-weight='bold'");
    }
  }

  // Legend.
  const double lx = R + 16;
  double ly = T + 4;
  auto entry = [&](const std::string& label, auto&& draw) {
    draw(lx + 8, ly);
    text(os, lx + 22, ly + 4, label);
    ly += 19;
  };
  entry("S(ψ), safe heading", [&](double x, double y) { circle(os, x, y, 4.5, kSafe); });
  entry("S(ψ), unsafe heading", [&](double x, double y) { circle(os, x, y, 4.5, kUnsafe); });
  entry(r.safe ? "chosen heading ψ*" : "lowest S (not safe)", [&](double x, double y) {
    circle(os, x, y, 7, "none", std::string(" stroke='") + (r.safe ? kSafe : kUnsafe) + "' stroke-width='2'");
  });
  entry("run: final nutation", [&](double x, double y) { circle(os, x, y, 2, "#888"); });
  entry("run with a strike", [&](double x, double y) { diamond(os, x, y, 4, kStrike); });
  entry("run tipped over", [&](double x, double y) { cross(os, x, y, 3.5, kTipped); });
  entry("run beyond the axis", [&](double x, double y) { up_arrow(os, x, y, 4, "#666"); });
  entry("run invalid (not scored)", [&](double x, double y) { square(os, x, y, 3, kInvalid); });
  entry("over unobserved terrain", [&](double x, double y) {
    os << "<rect x='" << num(x - 6, 1) << "' y='" << num(y - 6, 1) << "' width='12' height='12' fill='" << kUnobserved
       << "' fill-opacity='0.5'/>\n";
  });
  entry("safety threshold", [&](double x, double y) {
    os << "<line x1='" << num(x - 8, 1) << "' y1='" << num(y, 1) << "' x2='" << num(x + 8, 1) << "' y2='" << num(y, 1)
       << "' stroke='" << kUnsafe << "' stroke-dasharray='4,3'/>\n";
  });
  // The verdict, wrapped to the legend's width.
  ly += 8;
  std::string verdict =
      r.safe ? "land at heading " + num(rad_to_deg(r.headings[static_cast<std::size_t>(r.best)].yaw), 1) + " deg"
             : "do not land: " + unsafe_summary(r);
  std::istringstream words(verdict);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && line.size() + word.size() > 30) {
      text(os, lx, ly, line, r.safe ? "" : " fill='" + std::string(kUnsafe) + "'");
      ly += 15;
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) text(os, lx, ly, line, r.safe ? "" : " fill='" + std::string(kUnsafe) + "'");
}

std::string title(const SweepResult& r, const SweepPlotLabels& labels) {
  return "Landing sweep: " + labels.terrain + ", " + labels.airframe + ", landing point (" +
         num(r.landing_point.x(), 3) + ", " + num(r.landing_point.y(), 3) + ") m, " +
         std::to_string(r.headings.size()) + " headings x " + std::to_string(r.rounds_completed) + " runs";
}

void header(std::ostream& os, double w, double h) {
  os << "<svg xmlns='http://www.w3.org/2000/svg' width='" << num(w, 0) << "' height='" << num(h, 0)
     << "' font-family='sans-serif' font-size='12'>\n"
     << "<rect width='100%' height='100%' fill='white'/>\n";
}

}  // namespace

std::string sweep_plot_svg(const SweepResult& r, const SweepPlotLabels& labels) {
  const double W = 900, H = 440;
  std::ostringstream os;
  header(os, W, H);
  text(os, W / 2, 20, title(r, labels), " text-anchor='middle' font-size='14'");
  heading_panel(os, r, 0, 16, W, H - 16);
  os << "</svg>\n";
  return os.str();
}

std::string search_plot_svg(const SearchResult& search, const Eigen::Vector2d& requested, double radius,
                            const Airframe& af, const TerrainModel& terrain, const SweepPlotLabels& labels) {
  const SweepResult& r = search.sweep;
  const double W = 900, H1 = 440, H2 = 520, H = H1 + H2;
  std::ostringstream os;
  header(os, W, H);
  text(os, W / 2, 20, title(r, labels), " text-anchor='middle' font-size='14'");
  heading_panel(os, r, 0, 16, W, H1 - 16);

  // ---- top view of the search ----------------------------------------------
  const double reach = af.footprint_radius();
  const double half = radius + reach + 0.1;
  const double size = H2 - 90, L = 70, T = H1 + 40;
  const double scale = size / (2 * half);
  auto PX = [&](double x) { return L + (x - (requested.x() - half)) * scale; };
  auto PY = [&](double y) { return T + ((requested.y() + half) - y) * scale; };
  text(os, W / 2, H1 + 20,
       "Landing-point search: candidates within " + num(radius, 3) + " m of (" + num(requested.x(), 3) + ", " +
           num(requested.y(), 3) + "), coloured by their best S",
       " text-anchor='middle' font-size='14'");
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
  os << "<defs><pattern id='unk' width='6' height='6' patternUnits='userSpaceOnUse' patternTransform='rotate(45)'>"
     << "<rect width='6' height='6' fill='" << kUnobserved << "'/><line x1='0' y1='0' x2='0' y2='6' stroke='#a0522d' "
     << "stroke-width='2'/></pattern></defs>\n";
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double v = z[static_cast<std::size_t>(j) * n + i];
      if (std::isnan(v)) continue;
      const double cx = requested.x() - half + (i + 0.5) * step, cy = requested.y() - half + (j + 0.5) * step;
      const bool unknown = terrain.unknown_near({cx, cy}, {cx, cy}, 0.0);
      const int g = static_cast<int>(90 + 150 * (v - zlo) / zspan);
      char fill[16];
      std::snprintf(fill, sizeof fill, "#%02x%02x%02x", g, g, std::min(255, g + 15));
      os << "<rect x='" << num(PX(cx - step / 2), 1) << "' y='" << num(PY(cy + step / 2), 1) << "' width='"
         << num(step * scale + 0.6, 1) << "' height='" << num(step * scale + 0.6, 1) << "' fill='"
         << (unknown ? "url(#unk)" : fill) << "'/>\n";
    }
  }
  os << "<rect x='" << num(L, 1) << "' y='" << num(T, 1) << "' width='" << num(size, 1) << "' height='" << num(size, 1)
     << "' fill='none' stroke='black'/>\n";
  // Axes ticks in metres.
  const double tick = nice_step(2 * half, 5);
  for (double v = std::ceil((requested.x() - half) / tick) * tick; v <= requested.x() + half + 1e-9; v += tick) {
    text(os, PX(v), T + size + 16, num(v, 2), " text-anchor='middle'");
  }
  for (double v = std::ceil((requested.y() - half) / tick) * tick; v <= requested.y() + half + 1e-9; v += tick) {
    text(os, L - 6, PY(v) + 4, num(v, 2), " text-anchor='end'");
  }
  text(os, L + size / 2, T + size + 34, "x [m]", " text-anchor='middle'");
  text(os, L - 44, T + size / 2, "y [m]", " text-anchor='middle'");
  // The search circle and the requested point.
  circle(os, PX(requested.x()), PY(requested.y()), radius * scale, "none", " stroke='#1f5fbf' stroke-dasharray='5,4'");
  cross(os, PX(requested.x()), PY(requested.y()), 6, "black", 1.5);
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
      circle(os, x, y, std::min(2.0, mr), "#999");
    } else if (!c.covered || std::isnan(c.score)) {
      circle(os, x, y, mr * 0.85, "white", " stroke='#555' stroke-width='1.5'");
    } else {
      circle(os, x, y, mr, score_colour(c.score, thr),
             std::string(" stroke='") + (c.safe ? "black" : kUnsafe) + "' stroke-width='" + (c.safe ? "1" : "2") + "'");
      if (!c.safe) cross(os, x, y, mr * 0.55, kUnsafe, 1.5);
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
      os << "<line x1='" << num(PX(a.x()), 1) << "' y1='" << num(PY(a.y()), 1) << "' x2='" << num(PX(b.x()), 1)
         << "' y2='" << num(PY(b.y()), 1) << "' stroke='" << colour << "' stroke-width='"
         << num(std::max(2.0, 2 * arm.radius * scale), 1) << "'/>\n";
      circle(os, PX(b.x()), PY(b.y()), af.prop_radius * scale, "none",
             std::string(" stroke='") + colour + "' stroke-width='1.5'");
    }
    const Box body = af.body_box();
    os << "<polygon points='";
    for (const auto& s :
         {Eigen::Vector2d(1, 1), Eigen::Vector2d(-1, 1), Eigen::Vector2d(-1, -1), Eigen::Vector2d(1, -1)}) {
      const Eigen::Vector2d p = W2(Eigen::Vector3d(s.x() * body.half_extents.x(), s.y() * body.half_extents.y(), 0));
      os << num(PX(p.x()), 1) << "," << num(PY(p.y()), 1) << " ";
    }
    os << "' fill='" << colour << "' fill-opacity='0.5' stroke='" << colour << "'/>\n";
    for (const auto& l : af.legs) {
      const Eigen::Vector2d p = c.xy + rot * l;
      circle(os, PX(p.x()), PY(p.y()), 3, "black");
    }
    const Eigen::Vector2d nose = c.xy + rot * Eigen::Vector2d(reach * 0.8, 0);
    os << "<line x1='" << num(PX(c.xy.x()), 1) << "' y1='" << num(PY(c.xy.y()), 1) << "' x2='" << num(PX(nose.x()), 1)
       << "' y2='" << num(PY(nose.y()), 1) << "' stroke='black' stroke-width='2' marker-end='url(#arrow)'/>\n";
    os << "<defs><marker id='arrow' markerWidth='8' markerHeight='8' refX='6' refY='4' orient='auto'>"
       << "<path d='M0,0 L8,4 L0,8 Z' fill='black'/></marker></defs>\n";
  }
  // Legend of the map.
  const double lx = L + size + 30;
  double ly = T + 6;
  auto entry = [&](const std::string& label, auto&& draw) {
    draw(lx + 8, ly);
    text(os, lx + 22, ly + 4, label);
    ly += 20;
  };
  entry("requested point", [&](double x, double y) { cross(os, x, y, 5, "black", 1.5); });
  entry("candidate, safe (fill: best S)", [&](double x, double y) { circle(os, x, y, 6, kSafe, " stroke='black'"); });
  entry("candidate, unsafe", [&](double x, double y) {
    circle(os, x, y, 6, score_colour(0.5 * thr, thr), std::string(" stroke='") + kUnsafe + "' stroke-width='2.5'");
    cross(os, x, y, 4, kUnsafe, 1.5);
  });
  entry("off the scan / not scored", [&](double x, double y) { circle(os, x, y, 5, "white", " stroke='#555'"); });
  entry("not flown (a nearer point is safe)", [&](double x, double y) { circle(os, x, y, 2, "#999"); });
  entry("unobserved terrain", [&](double x, double y) {
    os << "<rect x='" << num(x - 6, 1) << "' y='" << num(y - 6, 1) << "' width='12' height='12' fill='url(#unk)'/>\n";
  });
  entry(std::string(r.safe ? "chosen: " : "least bad: ") + "airframe at ψ*", [&](double x, double y) {
    os << "<rect x='" << num(x - 5, 1) << "' y='" << num(y - 5, 1) << "' width='10' height='10' fill='"
       << (r.safe ? kSafe : kUnsafe) << "' fill-opacity='0.5'/>\n";
  });
  // Colour bar of S from 0 to the threshold.
  ly += 10;
  text(os, lx, ly, "best S [rad]");
  ly += 8;
  for (int k = 0; k < 20; ++k) {
    os << "<rect x='" << num(lx + k * 8, 1) << "' y='" << num(ly, 1) << "' width='8.5' height='12' fill='"
       << score_colour(thr * k / 19.0, thr) << "'/>\n";
  }
  text(os, lx, ly + 26, "0");
  text(os, lx + 160, ly + 26, num(thr, 3) + " (threshold)", " text-anchor='end'");
  ly += 48;
  text(os, lx, ly, "terrain height [m]");
  ly += 8;
  for (int k = 0; k < 20; ++k) {
    const int g = static_cast<int>(90 + 150 * k / 19.0);
    char fill[16];
    std::snprintf(fill, sizeof fill, "#%02x%02x%02x", g, g, std::min(255, g + 15));
    os << "<rect x='" << num(lx + k * 8, 1) << "' y='" << num(ly, 1) << "' width='8.5' height='12' fill='" << fill
       << "'/>\n";
  }
  text(os, lx, ly + 26, num(zlo, 3));
  text(os, lx + 160, ly + 26, num(zhi, 3), " text-anchor='end'");
  os << "</svg>\n";
  return os.str();
}

}  // namespace touchdown::twin
