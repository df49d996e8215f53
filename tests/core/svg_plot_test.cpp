// The SVG plot writer of src/core/svg_plot.hpp: tick steps for a few ranges
// (hand-computed), the data-to-pixel map, escaping, and a whole figure that
// parses back as XML (a small checker here, and xmllint when installed).
#include "core/svg_plot.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace {

namespace tdd = touchdown::detail;

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// Well-formed XML without a DTD: every element closed in order, attribute
// values quoted, no bare '<' or '&' in text. Returns "" or what is wrong;
// counts the elements.
std::string xml_problem(const std::string& s, std::size_t& elements) {
  std::vector<std::string> open;
  elements = 0;
  std::size_t i = 0;
  while (i < s.size()) {
    if (s[i] == '&') {
      const auto semi = s.find(';', i);
      const std::string entity = semi == std::string::npos ? "" : s.substr(i, semi - i + 1);
      if (entity != "&amp;" && entity != "&lt;" && entity != "&gt;" && entity != "&apos;" && entity != "&quot;") {
        return "bare & at " + std::to_string(i);
      }
      i = semi + 1;
      continue;
    }
    if (s[i] != '<') {
      if (s[i] == '>') return "bare > at " + std::to_string(i);
      ++i;
      continue;
    }
    const bool closing = i + 1 < s.size() && s[i + 1] == '/';
    std::size_t j = i + (closing ? 2 : 1);
    std::string name;
    while (j < s.size() && (std::isalnum(static_cast<unsigned char>(s[j])) || s[j] == '-' || s[j] == ':')) {
      name += s[j++];
    }
    if (name.empty()) return "tag without a name at " + std::to_string(i);
    // Attributes: name='value' or name="value", until > or />.
    while (j < s.size() && s[j] != '>' && !(s[j] == '/' && j + 1 < s.size() && s[j + 1] == '>')) {
      if (s[j] == '\'' || s[j] == '"') {
        const auto end = s.find(s[j], j + 1);
        if (end == std::string::npos) return "unterminated attribute in <" + name + ">";
        const std::string value = s.substr(j + 1, end - j - 1);
        if (value.find('<') != std::string::npos) return "< in an attribute of <" + name + ">";
        j = end + 1;
      } else {
        ++j;
      }
    }
    if (j >= s.size()) return "unterminated tag <" + name + ">";
    const bool self_closing = s[j] == '/';
    i = j + (self_closing ? 2 : 1);
    if (closing) {
      if (open.empty() || open.back() != name)
        return "</" + name + "> closes " + (open.empty() ? "nothing" : open.back());
      open.pop_back();
    } else {
      ++elements;
      if (!self_closing) open.push_back(name);
    }
  }
  return open.empty() ? "" : "<" + open.back() + "> not closed";
}

TEST(SvgTicks, NiceStepsOfOneTwoTwoAndAHalfFive) {
  EXPECT_DOUBLE_EQ(tdd::nice_step(1.0, 5), 0.2);     // 0.2 exactly what is asked
  EXPECT_DOUBLE_EQ(tdd::nice_step(10.0, 6), 2.0);    // 1.67 → 2
  EXPECT_DOUBLE_EQ(tdd::nice_step(3.0, 6), 0.5);     // 0.5
  EXPECT_DOUBLE_EQ(tdd::nice_step(1000.0, 4), 250);  // 250 = 2.5 × 10^2
  EXPECT_DOUBLE_EQ(tdd::nice_step(0.375, 6), 0.1);   // 0.0625 → 0.1 (none of 0.01..0.05 reaches it)
  EXPECT_DOUBLE_EQ(tdd::nice_step(360, 8), 50);      // 45 → 50
  EXPECT_DOUBLE_EQ(tdd::nice_step(0.99, 5), 0.2);    // 0.198 → 0.2
  EXPECT_DOUBLE_EQ(tdd::nice_step(7e-4, 7), 1e-4);
}

TEST(SvgTicks, DegreeSteps) {
  EXPECT_EQ(tdd::degree_step(360, 8), 45);
  EXPECT_EQ(tdd::degree_step(180, 8), 30);  // 15 would give 12 intervals
  EXPECT_EQ(tdd::degree_step(40, 8), 5);
  EXPECT_EQ(tdd::degree_step(90, 6), 15);
  EXPECT_EQ(tdd::degree_step(1000, 8), 90);  // none fits: the largest
}

TEST(SvgTicks, DecimalsOfAStep) {
  EXPECT_EQ(tdd::step_decimals(0.25), 2);
  EXPECT_EQ(tdd::step_decimals(0.1), 1);
  EXPECT_EQ(tdd::step_decimals(0.05), 2);
  EXPECT_EQ(tdd::step_decimals(2.5), 1);
  EXPECT_EQ(tdd::step_decimals(50), 0);
  EXPECT_EQ(tdd::step_decimals(1e-3), 3);
  EXPECT_EQ(tdd::step_decimals(1.0 / 3), 9);  // no finite decimal: capped
}

TEST(SvgTicks, MultiplesOfTheStepInTheRange) {
  const auto t = tdd::ticks(-0.3, 1.05, 0.25);
  ASSERT_EQ(t.size(), 6u);
  const double expected[] = {-0.25, 0, 0.25, 0.5, 0.75, 1.0};
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_NEAR(t[i], expected[i], 1e-12);
  const auto deg = tdd::ticks(0, 360, 45);
  ASSERT_EQ(deg.size(), 9u);
  EXPECT_EQ(deg.back(), 360);                       // the end is a tick
  EXPECT_EQ(tdd::ticks(0.1, 0.6, 0.1).size(), 6u);  // 0.1 + ... + 0.1 passes 0.6 by a rounding: still a tick
  EXPECT_TRUE(tdd::ticks(0, 1, 0).empty());
}

TEST(SvgTicks, FittedAxisEndsOnTicks) {
  const tdd::PlotAxis a = tdd::fit_axis(0.13, 0.92, 5, "z [m]");
  EXPECT_DOUBLE_EQ(a.step, 0.2);
  EXPECT_DOUBLE_EQ(a.lo, 0.0);
  EXPECT_DOUBLE_EQ(a.hi, 1.0);
  EXPECT_EQ(a.title, "z [m]");
  const tdd::PlotAxis b = tdd::fit_axis(-3.1, 7.4, 5, "");
  EXPECT_DOUBLE_EQ(b.step, 2.5);
  EXPECT_DOUBLE_EQ(b.lo, -5.0);
  EXPECT_DOUBLE_EQ(b.hi, 7.5);
}

TEST(SvgTicks, Colours) {
  EXPECT_EQ(tdd::rgb_colour(255, 0, 16), "#ff0010");
  EXPECT_EQ(tdd::rgb_colour(300, -5, 128), "#ff0080");
}

TEST(SvgPlot, FrameMapsDataToPixels) {
  tdd::PlotFrame f;
  f.left = 100;
  f.top = 50;
  f.right = 500;
  f.bottom = 250;
  f.x.lo = 0;
  f.x.hi = 10;
  f.y.lo = -1;
  f.y.hi = 1;
  EXPECT_DOUBLE_EQ(f.px(0), 100);
  EXPECT_DOUBLE_EQ(f.px(10), 500);
  EXPECT_DOUBLE_EQ(f.px(2.5), 200);
  EXPECT_DOUBLE_EQ(f.py(-1), 250);  // y up
  EXPECT_DOUBLE_EQ(f.py(1), 50);
  EXPECT_DOUBLE_EQ(f.py(0), 150);
  f.x.reversed = true;
  EXPECT_DOUBLE_EQ(f.px(0), 500);
  EXPECT_DOUBLE_EQ(f.px(10), 100);
  const auto p = f.to_pixels({0, 5}, {1, -1});
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1], Eigen::Vector2d(300, 250));
}

TEST(SvgPlot, EscapesText) {
  tdd::SvgWriter svg(100, 100);
  svg.title("a & b < c > d's");
  svg.text(1, 2, "x<y");
  const std::string s = svg.finish();
  EXPECT_NE(s.find(">a &amp; b &lt; c &gt; d&apos;s</text>"), std::string::npos) << s;
  EXPECT_NE(s.find(">x&lt;y</text>"), std::string::npos) << s;
}

TEST(SvgPlot, NumbersWithOneDecimalTrimmed) {
  EXPECT_EQ(tdd::SvgWriter::number(12.25), "12.2");
  EXPECT_EQ(tdd::SvgWriter::number(40.0), "40");
  EXPECT_EQ(tdd::SvgWriter::number(-0.01), "0");
  EXPECT_EQ(tdd::SvgWriter::point(1.06, -2), "1.1,-2");
}

TEST(SvgPlot, AxesDrawTicksLabelsAndTitles) {
  tdd::SvgWriter svg(400, 300);
  tdd::PlotFrame f{70, 40, 370, 240, tdd::fit_axis(0, 10, 5, "t [s]"), tdd::fit_axis(-1, 1, 4, "v [m/s]")};
  f.y.grid = false;
  svg.axes(f);
  const std::string s = svg.finish();
  // x: 0, 2, ..., 10 (6 ticks, grid and mark each); y: -1, -0.5, ..., 1 (5 ticks, mark only).
  EXPECT_EQ(count(s, "<line"), 6u * 2 + 5u);
  EXPECT_NE(s.find(">-0.5</text>"), std::string::npos) << s;
  EXPECT_NE(s.find(">10</text>"), std::string::npos) << s;
  EXPECT_NE(s.find("text-anchor='middle'>t [s]</text>"), std::string::npos) << s;
  EXPECT_NE(s.find("transform='rotate(-90 18,140)' text-anchor='middle'>v [m/s]</text>"), std::string::npos) << s;
  EXPECT_EQ(count(s, "<rect"), 2u);  // background and frame
}

TEST(SvgPlot, AWholeFigureIsWellFormed) {
  tdd::SvgWriter svg(640, 400);
  svg.title("Velocity & acceleration: <landing.yaml>");
  tdd::PlotFrame f{70, 40, 500, 340, tdd::fit_axis(0, 5.5, 6, "t [s]"), tdd::fit_axis(-4, 4, 4, "v [m/s]")};
  svg.axes(f);
  svg.begin_clip(f.left, f.top, f.width(), f.height());
  svg.polyline(f.to_pixels({0, 1, 2, 3}, {0, 1, -1, 2}), " fill='none' stroke='#1f77b4' stroke-width='1.5'");
  svg.polygon(f.to_pixels({0, 1, 1}, {0, 0, 1}), " fill='#ff7f0e' fill-opacity='0.3'");
  svg.polygon(f.to_pixels({0, 1}, {0, 0}), " fill='red'");  // fewer than 3 points: nothing
  svg.end_clip();
  svg.diamond(100, 100, 4, " fill='red'");
  svg.cross(110, 100, 4, " stroke='black' stroke-width='2'");
  svg.triangle(120, 100, 4, " fill='#666'");
  svg.square(130, 100, 3, " fill='white' stroke='black'");
  svg.circle(140, 100, 2, " fill='#888'");
  tdd::SvgLegend legend(svg, 510, 50);
  legend.entry("v_x [m/s]", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, " stroke='#1f77b4'"); });
  legend.entry("limit & margin", [&](double x, double y) { svg.line(x - 8, y, x + 8, y, " stroke='black'"); });
  EXPECT_DOUBLE_EQ(legend.y(), 50 + 2 * 19);
  tdd::SvgLegend row(svg, 70, 380, 18, tdd::SvgLegend::Flow::Row);
  row.entry("ab", [&](double x, double y) { svg.circle(x, y, 3, " fill='red'"); });
  EXPECT_DOUBLE_EQ(row.x(), 70 + 22 + 2 * 7 + 18);
  const std::string s = svg.finish();

  std::size_t elements = 0;
  EXPECT_EQ(xml_problem(s, elements), "");
  EXPECT_EQ(count(s, "<polygon"), 1u);
  EXPECT_EQ(count(s, "<polyline"), 1u);
  EXPECT_EQ(count(s, "<clipPath"), 1u);
  EXPECT_EQ(count(s, "<path"), 3u);
  EXPECT_GT(elements, 40u);
  EXPECT_EQ(s.rfind("<svg", 0), 0u);
  EXPECT_EQ(s.substr(s.size() - 7), "</svg>\n");

  // An independent parser, where installed.
  if (std::system("xmllint --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "xmllint not installed";
  const touchdown::test::TempDir dir;  // its own directory: ctest -j runs tests side by side
  const auto path = dir / "plot.svg";
  std::ofstream(path) << s;
  EXPECT_EQ(std::system(("xmllint --noout " + path.string()).c_str()), 0);
}

TEST(SvgPlot, TheCheckerCatchesBrokenDocuments) {
  std::size_t n = 0;
  EXPECT_NE(xml_problem("<svg><g></svg>", n), "");
  EXPECT_NE(xml_problem("<svg>a & b</svg>", n), "");
  EXPECT_NE(xml_problem("<svg><text x='1>a</text></svg>", n), "");
  EXPECT_EQ(xml_problem("<svg><g/><text x='1'>a &amp; b</text></svg>", n), "");
  EXPECT_EQ(n, 3u);
}

}  // namespace
