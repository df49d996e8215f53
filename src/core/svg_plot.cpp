#include "svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "format.hpp"
#include "touchdown/core/xml.hpp"

namespace touchdown::detail {
namespace {

constexpr const char* kGrid = "#e5e5e5";
constexpr double kTickMark = 5;      // px outside the frame
constexpr double kXLabelBelow = 18;  // baseline of x tick labels below the frame
constexpr double kXTitleBelow = 36;  // baseline of the x title below the frame
constexpr double kYLabelLeft = 6;    // end of y tick labels left of the frame
constexpr double kYTitleLeft = 52;   // centre of the upright y title left of the frame
constexpr double kCharWidth = 7;     // px per character of 12 px sans-serif, about

std::string tick_label(double v, const PlotAxis& a) {
  return format_trimmed(v, a.decimals >= 0 ? a.decimals : step_decimals(a.step));
}

// Characters (UTF-8 code points) of a label: its width in a row legend.
double label_chars(std::string_view s) {
  double n = 0;
  for (const char c : s) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80 ? 1 : 0;
  return n;
}

}  // namespace

double nice_step(double span, int intervals) {
  const double raw = span / intervals;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 2.5, 5.0}) {
    if (m * p >= raw * 0.999) return m * p;
  }
  return 10 * p;
}

double degree_step(double span_deg, int max_intervals) {
  for (const double s : {5.0, 10.0, 15.0, 30.0, 45.0, 60.0, 90.0}) {
    if (span_deg / s <= max_intervals + 1e-9) return s;
  }
  return 90.0;
}

int step_decimals(double step) {
  int d = 0;
  for (double scaled = std::abs(step); d < 9; ++d, scaled *= 10) {
    if (std::abs(scaled - std::round(scaled)) <= 1e-9 * std::max(1.0, scaled)) break;
  }
  return d;
}

std::vector<double> ticks(double lo, double hi, double step) {
  std::vector<double> out;
  if (!(step > 0) || !std::isfinite(lo) || !std::isfinite(hi)) return out;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) out.push_back(v);
  return out;
}

std::string rgb_colour(int red, int green, int blue) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", std::clamp(red, 0, 255), std::clamp(green, 0, 255),
                std::clamp(blue, 0, 255));
  return buf;
}

PlotAxis fit_axis(double lo, double hi, int intervals, std::string title) {
  PlotAxis a;
  a.step = nice_step(hi - lo, intervals);
  a.lo = std::floor(lo / a.step + 1e-9) * a.step;
  a.hi = std::ceil(hi / a.step - 1e-9) * a.step;
  a.title = std::move(title);
  return a;
}

double PlotFrame::px(double v) const {
  const double d = (right - left) * (v - x.lo) / (x.hi - x.lo);
  return x.reversed ? right - d : left + d;
}

double PlotFrame::py(double v) const {
  const double d = (bottom - top) * (v - y.lo) / (y.hi - y.lo);
  return y.reversed ? top + d : bottom - d;
}

std::vector<Eigen::Vector2d> PlotFrame::to_pixels(const std::vector<double>& xs, const std::vector<double>& ys) const {
  std::vector<Eigen::Vector2d> out;
  const std::size_t n = std::min(xs.size(), ys.size());
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) out.emplace_back(px(xs[i]), py(ys[i]));
  return out;
}

// --------------------------------------------------------------- writer --

SvgWriter::SvgWriter(double width, double height) : width_(width), height_(height) {
  out_ = "<svg xmlns='http://www.w3.org/2000/svg' width='" + number(width) + "' height='" + number(height) +
         "' font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' fill='white'/>\n";
}

std::string SvgWriter::number(double v) { return format_trimmed(v, 1); }

std::string SvgWriter::point(double x, double y) { return number(x) + "," + number(y); }

void SvgWriter::title(std::string_view text, double y) {
  this->text(width_ / 2, y, text, " text-anchor='middle' font-size='14'");
}

void SvgWriter::text(double x, double y, std::string_view text, std::string_view attributes) {
  out_ += "<text x='" + number(x) + "' y='" + number(y) + "'";
  out_ += attributes;
  out_ += ">" + xml_escape(text) + "</text>\n";
}

void SvgWriter::line(double x1, double y1, double x2, double y2, std::string_view attributes) {
  out_ += "<line x1='" + number(x1) + "' y1='" + number(y1) + "' x2='" + number(x2) + "' y2='" + number(y2) + "'";
  out_ += attributes;
  out_ += "/>\n";
}

void SvgWriter::rect(double x, double y, double width, double height, std::string_view attributes) {
  out_ +=
      "<rect x='" + number(x) + "' y='" + number(y) + "' width='" + number(width) + "' height='" + number(height) + "'";
  out_ += attributes;
  out_ += "/>\n";
}

void SvgWriter::circle(double cx, double cy, double r, std::string_view attributes) {
  out_ += "<circle cx='" + number(cx) + "' cy='" + number(cy) + "' r='" + number(r) + "'";
  out_ += attributes;
  out_ += "/>\n";
}

void SvgWriter::polyline(const std::vector<Eigen::Vector2d>& points, std::string_view attributes) {
  point_list("polyline", points, attributes);
}

void SvgWriter::polygon(const std::vector<Eigen::Vector2d>& points, std::string_view attributes) {
  if (points.size() >= 3) point_list("polygon", points, attributes);
}

void SvgWriter::point_list(std::string_view element, const std::vector<Eigen::Vector2d>& points,
                           std::string_view attributes) {
  out_ += "<";
  out_ += element;
  out_ += attributes;
  out_ += " points='";
  for (const auto& p : points) out_ += point(p.x(), p.y()) + " ";
  out_ += "'/>\n";
}

void SvgWriter::path(std::string_view d, std::string_view attributes) {
  out_ += "<path d='";
  out_ += d;
  out_ += "'";
  out_ += attributes;
  out_ += "/>\n";
}

void SvgWriter::diamond(double x, double y, double r, std::string_view attributes) {
  path("M" + point(x, y - r) + " L" + point(x + r, y) + " L" + point(x, y + r) + " L" + point(x - r, y) + " Z",
       attributes);
}

void SvgWriter::cross(double x, double y, double r, std::string_view attributes) {
  path("M" + point(x - r, y - r) + " L" + point(x + r, y + r) + " M" + point(x - r, y + r) + " L" + point(x + r, y - r),
       attributes);
}

void SvgWriter::triangle(double x, double y, double r, std::string_view attributes) {
  path("M" + point(x, y - r) + " L" + point(x + r, y + r) + " L" + point(x - r, y + r) + " Z", attributes);
}

void SvgWriter::square(double x, double y, double r, std::string_view attributes) {
  rect(x - r, y - r, 2 * r, 2 * r, attributes);
}

void SvgWriter::axes(const PlotFrame& f) {
  const std::string grid = std::string(" stroke='") + kGrid + "'";
  for (const double v : ticks(f.y.lo, f.y.hi, f.y.step)) {
    const double y = f.py(v);
    if (f.y.grid) line(f.left, y, f.right, y, grid);
    if (f.y.tick_marks) line(f.left - kTickMark, y, f.left, y, " stroke='black'");
    text(f.left - kYLabelLeft, y + 4, tick_label(v, f.y), " text-anchor='end'");
  }
  for (const double v : ticks(f.x.lo, f.x.hi, f.x.step)) {
    const double x = f.px(v);
    if (f.x.grid) line(x, f.top, x, f.bottom, grid);
    if (f.x.tick_marks) line(x, f.bottom, x, f.bottom + kTickMark, " stroke='black'");
    text(x, f.bottom + kXLabelBelow, tick_label(v, f.x), " text-anchor='middle'");
  }
  rect(f.left, f.top, f.width(), f.height(), " fill='none' stroke='black'");
  if (!f.x.title.empty()) text((f.left + f.right) / 2, f.bottom + kXTitleBelow, f.x.title, " text-anchor='middle'");
  if (!f.y.title.empty()) {
    const double x = f.left - kYTitleLeft, y = (f.top + f.bottom) / 2;
    text(x, y, f.y.title, " transform='rotate(-90 " + point(x, y) + ")' text-anchor='middle'");
  }
}

void SvgWriter::begin_clip(double x, double y, double width, double height) {
  const std::string id = "clip" + std::to_string(clips_++);
  out_ += "<clipPath id='" + id + "'>";
  rect(x, y, width, height, "");
  out_ += "</clipPath>\n<g clip-path='url(#" + id + ")'>\n";
}

void SvgWriter::end_clip() { out_ += "</g>\n"; }

void SvgWriter::raw(std::string_view svg) { out_ += svg; }

std::string SvgWriter::finish() {
  out_ += "</svg>\n";
  return std::move(out_);
}

// --------------------------------------------------------------- legend --

SvgLegend::SvgLegend(SvgWriter& svg, double x, double y, double spacing, Flow flow)
    : svg_(svg), x_(x), y_(y), spacing_(spacing), flow_(flow) {}

void SvgLegend::advance(std::string_view label) {
  if (flow_ == Flow::Column) {
    y_ += spacing_;
  } else {
    x_ += 22 + kCharWidth * label_chars(label) + spacing_;
  }
}

}  // namespace touchdown::detail
