// detect-bench's report (docs/benchmarks.md, "Marker detectors"): the
// detectors run over a dataset's frames, the figures per group of frames
// and the recall-against-distance figure.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "core/format.hpp"
#include "core/json_number.hpp"
#include "core/json_read.hpp"
#include "core/svg_plot.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/scenario/detector_bench.hpp"

namespace touchdown::scenario {

namespace {
using Json = nlohmann::ordered_json;
using detail::format_fixed;
using detail::round3;
}  // namespace

DatasetMarker read_dataset_marker(const std::filesystem::path& dataset_dir) {
  const std::filesystem::path path = dataset_dir / "dataset.json";
  std::ifstream in(path);
  if (!in) throw IoError(path.string() + ": cannot read (not a landing_scenario dataset)");
  Json meta;
  try {
    meta = Json::parse(in);
  } catch (const Json::exception&) {
    throw ParseError(path.string() + ": not JSON");
  }
  DatasetMarker m;
  try {
    m.dictionary = meta.at("marker").at("dictionary").get<std::string>();
    const Json& id = meta.at("marker").at("id");
    const std::optional<int> i = touchdown::detail::json_int(id);
    if (!i) throw ParseError(path.string() + ": marker.id: " + touchdown::detail::json_int_problem(id));
    m.id = *i;
  } catch (const Json::exception&) {
    throw ParseError(path.string() + ": marker.dictionary, marker.id: missing");
  }
  return m;
}

std::vector<std::vector<BenchFrame>> run_detector_bench(const std::filesystem::path& dataset_dir,
                                                        const std::vector<BenchLabel>& labels,
                                                        const DatasetMarker& marker,
                                                        const std::vector<std::unique_ptr<MarkerDetector>>& detectors,
                                                        const ProgressCallback& progress) {
  std::vector<std::vector<BenchFrame>> runs(detectors.size());
  std::vector<MarkerDetection> found;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const std::filesystem::path image = dataset_dir / labels[i].image;
    const cv::Mat gray = cv::imread(image.string(), cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw IoError(image.string() + ": not an image OpenCV can read");
    const DetectorFrame frame{{}, {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
    for (std::size_t d = 0; d < detectors.size(); ++d) {
      detectors[d]->reset(marker.dictionary, marker.id);
      const auto t0 = std::chrono::steady_clock::now();
      detectors[d]->detect(frame, found);
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      runs[d].push_back(score_frame(labels[i], found, marker.id));
      runs[d].back().ms = ms;
    }
    if (progress) progress(progress_since(start, i + 1, labels.size(), i));
  }
  return runs;
}

std::string bench_recall_plot(const std::vector<std::string>& names, const std::vector<std::vector<BenchFrame>>& runs,
                              const std::vector<BenchLabel>& labels, double threshold, const std::string& title) {
  const std::vector<std::string>& bands = distance_bands();
  std::vector<std::string> weathers;
  for (const auto& l : labels) {
    if (std::find(weathers.begin(), weathers.end(), l.weather) == weathers.end()) weathers.push_back(l.weather);
  }
  std::sort(weathers.begin(), weathers.end());
  const auto& colours = detail::palette::kSeries;
  const int columns = 5, rows = std::max(1, static_cast<int>((weathers.size() + columns - 1) / columns));
  const double panel_w = 150, panel_h = 130, gap_x = 42, gap_y = 58, left = 62, top = 70;
  detail::SvgWriter svg(static_cast<int>(left + columns * (panel_w + gap_x) + 10),
                        static_cast<int>(top + rows * (panel_h + gap_y) + 10));
  svg.title(title);
  // The legend above the panels: one swatch per detector.
  for (std::size_t d = 0; d < names.size(); ++d) {
    const double lx = left + 170.0 * static_cast<double>(d);
    const std::string style = std::string(" fill='none' stroke='") + colours[d % colours.size()] +
                              "' stroke-width='2'" + (d == 0 ? "" : " stroke-dasharray='6 3'");
    svg.line(lx, 42, lx + 24, 42, style);
    svg.text(lx + 30, 46, names[d]);
  }
  for (std::size_t w = 0; w < weathers.size(); ++w) {
    const int col = static_cast<int>(w) % columns, row = static_cast<int>(w) / columns;
    detail::PlotAxis x;
    x.lo = -0.4;
    x.hi = static_cast<double>(bands.size()) - 0.6;
    x.grid = false;
    detail::PlotAxis y = detail::fit_axis(0, 1, 4, col == 0 ? "recall at " + format_fixed(threshold, 2) : "");
    const double px0 = left + col * (panel_w + gap_x), py0 = top + row * (panel_h + gap_y);
    const detail::PlotFrame f{px0, py0, px0 + panel_w, py0 + panel_h, x, y};
    svg.axes(f);
    svg.text(px0 + panel_w / 2, py0 - 6, weathers[w], " text-anchor='middle' font-weight='bold'");
    for (std::size_t b = 0; b < bands.size(); ++b) {
      std::string band = bands[b];  // "3-6 m" -> "3-6": the unit goes to the axis title
      if (band.size() > 2 && band.ends_with(" m")) band.resize(band.size() - 2);
      svg.text(f.px(static_cast<double>(b)), f.bottom + 14, band, " text-anchor='middle' font-size='10'");
    }
    if (row == rows - 1 || w + columns >= weathers.size())
      svg.text(px0 + panel_w / 2, f.bottom + 30, "camera to marker [m]", " text-anchor='middle' font-size='10'");
    for (std::size_t d = 0; d < names.size(); ++d) {
      std::vector<double> xs, ys;
      for (std::size_t b = 0; b < bands.size(); ++b) {
        int pos = 0, hit = 0;
        for (std::size_t i = 0; i < labels.size(); ++i) {
          if (labels[i].weather != weathers[w] || distance_band(labels[i].distance) != bands[b]) continue;
          if (runs[d][i].role != TargetRole::Positive) continue;
          ++pos;
          for (const Scored& sc : runs[d][i].detections) hit += sc.hit && sc.confidence >= threshold ? 1 : 0;
        }
        if (pos >= 10) {
          xs.push_back(static_cast<double>(b));
          ys.push_back(static_cast<double>(hit) / pos);
        }
      }
      if (xs.empty()) continue;
      const std::string colour = colours[d % colours.size()];
      svg.polyline(f.to_pixels(xs, ys), " fill='none' stroke='" + colour + "' stroke-width='1.8'" +
                                            (d == 0 ? "" : " stroke-dasharray='6 3'"));
      for (const Eigen::Vector2d& p : f.to_pixels(xs, ys)) svg.circle(p.x(), p.y(), 2.5, " fill='" + colour + "'");
    }
  }
  return svg.finish();
}

BenchReport bench_report(const std::vector<std::string>& names, const std::vector<std::vector<BenchFrame>>& runs,
                         const std::vector<BenchLabel>& labels, const BenchReportInfo& info) {
  const double threshold = info.threshold;
  // Groups of frames: all, by weather, distance band, visible fraction, phase.
  struct Group {
    std::string name;
    std::vector<std::size_t> frames;
  };
  std::vector<Group> groups{{"all", {}}};
  std::map<std::string, std::vector<std::size_t>> by_weather, by_distance, by_visible, by_phase, by_sight;
  // The systems' working range: clear weather, the oracle reads the target.
  Group working{"clear, observable", {}};
  for (std::size_t i = 0; i < labels.size(); ++i) {
    groups[0].frames.push_back(i);
    if (!labels[i].sight.empty()) by_sight["sight " + labels[i].sight].push_back(i);
    if (labels[i].weather == "clear" && labels[i].sight == "observable") working.frames.push_back(i);
    by_weather["weather " + labels[i].weather].push_back(i);
    by_phase["phase " + labels[i].phase].push_back(i);
    by_distance["distance " + distance_band(labels[i].distance)].push_back(i);
    if (runs[0][i].role == TargetRole::Positive)
      by_visible["visible " + visible_band(labels[i].visible_fraction)].push_back(i);
  }
  // Weather and phase by name; distance and visibility from near to far, whole to least.
  for (auto& [k, v] : by_weather) groups.push_back({k, v});
  for (const std::string& band : distance_bands()) {
    const std::string k = "distance " + band;
    if (by_distance.count(k)) groups.push_back({k, by_distance[k]});
  }
  for (const std::string& band : visible_bands()) {
    const std::string k = "visible " + band;
    if (by_visible.count(k)) groups.push_back({k, by_visible[k]});
  }
  for (auto& [k, v] : by_phase) groups.push_back({k, v});
  for (auto& [k, v] : by_sight) groups.push_back({k, v});
  if (!working.frames.empty()) groups.push_back(working);
  Json out;
  out["dataset"] = info.dataset;
  out["frames"] = labels.size();
  out["threshold"] = threshold;
  out["marker"] = {{"dictionary", info.marker.dictionary}, {"id", info.marker.id}};
  std::ostringstream table;
  table << std::left << std::setw(26) << "group" << std::right << std::setw(7) << "frames" << std::setw(8) << "targets";
  for (const std::string& n : names)
    table << std::setw(16) << (n + " recall") << std::setw(11) << "precision" << std::setw(9) << "AP@0.5";
  table << "\n";
  for (const Group& g : groups) {
    table << std::left << std::setw(26) << g.name << std::right << std::setw(7) << g.frames.size();
    Json jg;
    for (std::size_t d = 0; d < names.size(); ++d) {
      std::vector<const BenchFrame*> fr;
      for (std::size_t i : g.frames) fr.push_back(&runs[d][i]);
      const BenchFigures b = bench_figures(fr, threshold);
      if (d == 0) table << std::setw(8) << b.positives;
      table << std::setw(16) << (b.positives ? format_fixed(b.recall(), 3) : "-") << std::setw(11)
            << format_fixed(b.precision(), 3) << std::setw(9)
            << (std::isnan(b.ap50) ? std::string("-") : format_fixed(b.ap50, 3));
      jg[names[d]] = {{"frames", b.frames},
                      {"targets", b.positives},
                      {"hits", b.hits},
                      {"false_positives", b.false_positives},
                      {"recall", round3(b.recall())},
                      {"precision", round3(b.precision())},
                      {"ap50", std::isnan(b.ap50) ? Json(nullptr) : Json(round3(b.ap50))}};
    }
    table << "\n";
    out["groups"][g.name] = jg;
  }
  // False positives on frames without the target, and time per frame.
  std::ostringstream tail;
  for (std::size_t d = 0; d < names.size(); ++d) {
    int none = 0, none_distract = 0, fp = 0, fp_distract = 0;
    std::vector<double> ms;
    for (std::size_t i = 0; i < labels.size(); ++i) {
      ms.push_back(runs[d][i].ms);
      if (runs[d][i].role != TargetRole::None) continue;
      int n = 0;
      for (const Scored& sc : runs[d][i].detections) n += sc.confidence >= threshold ? 1 : 0;
      ++none, fp += n;
      if (labels[i].distractors_in_view > 0) ++none_distract, fp_distract += n;
    }
    const double per_k = none ? 1000.0 * fp / none : 0.0;
    const double per_k_d = none_distract ? 1000.0 * fp_distract / none_distract : 0.0;
    const double med = median(ms);
    tail << names[d] << ": " << format_fixed(per_k, 1) << " false positives per 1000 frames without the target ("
         << none << " frames; " << format_fixed(per_k_d, 1) << " on the " << none_distract
         << " with distractors in view), " << format_fixed(med, 2) << " ms per frame (median, one core)\n";
    out["detectors"][names[d]] = {{"false_positives_per_1000", round3(per_k)},
                                  {"frames_without_target", none},
                                  {"false_positives_per_1000_with_distractors", round3(per_k_d)},
                                  {"frames_with_distractors", none_distract},
                                  {"ms_median", round3(med)}};
  }
  BenchReport report;
  report.text = "dataset " + info.dataset + " (" + std::to_string(labels.size()) + " frames, split " + info.split +
                "), marker " + info.marker.dictionary + " id " + std::to_string(info.marker.id) + ", threshold " +
                format_fixed(threshold, 2) + "\n" + table.str() + tail.str();
  report.json = out.dump();
  return report;
}

}  // namespace touchdown::scenario
