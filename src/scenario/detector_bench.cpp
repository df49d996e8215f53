// Marker detectors measured on a labelled dataset (detector_bench.hpp).
#include "touchdown/scenario/detector_bench.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "scenario/learned_detector.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {

using detail::box_iou;

std::vector<BenchLabel> read_bench_labels(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path.string() + ": cannot read");
  return parse_bench_labels(in, path);
}

std::vector<BenchLabel> parse_bench_labels(std::istream& in, const std::filesystem::path& path) {
  std::vector<BenchLabel> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty()) continue;
    const std::string where = path.string() + ":" + std::to_string(n) + ": ";
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception&) {
      throw ParseError(where + "not JSON");
    }
    BenchLabel l;
    const char* key = "image";
    try {
      l.image = j.at("image").get<std::string>();
      key = "split";
      l.split = j.at("split").get<std::string>();
      key = "weather";
      l.weather = j.at("weather").get<std::string>();
      key = "phase";
      l.phase = j.at("phase").get<std::string>();
      key = "distance";
      l.distance = j.at("distance").get<double>();
      key = "target";
      const nlohmann::json& t = j.at("target");
      l.in_view = t.at("in_view").get<bool>();
      const auto& corners = t.at("corners");
      l.has_corners = corners.size() == 4;
      for (std::size_t k = 0; l.has_corners && k < 4; ++k)
        l.corners[k] = Eigen::Vector2d(corners.at(k).at(0).get<double>(), corners.at(k).at(1).get<double>());
      const auto& box = t.at("box");
      l.box_min = Eigen::Vector2d(box.at(0).get<double>(), box.at(1).get<double>());
      l.box_max = Eigen::Vector2d(box.at(2).get<double>(), box.at(3).get<double>());
      l.inside_fraction = t.at("inside_fraction").get<double>();
      l.visible_fraction = t.at("visible_fraction").get<double>();
      if (t.contains("sight")) l.sight = t.at("sight").get<std::string>();
      key = "distractors";
      for (const auto& d : j.at("distractors")) l.distractors_in_view += d.at("in_view").get<bool>() ? 1 : 0;
    } catch (const nlohmann::json::exception&) {
      throw ParseError(where + key + ": missing or of the wrong type");
    }
    if (l.image.empty() || l.image.find("..") != std::string::npos || l.image.front() == '/')
      throw ParseError(where + "image: must be a path inside the dataset");
    if (!std::isfinite(l.distance) || !l.box_min.allFinite() || !l.box_max.allFinite())
      throw ParseError(where + "target: not finite");
    out.push_back(std::move(l));
  }
  return out;
}

TargetRole bench_role(const BenchLabel& l) {
  if (!l.in_view || !l.has_corners) return TargetRole::None;
  double side = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < 4; ++k) side = std::min(side, (l.corners[k] - l.corners[(k + 1) % 4]).norm());
  if (l.inside_fraction >= 0.85 && l.visible_fraction >= 0.6 && side >= 8) return TargetRole::Positive;
  return TargetRole::Ignored;
}

BenchFrame score_frame(const BenchLabel& label, const std::vector<MarkerDetection>& found, int id) {
  BenchFrame f;
  f.role = bench_role(label);
  bool matched = false;
  // Highest confidence first: the best detection takes the target.
  std::vector<const MarkerDetection*> mine;
  for (const MarkerDetection& d : found) {
    if (d.id == id) mine.push_back(&d);
  }
  std::stable_sort(mine.begin(), mine.end(),
                   [](const MarkerDetection* a, const MarkerDetection* b) { return a->confidence > b->confidence; });
  for (const MarkerDetection* d : mine) {
    const bool overlaps =
        f.role != TargetRole::None && box_iou(d->box_min, d->box_max, label.box_min, label.box_max) >= 0.5;
    if (overlaps && f.role == TargetRole::Ignored) continue;
    f.detections.push_back({d->confidence, overlaps && !matched});
    matched = matched || overlaps;
  }
  return f;
}

double average_precision(std::vector<Scored> d, int positives) {
  if (positives <= 0) return std::numeric_limits<double>::quiet_NaN();
  std::stable_sort(d.begin(), d.end(), [](const Scored& a, const Scored& b) { return a.confidence > b.confidence; });
  std::vector<double> recall, precision;
  int tp = 0, fp = 0;
  for (const Scored& s : d) {
    (s.hit ? tp : fp) += 1;
    recall.push_back(static_cast<double>(tp) / positives);
    precision.push_back(static_cast<double>(tp) / (tp + fp));
  }
  // The precision envelope from the right, then the area under its steps.
  for (std::size_t i = precision.size(); i-- > 1;) precision[i - 1] = std::max(precision[i - 1], precision[i]);
  double ap = 0, last_recall = 0;
  for (std::size_t i = 0; i < recall.size(); ++i) {
    ap += (recall[i] - last_recall) * precision[i];
    last_recall = recall[i];
  }
  return ap;
}

BenchFigures bench_figures(const std::vector<const BenchFrame*>& frames, double threshold) {
  BenchFigures b;
  std::vector<Scored> all;
  for (const BenchFrame* f : frames) {
    ++b.frames;
    b.positives += f->role == TargetRole::Positive ? 1 : 0;
    for (const Scored& s : f->detections) {
      all.push_back(s);
      if (s.confidence < threshold) continue;
      (s.hit ? b.hits : b.false_positives) += 1;
    }
  }
  b.ap50 = average_precision(all, b.positives);
  return b;
}

const std::vector<std::string>& distance_bands() {
  static const std::vector<std::string> kBands{"0-3 m", "3-6 m", "6-10 m", "10-15 m", "15+ m"};
  return kBands;
}

std::string distance_band(double d) {
  const auto& b = distance_bands();
  return d < 3 ? b[0] : d < 6 ? b[1] : d < 10 ? b[2] : d < 15 ? b[3] : b[4];
}

const std::vector<std::string>& visible_bands() {
  static const std::vector<std::string> kBands{"whole", "0.8-0.99", "0.6-0.8"};
  return kBands;
}

std::string visible_band(double v) {
  const auto& b = visible_bands();
  return v >= 0.99 ? b[0] : v >= 0.8 ? b[1] : b[2];
}

}  // namespace touchdown::scenario
