#pragma once
// SVG figures, private to the library and its apps (not installed): the one
// writer behind every plot (the landing sweep's S(ψ) and search figures,
// landing_plan's views and time plots), so that each figure has the same
// axes, "nice" ticks, tick labels, axis titles with units, legend and title.
//
// A figure is an SvgWriter (the document: elements, markers, clipping), one
// PlotFrame per plot (a pixel rectangle and the data range of each axis,
// which maps data to pixels and draws its axes), and an SvgLegend. A line
// plot:
//
//   SvgWriter svg(640, 400);
//   svg.title("Velocity: landing.yaml");
//   PlotFrame f{70, 40, 600, 340, fit_axis(0, t_end, 6, "t [s]"), fit_axis(v_lo, v_hi, 5, "v [m/s]")};
//   svg.axes(f);
//   svg.polyline(f.to_pixels(ts, vs), " fill='none' stroke='#1f77b4' stroke-width='1.5'");
//   SvgLegend legend(svg, 610, 50);
//   legend.entry("v_x", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, " stroke='#1f77b4'"); });
//   std::string text = svg.finish();
//
// Coordinates print with one decimal, trailing zeros dropped ("12.5", "40"):
// a tenth of a pixel is below what a screen or printer shows, and the
// figures stay small and byte-stable. Text is XML-escaped; attribute text
// (" stroke='black'") is written as given, so it must be well-formed.
// Not thread-safe: one writer per figure.
#include <Eigen/Core>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::detail {

// ---------------------------------------------------------------- ticks --

/// A tick step of 1, 2, 2.5 or 5 × 10^k that cuts `span` (> 0) into about
/// `intervals` intervals: the smallest such step at least span / intervals
/// (less 0.1 %, so that 1.0 / 5 gives 0.2, not 0.25).
double nice_step(double span, int intervals);

/// A tick step for angles in degrees: the smallest of 5, 10, 15, 30, 45,
/// 60, 90 that cuts `span_deg` into at most `max_intervals` intervals (90
/// when none does).
double degree_step(double span_deg, int max_intervals = 8);

/// Decimals that print every multiple of `step` exactly (0.25 → 2, 0.1 → 1,
/// 2.5 → 1, 50 → 0); at most 9.
int step_decimals(double step);

/// The multiples of `step` (> 0) in [lo, hi], from the first upwards by
/// adding `step` (hi has 1e-9 step of slack for the sum's rounding).
std::vector<double> ticks(double lo, double hi, double step);

/// "#rrggbb", each component clamped to [0, 255].
std::string rgb_colour(int red, int green, int blue);

/// The one palette of every touchdown figure: Tableau 10's colours
/// (matplotlib's default cycle), which stay distinct for the common colour
/// vision deficiencies in this order's first four. A series, a state or a
/// verdict takes a named colour; the n-th line of a figure takes
/// kSeries[n % size].
namespace palette {
inline constexpr const char* kBlue = "#1f77b4";
inline constexpr const char* kOrange = "#ff7f0e";
inline constexpr const char* kGreen = "#2ca02c";
inline constexpr const char* kRed = "#d62728";
inline constexpr const char* kPurple = "#9467bd";
inline constexpr const char* kBrown = "#8c564b";
inline constexpr const char* kPink = "#e377c2";
inline constexpr const char* kGrey = "#7f7f7f";
inline constexpr const char* kOlive = "#bcbd22";
inline constexpr const char* kCyan = "#17becf";
/// Below the data: light grey fills, dark ink.
inline constexpr const char* kLight = "#dddddd";
inline constexpr const char* kInk = "#2c2c2c";
inline constexpr std::array<const char*, 8> kSeries{kBlue, kRed, kGreen, kOrange, kPurple, kBrown, kPink, kGrey};
}  // namespace palette

// ----------------------------------------------------------------- axes --

/// One axis of a plot frame.
struct PlotAxis {
  double lo = 0;           ///< data value at the frame's left (x) or bottom (y) edge
  double hi = 1;           ///< data value at the opposite edge; hi > lo
  double step = 0;         ///< data units between ticks; 0: no ticks
  int decimals = -1;       ///< tick labels' decimals (trailing zeros dropped); -1: step_decimals(step)
  std::string title;       ///< name and unit, "heading ψ [deg]"; empty: none
  bool grid = true;        ///< a light line across the frame at each tick
  bool tick_marks = true;  ///< a 5 px mark outside the frame at each tick
  bool reversed = false;   ///< values grow leftwards (x) or downwards (y)
};

/// An axis over [lo, hi] widened to whole ticks of nice_step(hi - lo,
/// intervals) (hi > lo).
PlotAxis fit_axis(double lo, double hi, int intervals, std::string title);

/// A rectangle of the figure in pixels (y down) and the data it shows.
struct PlotFrame {
  double left = 0, top = 0, right = 1, bottom = 1;  ///< pixels
  PlotAxis x, y;

  /// Data x to pixel x (not clamped to the frame).
  [[nodiscard]] double px(double v) const;
  /// Data y to pixel y (not clamped to the frame).
  [[nodiscard]] double py(double v) const;
  /// Data points to pixels, for polyline() and polygon().
  [[nodiscard]] std::vector<Eigen::Vector2d> to_pixels(const std::vector<double>& xs,
                                                       const std::vector<double>& ys) const;
  [[nodiscard]] double width() const { return right - left; }
  [[nodiscard]] double height() const { return bottom - top; }
};

// --------------------------------------------------------------- writer --

/// An SVG document being written. `attributes` arguments are attribute
/// text written after the element's geometry, each attribute with a leading
/// space: " stroke='black' stroke-width='2'".
class SvgWriter {
 public:
  /// Opens a `width` × `height` px document: white background, sans-serif
  /// 12 px text.
  SvgWriter(double width, double height);

  [[nodiscard]] double width() const { return width_; }
  [[nodiscard]] double height() const { return height_; }

  /// The title, centred at the top (14 px): name the input it shows.
  void title(std::string_view text, double y = 20);
  /// Text at (x, y): the baseline's start, or its middle or end with
  /// " text-anchor='middle'" or 'end'.
  void text(double x, double y, std::string_view text, std::string_view attributes = "");
  void line(double x1, double y1, double x2, double y2, std::string_view attributes);
  void rect(double x, double y, double width, double height, std::string_view attributes);
  void circle(double cx, double cy, double r, std::string_view attributes);
  void polyline(const std::vector<Eigen::Vector2d>& points, std::string_view attributes);
  /// Nothing for fewer than 3 points.
  void polygon(const std::vector<Eigen::Vector2d>& points, std::string_view attributes);
  /// A path with data `d` (see path_point()).
  void path(std::string_view d, std::string_view attributes);

  /// Markers centred at (x, y), `r` from the centre to a corner or tip:
  /// a diamond, an "x", a triangle pointing up and a square.
  void diamond(double x, double y, double r, std::string_view attributes);
  void cross(double x, double y, double r, std::string_view attributes);
  void triangle(double x, double y, double r, std::string_view attributes);
  void square(double x, double y, double r, std::string_view attributes);

  /// The frame of `f`, its ticks with grid lines and labels and its axis
  /// titles (y's turned upright, left of the tick labels). Drawn in this
  /// order: y ticks, x ticks, frame, x title, y title.
  void axes(const PlotFrame& f);

  /// What follows is clipped to the rectangle until end_clip().
  void begin_clip(double x, double y, double width, double height);
  void end_clip();

  /// SVG written as given (defs, patterns, groups).
  void raw(std::string_view svg);

  /// Closes the document and returns its text; the writer is spent.
  [[nodiscard]] std::string finish();

  /// A coordinate's text: one decimal, trailing zeros dropped.
  [[nodiscard]] static std::string number(double v);
  /// "x,y" for path data and point lists.
  [[nodiscard]] static std::string point(double x, double y);

 private:
  // <element ATTRIBUTES points='x,y x,y '/>
  void point_list(std::string_view element, const std::vector<Eigen::Vector2d>& points, std::string_view attributes);

  std::string out_;
  double width_, height_;
  int clips_ = 0;
};

/// A legend: entries one below the other (a column), or left to right (a
/// row). Each entry is a swatch that the caller draws, centred 8 px right of
/// the entry's start, and its label 22 px right of the start.
class SvgLegend {
 public:
  enum class Flow { Column, Row };

  SvgLegend(SvgWriter& svg, double x, double y, double spacing = 19, Flow flow = Flow::Column);

  /// Draws one entry: draw_swatch(x, y) draws at the swatch's centre.
  template <typename DrawSwatch>
  void entry(std::string_view label, DrawSwatch&& draw_swatch) {
    draw_swatch(x_ + 8, y_);
    svg_.text(x_ + 22, y_ + 4, label);
    advance(label);
  }

  /// Where the next entry goes (after the last one: where notes below go).
  [[nodiscard]] double x() const { return x_; }
  [[nodiscard]] double y() const { return y_; }

 private:
  void advance(std::string_view label);

  SvgWriter& svg_;
  double x_, y_, spacing_;
  Flow flow_;
};

}  // namespace touchdown::detail

template <>
struct touchdown::EnumNames<touchdown::detail::SvgLegend::Flow> {
  static constexpr std::array<std::string_view, 2> names{"column", "row"};
};

namespace touchdown::detail {

inline std::string_view to_string(SvgLegend::Flow flow) { return enum_name(flow); }

}  // namespace touchdown::detail
