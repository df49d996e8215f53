// The detector dataset on disk (docs/formats.md, "Detector dataset"):
// labels.jsonl lines, the grey PNG frames and dataset.json.
#include <charconv>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/io_util.hpp"
#include "core/json_number.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/dataset.hpp"

namespace touchdown::scenario {

namespace {

using Json = nlohmann::ordered_json;
using detail::round3;

Json quad_json(const QuadLabel& q) {
  Json j;
  j["in_view"] = q.in_view();
  Json corners = Json::array();
  if (q.in_front) {
    for (const Eigen::Vector2d& c : q.corners) corners.push_back({round3(c.x()), round3(c.y())});
  }
  j["corners"] = corners;
  j["box"] = {round3(q.box_min.x()), round3(q.box_min.y()), round3(q.box_max.x()), round3(q.box_max.y())};
  j["inside_fraction"] = round3(q.inside_fraction);
  j["visible_fraction"] = round3(q.visible_fraction);
  return j;
}

}  // namespace

bool parse_marker_spec(std::string_view text, std::string& dictionary, int& id) {
  const std::size_t colon = text.find(':');
  if (colon == std::string_view::npos || colon == 0) return false;
  const std::string_view digits = text.substr(colon + 1);
  int value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size()) return false;
  dictionary = std::string(text.substr(0, colon));
  id = value;
  return true;
}

std::string dataset_label_json(const DatasetFrame& f, std::string_view image) {
  Json j;
  j["image"] = image;
  j["index"] = f.index;
  j["split"] = enum_name(f.split);
  j["scenario_seed"] = f.scenario_seed;
  j["map"] = to_string(f.scenario.map);
  j["weather"] = f.weather;
  const Weather& w = f.scenario.weather;
  j["conditions"] = {{"fog", round3(w.fog)},
                     {"rain", round3(w.rain)},
                     {"snow", round3(w.snow)},
                     {"dust", round3(w.dust)},
                     {"leaves", round3(w.leaves)},
                     {"ground_wetness", round3(w.ground_wetness)},
                     {"ground_snow", round3(w.ground_snow)},
                     {"ground_leaves", round3(w.ground_leaves)},
                     {"ambient", round3(w.ambient)},
                     {"sun_elevation_deg", round3(w.sun_elevation_deg)}};
  j["phase"] = f.phase;
  const Eigen::Vector3d c = f.T_world_camera.translation();
  j["camera"] = {{"position", {round3(c.x()), round3(c.y()), round3(c.z())}},
                 {"tilt_deg", round3(f.camera.tilt_deg)},
                 {"hfov_deg", f.camera.hfov_deg},
                 {"width", f.camera.width},
                 {"height", f.camera.height}};
  j["distance"] = round3(f.distance);
  Json t = quad_json(f.target);
  t["sight"] = to_string(f.view.sight);
  t["side_px"] = round3(f.view.side_px);
  t["contrast"] = round3(f.view.contrast);
  j["target"] = t;
  Json d = Json::array();
  for (const DistractorLabel& x : f.distractors) {
    Json q = quad_json(x.quad);
    q["kind"] = to_string(x.kind);
    d.push_back(q);
  }
  j["distractors"] = d;
  j["occluder"] = f.occluder;
  return j.dump();
}

DatasetSummary write_dataset(const DatasetOptions& options, int count, const std::filesystem::path& out,
                             const BatchOptions& batch) {
  namespace fs = std::filesystem;
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("dataset: " + why);
  if (count < 1) throw InvalidArgument("dataset: count must be >= 1 (got " + std::to_string(count) + ")");
  if (fs::exists(out)) throw IoError(out.string() + ": exists (a dataset goes into a new directory)");
  StagedDirectory staged(fs::absolute(out));
  const fs::path tmp = staged.path();
  fs::create_directories(tmp / "images");
  const auto n = static_cast<std::size_t>(count);
  std::vector<std::string> lines(n);
  std::vector<DatasetSplit> split_of(n);
  const BatchReport report = run_batch(n, batch, [&](std::size_t i, std::size_t) {
    const DatasetFrame f = render_dataset_frame(options, static_cast<int>(i));
    char name[32];
    std::snprintf(name, sizeof name, "images/%06zu.png", i);
    const cv::Mat bgr(f.frame.height, f.frame.width, CV_8UC3, const_cast<std::uint8_t*>(f.frame.image.pixels.data()));
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    if (!cv::imwrite((tmp / name).string(), gray, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      throw IoError((out / name).string() + ": cannot write");
    lines[i] = dataset_label_json(f, name);
    split_of[i] = f.split;
  });
  if (report.cancelled) return {};
  DatasetSummary summary;
  summary.count = count;
  for (const DatasetSplit s : split_of) ++summary.splits[static_cast<std::size_t>(s)];
  std::string text;
  for (const std::string& l : lines) text += l + "\n";
  touchdown::detail::write_text_file(tmp / "labels.jsonl", text, (out / "labels.jsonl").string());
  Json meta;
  meta["format"] = "touchdown-dataset/1";
  meta["seed"] = options.seed;
  meta["count"] = count;
  meta["marker"] = {{"dictionary", options.dictionary}, {"id", options.marker_id}};
  meta["camera"] = {{"width", options.camera.width},
                    {"height", options.camera.height},
                    {"hfov_deg", options.camera.hfov_deg},
                    {"max_tilt_deg", options.max_tilt_deg}};
  meta["splits"] = {{"train", summary.splits[0]}, {"validation", summary.splits[1]}, {"test", summary.splits[2]}};
  meta["images"] = "8-bit grey PNG, the systems' BGR frame converted as cv::cvtColor(COLOR_BGR2GRAY)";
  touchdown::detail::write_text_file(tmp / "dataset.json", meta.dump(2) + "\n", (out / "dataset.json").string());
  staged.commit();
  return summary;
}

}  // namespace touchdown::scenario
