// Figures of a mission and of the envelope (mission_plot.hpp).
#include "touchdown/mission/mission_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>

#include "core/format.hpp"
#include "core/svg_plot.hpp"

namespace touchdown::mission {
namespace {

using detail::fit_axis;
using detail::PlotFrame;
using detail::SvgLegend;
using detail::SvgWriter;

// The colours of the series (drone, estimate, setpoint, pad) and of the
// states (searching … shutdown).
namespace palette = touchdown::detail::palette;
constexpr std::array<const char*, 4> kSeries{palette::kBlue, palette::kGreen, palette::kRed, palette::kGrey};
constexpr std::array<const char*, 5> kStates{palette::kLight, palette::kPurple, palette::kCyan, palette::kOrange,
                                             palette::kInk};

std::string stroke(const char* colour, double width = 1.4, const char* dash = nullptr) {
  std::string s =
      std::string(" fill='none' stroke='") + colour + "' stroke-width='" + detail::format_trimmed(width, 1) + "'";
  if (dash) s += std::string(" stroke-dasharray='") + dash + "'";
  return s;
}

// The state changes as vertical lines across a time frame, labelled on the
// first panel.
void mark_states(SvgWriter& svg, const PlotFrame& f, const MissionResult& r, bool label) {
  int row = 0;
  for (const Transition& tr : r.transitions) {
    const double x = f.px(tr.t);
    if (x < f.left || x > f.right) continue;
    const char* colour = kStates[static_cast<std::size_t>(tr.to)];
    svg.line(x, f.top, x, f.bottom, stroke(colour, 1.2, "4,3"));
    if (label) {
      svg.text(x + 3, f.top + 12 + 11 * (row++ % 3), std::string(to_string(tr.to)),
               std::string(" font-size='10' fill='") + colour + "'");
    }
  }
}

// Three panels (x, y, z) of series picked from the trace by `get`.
std::string three_panels(const MissionResult& r, const std::string& title, const std::string& unit,
                         const std::array<std::function<Eigen::Vector3d(const MissionSample&)>, 4>& get,
                         const std::array<const char*, 4>& names) {
  SvgWriter svg(900, 720);
  svg.title(title);
  const auto& tr = r.trace;
  const double t_end = tr.empty() ? 1.0 : std::max(tr.back().t, 1.0);
  std::vector<double> ts;
  for (const auto& s : tr) ts.push_back(s.t);
  const char* axis_names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    double lo = 1e300, hi = -1e300;
    std::array<std::vector<double>, 4> ys;
    for (std::size_t k = 0; k < 4; ++k) {
      if (!get[k]) continue;
      for (const auto& s : tr) {
        const double v = get[k](s)[axis];
        ys[k].push_back(v);
        if (std::isfinite(v)) {
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
    }
    if (!(hi > lo)) {
      lo -= 1;
      hi += 1;
    }
    const double top = 40 + axis * 220.0;
    PlotFrame f{70,
                top,
                760,
                top + 180,
                fit_axis(0, t_end, 8, axis == 2 ? "t [s]" : ""),
                fit_axis(lo, hi, 4, std::string(axis_names[axis]) + " " + unit)};
    svg.axes(f);
    mark_states(svg, f, r, axis == 0);
    for (std::size_t k = 0; k < 4; ++k) {
      if (ys[k].empty()) continue;
      svg.polyline(f.to_pixels(ts, ys[k]), stroke(kSeries[k], k == 0 ? 1.8 : 1.2, k == 2 ? "5,3" : nullptr));
    }
  }
  SvgLegend legend(svg, 772, 60);
  for (std::size_t k = 0; k < 4; ++k) {
    if (!get[k]) continue;
    legend.entry(names[k], [&](double x, double y) { svg.line(x - 8, y, x + 8, y, stroke(kSeries[k], 2)); });
  }
  for (std::size_t s = 0; s < kStates.size(); ++s) {
    legend.entry(std::string(to_string(static_cast<MissionState>(s))),
                 [&](double x, double y) { svg.line(x, y - 7, x, y + 7, stroke(kStates[s], 1.5, "4,3")); });
  }
  return svg.finish();
}

}  // namespace

std::string plot_positions(const MissionResult& r, const std::string& title) {
  return three_panels(
      r, "Positions: " + title, "[m]",
      {[](const MissionSample& s) { return s.drone; }, [](const MissionSample& s) { return s.estimate; },
       [](const MissionSample& s) { return s.setpoint; }, [](const MissionSample& s) { return s.pad; }},
      {"drone", "estimate", "setpoint", "pad"});
}

std::string plot_velocities(const MissionResult& r, const std::string& title) {
  return three_panels(
      r, "Velocities: " + title, "[m/s]",
      {[](const MissionSample& s) { return s.drone_v; }, [](const MissionSample& s) { return s.estimate_v; },
       [](const MissionSample& s) { return s.setpoint_v; }, [](const MissionSample& s) { return s.pad_v; }},
      {"drone", "estimate", "setpoint", "pad"});
}

std::string plot_errors(const MissionResult& r, const std::string& title) {
  SvgWriter svg(940, 420);
  svg.title("Errors: " + title);
  const auto& tr = r.trace;
  const double t_end = tr.empty() ? 1.0 : std::max(tr.back().t, 1.0);
  std::vector<double> ts, pose_t, pose, track;
  double hi = 0.05;
  for (const auto& s : tr) {
    ts.push_back(s.t);
    track.push_back(s.tracking_error);
    if (s.pose_error >= 0) {
      pose_t.push_back(s.t);
      pose.push_back(s.pose_error);
    }
  }
  // The y range: to the 99th percentile of both, so that a start-up spike
  // does not flatten the rest.
  std::vector<double> all = track;
  all.insert(all.end(), pose.begin(), pose.end());
  if (!all.empty()) {
    std::sort(all.begin(), all.end());
    hi = std::max(hi, all[static_cast<std::size_t>(0.99 * static_cast<double>(all.size() - 1))]);
  }
  PlotFrame f{70, 40, 760, 370, fit_axis(0, t_end, 8, "t [s]"), fit_axis(0, hi, 5, "error [m]")};
  svg.axes(f);
  mark_states(svg, f, r, true);
  svg.begin_clip(f.left, f.top, f.width(), f.height());
  svg.polyline(f.to_pixels(ts, track), stroke(kSeries[2], 1.2));
  svg.polyline(f.to_pixels(pose_t, pose), stroke(kSeries[1], 1.2));
  svg.end_clip();
  SvgLegend legend(svg, 772, 60);
  legend.entry("tracking error", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, stroke(kSeries[2], 2)); });
  legend.entry("pose error", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, stroke(kSeries[1], 2)); });
  return svg.finish();
}

std::string plot_top_view(const MissionResult& r, const std::string& title) {
  SvgWriter svg(760, 700);
  svg.title("Top view: " + title);
  const auto& tr = r.trace;
  std::vector<double> dx, dy, px, py;
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const auto& s : tr) {
    dx.push_back(s.drone.x());
    dy.push_back(s.drone.y());
    px.push_back(s.pad.x());
    py.push_back(s.pad.y());
    for (const Eigen::Vector3d& p : {s.drone, s.pad}) {
      x_lo = std::min(x_lo, p.x());
      x_hi = std::max(x_hi, p.x());
      y_lo = std::min(y_lo, p.y());
      y_hi = std::max(y_hi, p.y());
    }
  }
  if (tr.empty()) x_lo = y_lo = -1, x_hi = y_hi = 1;
  // Equal scales on both axes.
  const double span = std::max({x_hi - x_lo, y_hi - y_lo, 1.0}) * 1.05;
  const double cx = 0.5 * (x_lo + x_hi), cy = 0.5 * (y_lo + y_hi);
  PlotFrame f{70,
              40,
              610,
              580,
              fit_axis(cx - span / 2, cx + span / 2, 6, "x [m]"),
              fit_axis(cy - span / 2, cy + span / 2, 6, "y [m]")};
  // fit_axis widens each to whole ticks: equalise the spans again.
  const double sx = f.x.hi - f.x.lo, sy = f.y.hi - f.y.lo;
  if (sx > sy) {
    f.y.lo -= (sx - sy) / 2;
    f.y.hi += (sx - sy) / 2;
  } else {
    f.x.lo -= (sy - sx) / 2;
    f.x.hi += (sy - sx) / 2;
  }
  svg.axes(f);
  svg.polyline(f.to_pixels(px, py), stroke(kSeries[3], 2.0));
  svg.polyline(f.to_pixels(dx, dy), stroke(kSeries[0], 1.4));
  // State changes: a dot on both paths at the time of the change.
  std::size_t k = 0;
  for (const Transition& t : r.transitions) {
    while (k + 1 < tr.size() && tr[k].t < t.t) ++k;
    if (tr.empty()) break;
    const char* colour = kStates[static_cast<std::size_t>(t.to)];
    svg.circle(f.px(tr[k].drone.x()), f.py(tr[k].drone.y()), 5, std::string(" fill='") + colour + "' stroke='black'");
    svg.circle(f.px(tr[k].pad.x()), f.py(tr[k].pad.y()), 3.5, std::string(" fill='") + colour + "'");
  }
  if (!tr.empty()) {
    svg.square(f.px(dx.front()), f.py(dy.front()), 5, " fill='white' stroke='black'");
    svg.square(f.px(px.front()), f.py(py.front()), 5, std::string(" fill='white' stroke='") + palette::kGrey + "'");
  }
  SvgLegend legend(svg, 622, 60);
  legend.entry("drone", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, stroke(kSeries[0], 2)); });
  legend.entry("pad", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, stroke(kSeries[3], 2)); });
  legend.entry("start", [&](double x, double y) { svg.square(x, y, 5, " fill='white' stroke='black'"); });
  for (std::size_t s = 1; s < kStates.size(); ++s) {
    legend.entry("→ " + std::string(to_string(static_cast<MissionState>(s))), [&](double x, double y) {
      svg.circle(x, y, 5, std::string(" fill='") + kStates[s] + "' stroke='black'");
    });
  }
  svg.text(70, 650,
           std::string("outcome: ") + std::string(to_string(r.outcome)) +
               (std::isfinite(r.touchdown_error)
                    ? ", " + detail::format_trimmed(r.touchdown_error * 100, 1) + " cm from the pad centre"
                    : ""));
  return svg.finish();
}

namespace {

// A failure reason short enough for an envelope cell: the guard of an
// abort, "crashed", or "timeout (<state>)".
std::string short_reason(const std::string& why) {
  if (why.rfind("gave up: ", 0) == 0) return why.substr(9);
  if (why.rfind("crashed", 0) == 0) return "crashed";
  if (why.rfind("timeout in ", 0) == 0) return "timeout (" + why.substr(11, why.find(' ', 11) - 11) + ")";
  return why;
}

// The failure mix's colours: one per guard that most often ends a
// mission, crashes black, the rest grey (legend text, failure_reason key).
struct MixColour {
  const char* legend;
  const char* key;
  const char* colour;
};
constexpr std::array<MixColour, 9> kMix{{{"landed", "", "#1b7837"},
                                         {"crashed", "crashed", "#000000"},
                                         {"not stable", "not_stable", "#6a3d9a"},
                                         {"wind too strong", "wind_too_strong", "#1f78b4"},
                                         {"vehicle accelerating", "vehicle_accelerating", "#a6cee3"},
                                         {"plan infeasible", "plan_infeasible", "#ff7f00"},
                                         {"pose lost", "pose_lost", "#b15928"},
                                         {"low off centre", "low_off_centre", "#e31a1c"},
                                         {"timeout / other", "timeout", "#bdbdbd"}}};

// The failure mix's colour of a reason (failure_reason's text).
const char* mix_colour(const std::string& why) {
  const std::string key = short_reason(why);
  for (const MixColour& m : kMix) {
    if (*m.key != '\0' && key.rfind(m.key, 0) == 0) return m.colour;
  }
  return "#bdbdbd";  // timeout / other
}

}  // namespace

std::string plot_envelope(const std::vector<EnvelopeCell>& cells, const std::string& title) {
  SvgWriter svg(760, 560);
  svg.title("Landing envelope: " + title);
  std::vector<double> speeds, winds;
  for (const auto& c : cells) {
    if (std::find(speeds.begin(), speeds.end(), c.speed) == speeds.end()) speeds.push_back(c.speed);
    if (std::find(winds.begin(), winds.end(), c.wind) == winds.end()) winds.push_back(c.wind);
  }
  std::sort(speeds.begin(), speeds.end());
  std::sort(winds.begin(), winds.end());
  const double L = 90, T = 50, W = 520, H = 420;
  const double cw = W / static_cast<double>(std::max<std::size_t>(1, speeds.size()));
  const double ch = H / static_cast<double>(std::max<std::size_t>(1, winds.size()));
  for (const auto& c : cells) {
    const auto i = static_cast<double>(std::find(speeds.begin(), speeds.end(), c.speed) - speeds.begin());
    const auto j = static_cast<double>(std::find(winds.begin(), winds.end(), c.wind) - winds.begin());
    // Red (0 %) through yellow to green (100 %).
    const double s = c.success();
    const int red = s < 0.5 ? 215 : static_cast<int>(215 - (s - 0.5) * 2 * 170);
    const int green = s < 0.5 ? static_cast<int>(60 + s * 2 * 150) : 190;
    const double x = L + i * cw, y = T + H - (j + 1) * ch;
    if (!c.valid) {
      svg.rect(x, y, cw, ch, std::string(" fill='") + palette::kLight + "' stroke='white'");
      svg.text(x + cw / 2, y + ch / 2 + 4, "n/a", " text-anchor='middle' font-size='12' fill='#666'");
      continue;
    }
    svg.rect(x, y, cw, ch, " fill='" + detail::rgb_colour(red, green, 60) + "' stroke='white'");
    svg.text(x + cw / 2, y + ch / 2 + (c.reasons.empty() ? 4 : -4), detail::format_trimmed(100 * s, 0) + " %",
             " text-anchor='middle' font-size='12'");
    if (!c.reasons.empty()) {
      // The most frequent reason the others did not land, shortened to fit:
      // its count, then the reason in words on a line of its own.
      std::string why = short_reason(c.reasons.front().first);
      std::replace(why.begin(), why.end(), '_', ' ');
      svg.text(x + cw / 2, y + ch / 2 + 9, std::to_string(c.reasons.front().second) + " \u00d7",
               " text-anchor='middle' font-size='9'");
      svg.text(x + cw / 2, y + ch / 2 + 19, why,
               std::string(" text-anchor='middle' font-size='") + (why.size() > 17 ? "7.5" : "8.5") + "'");
      // The failure mix: a bar of every run, landed first, then each reason.
      const double bx = x + 4, bw = cw - 8, by = y + ch - 10;
      double at = bx;
      const auto segment = [&](int n, const std::string& colour) {
        const double width = bw * n / std::max(1, c.runs);
        svg.rect(at, by, width, 6, " fill='" + colour + "' stroke='none'");
        at += width;
      };
      segment(c.landed, "#1b7837");
      for (const auto& [reason, n] : c.reasons) segment(n, mix_colour(reason));
      svg.rect(bx, by, bw, 6, " fill='none' stroke='white' stroke-width='0.5'");
    }
  }
  svg.rect(L, T, W, H, " fill='none' stroke='black'");
  for (std::size_t i = 0; i < speeds.size(); ++i) {
    svg.text(L + (static_cast<double>(i) + 0.5) * cw, T + H + 18, detail::format_trimmed(speeds[i], 2),
             " text-anchor='middle'");
  }
  for (std::size_t j = 0; j < winds.size(); ++j) {
    svg.text(L - 8, T + H - (static_cast<double>(j) + 0.5) * ch + 4, detail::format_trimmed(winds[j], 2),
             " text-anchor='end'");
  }
  svg.text(L + W / 2, T + H + 40, "vehicle speed [m/s]", " text-anchor='middle'");
  svg.text(24, T + H / 2, "wind [m/s]",
           " text-anchor='middle' transform='rotate(-90 24 " + detail::format_trimmed(T + H / 2, 1) + ")'");
  svg.text(L + W + 14, T + 14, "share landed;");
  svg.text(L + W + 14, T + 30, "below it, the most");
  svg.text(L + W + 14, T + 46, "frequent reason the");
  svg.text(L + W + 14, T + 62, "others did not land");
  svg.text(L + W + 14, T + 78, "(--json: all of them);");
  svg.text(L + W + 14, T + 94, "at the bottom, the mix:");
  for (std::size_t k = 0; k < kMix.size(); ++k) {
    const double ly = T + 108 + 16 * static_cast<double>(k);
    svg.rect(L + W + 14, ly - 8, 12, 8, std::string(" fill='") + kMix[k].colour + "'");
    svg.text(L + W + 30, ly, kMix[k].legend, " font-size='11'");
  }
  return svg.finish();
}

}  // namespace touchdown::mission
