// The comparison of search methods: Table 2's text and the cumulative
// violations plot (compare.hpp).
#include "touchdown/search/compare.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include "core/format.hpp"
#include "core/svg_plot.hpp"

namespace touchdown::search {
namespace {

namespace td = touchdown::detail;

std::string mean_sd_text(const std::vector<double>& v, int decimals) {
  const MeanSd s = mean_sd(v);
  return td::format_fixed(s.mean + 0.0, decimals) + " ± " + td::format_fixed(s.sd + 0.0, decimals);
}

std::string column(const CompareCell& c, const std::function<double(const SearchMetrics&)>& get, int decimals) {
  std::vector<double> v;
  v.reserve(c.per_seed.size());
  for (const SearchMetrics& m : c.per_seed) v.push_back(get(m));
  return mean_sd_text(v, decimals);
}

// A metric some seeds may not reach: over the seeds that did.
std::string found_column(const CompareCell& c, std::optional<int> SearchMetrics::*field) {
  std::vector<double> v;
  for (const SearchMetrics& m : c.per_seed) {
    if (m.*field) v.push_back(*(m.*field));
  }
  if (v.empty()) return "not found";
  std::string text = mean_sd_text(v, 0);
  if (v.size() < c.per_seed.size()) {
    text += " (" + std::to_string(v.size()) + "/" + std::to_string(c.per_seed.size()) + " found)";
  }
  return text;
}

// Over the fair counts (issue 52): "n/a" when a seed's results carry no
// facts (written before issue 52) or the cell has none.
std::string fair_column(const CompareCell& c, const std::function<double(const SearchMetrics&)>& get, int decimals) {
  if (c.per_seed_fair.empty() || c.per_seed_fair.size() != c.per_seed.size()) return "n/a";
  std::vector<double> v;
  for (const SearchMetrics& m : c.per_seed_fair) {
    if (!m.facts_recorded) return "n/a";
    v.push_back(get(m));
  }
  return mean_sd_text(v, decimals);
}

std::string causes_column(const CompareCell& c) {
  if (c.fair_causes.empty() || c.fair_causes.size() != c.per_seed.size()) return "n/a";
  std::vector<double> v;
  for (int n : c.fair_causes) {
    if (n < 0) return "n/a";
    v.push_back(n);
  }
  return mean_sd_text(v, 1);
}

// Characters, not bytes: "±" is two bytes of UTF-8.
std::size_t display_width(const std::string& s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char ch) { return (static_cast<unsigned char>(ch) & 0xC0) != 0x80; }));
}

constexpr const auto& kColours = touchdown::detail::palette::kSeries;

template <typename Get>
std::vector<std::string> distinct(const std::vector<CompareCell>& cells, Get get) {
  std::vector<std::string> out;
  for (const CompareCell& c : cells) {
    if (std::find(out.begin(), out.end(), get(c)) == out.end()) out.push_back(get(c));
  }
  return out;
}

// The mean over seeds of the cumulative violations, up to the shortest
// seed's length, with (0, 0) first.
std::vector<double> mean_curve(const CompareCell& c) {
  if (c.cumulative.empty()) return {0.0};
  std::size_t n = c.cumulative.front().size();
  for (const auto& s : c.cumulative) n = std::min(n, s.size());
  std::vector<double> out(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (const auto& s : c.cumulative) sum += s[i];
    out[i + 1] = sum / static_cast<double>(c.cumulative.size());
  }
  return out;
}

}  // namespace

MeanSd mean_sd(const std::vector<double>& v) {
  MeanSd s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  if (v.size() > 1) {
    double ss = 0;
    for (double x : v) ss += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(ss / static_cast<double>(v.size() - 1));
  }
  return s;
}

std::string compare_table(const std::vector<CompareCell>& cells, int k) {
  std::vector<std::vector<std::string>> rows;
  rows.push_back({"method", "map", "violations [%]", "Top-" + std::to_string(k), "rounds to all types",
                  "parameter distance", "3-D coverage [cells]", "Type I", "Type II", "Type III", "off-marker",
                  "fair violations [%]", "fair Type II", "distinct fair causes"});
  for (const CompareCell& c : cells) {
    rows.push_back({c.method, c.map,
                    column(
                        c, [](const SearchMetrics& m) { return m.violation_percent; }, 1),
                    found_column(c, &SearchMetrics::top_k), found_column(c, &SearchMetrics::rounds_all_types),
                    column(
                        c, [](const SearchMetrics& m) { return m.parameter_distance; }, 3),
                    column(
                        c, [](const SearchMetrics& m) { return double(m.coverage_cells); }, 0),
                    column(
                        c, [](const SearchMetrics& m) { return double(m.type_i); }, 1),
                    column(
                        c, [](const SearchMetrics& m) { return double(m.type_ii); }, 1),
                    column(
                        c, [](const SearchMetrics& m) { return double(m.type_iii); }, 1),
                    column(
                        c, [](const SearchMetrics& m) { return double(m.off_marker); }, 1),
                    fair_column(
                        c, [](const SearchMetrics& m) { return m.violation_percent; }, 1),
                    fair_column(
                        c, [](const SearchMetrics& m) { return double(m.type_ii); }, 1),
                    causes_column(c)});
  }
  std::vector<std::size_t> width(rows.front().size(), 0);
  for (const auto& row : rows) {
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], display_width(row[i]));
  }
  std::string out;
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i > 0) line += "  ";
      line += row[i];
      if (i + 1 < row.size()) line.append(width[i] - display_width(row[i]), ' ');
    }
    out += line + '\n';
  }
  return out;
}

std::string compare_plot_svg(const std::vector<CompareCell>& cells, std::string_view title) {
  const auto maps = distinct(cells, [](const CompareCell& c) { return c.map; });
  const auto methods = distinct(cells, [](const CompareCell& c) { return c.method; });
  std::vector<std::vector<double>> curves;
  double x_max = 1, y_max = 1;
  for (const CompareCell& c : cells) {
    curves.push_back(mean_curve(c));
    x_max = std::max(x_max, static_cast<double>(curves.back().size() - 1));
    y_max = std::max(y_max, curves.back().back());
  }
  std::size_t longest = 0;
  for (const auto& m : methods) longest = std::max(longest, m.size());
  const double panel = 380, left = 70, top = 60, plot_w = 300, plot_h = 290;
  const double legend_w = 50 + 7.0 * static_cast<double>(longest);
  td::SvgWriter svg(left + panel * static_cast<double>(maps.size()) - (panel - plot_w) + 20 + legend_w,
                    top + plot_h + 60);
  svg.title(title);
  const td::PlotAxis x_axis = td::fit_axis(0, x_max, 5, "scenarios evaluated");
  const td::PlotAxis y_axis = td::fit_axis(0, y_max, 5, "violations found (mean over seeds)");
  for (std::size_t p = 0; p < maps.size(); ++p) {
    const double x0 = left + panel * static_cast<double>(p);
    const td::PlotFrame f{x0, top, x0 + plot_w, top + plot_h, x_axis, y_axis};
    svg.axes(f);
    svg.text(x0 + plot_w / 2, top - 8, "map: " + maps[p], " text-anchor='middle'");
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (cells[i].map != maps[p]) continue;
      const auto m =
          static_cast<std::size_t>(std::find(methods.begin(), methods.end(), cells[i].method) - methods.begin());
      std::vector<double> xs(curves[i].size());
      for (std::size_t j = 0; j < xs.size(); ++j) xs[j] = static_cast<double>(j);
      svg.polyline(f.to_pixels(xs, curves[i]),
                   std::string(" fill='none' stroke='") + kColours[m % kColours.size()] + "' stroke-width='1.8'");
    }
  }
  const double legend_x = left + panel * static_cast<double>(maps.size()) - (panel - plot_w) + 20;
  td::SvgLegend legend(svg, legend_x, top + 10);
  for (std::size_t m = 0; m < methods.size(); ++m) {
    const std::string colour = kColours[m % kColours.size()];
    legend.entry(methods[m], [&](double x, double y) {
      svg.line(x - 8, y, x + 8, y, " stroke='" + colour + "' stroke-width='1.8'");
    });
  }
  return svg.finish();
}

}  // namespace touchdown::search
