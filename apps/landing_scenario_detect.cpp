// landing_scenario dataset, detect and detect-bench: the marker detectors
// on rendered, labelled frames and on image files.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app_common.hpp"
#include "core/svg_plot.hpp"
#include "landing_scenario.hpp"
#include "system_option.hpp"
#include "touchdown/core/atomic_file.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/contract.hpp"
#include "touchdown/scenario/dataset.hpp"
#include "touchdown/scenario/detector_bench.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/report.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/search/dqn.hpp"
#include "touchdown/search/object_policy.hpp"
#include "video.hpp"

namespace {

namespace td = touchdown;
namespace ts = touchdown::scenario;
namespace tsr = touchdown::search;
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using namespace touchdown::app;
using namespace touchdown::app::scenario_app;

// ---- dataset: detector training and test frames -----------------------------------------

struct DatasetArgs {
  std::string out;
  int count = 1000;
  std::string marker = "4X4_50:0";
  int threads = 1;
  ts::DatasetOptions options;
};

CLI::App* add_dataset_command(CLI::App& app, DatasetArgs& a) {
  auto* cmd = app.add_subcommand(
      "dataset",
      "render labelled frames for training and testing marker detectors (docs/formats.md, Detector dataset)");
  a.threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  cmd->add_option("--out", a.out, "directory to create (must not exist): images/ and labels.jsonl")->required();
  cmd->add_option("--count", a.count, "frames")->check(CLI::Range(1, 10000000))->capture_default_str();
  add_seed_option(*cmd, "--seed", a.options.seed, "dataset seed (frame i is drawn from (seed, i))");
  cmd->add_option("--marker", a.marker, "the target marker, DICTIONARY:ID")->capture_default_str();
  cmd->add_option("--max-tilt", a.options.max_tilt_deg, "largest camera tilt drawn [deg]")
      ->check(td::app::degrees_not_radians("--max-tilt"))
      ->capture_default_str();
  cmd->add_option("--threads", a.threads, "worker threads (0 = every core)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return cmd;
}

int dataset_command(DatasetArgs& a) {
  parse_marker(a.marker, "--marker", &a.options.dictionary, &a.options.marker_id);
  std::string why;
  if (!a.options.validate(&why)) throw td::InvalidArgument("--marker/--max-tilt: " + why);
  if (fs::exists(a.out)) throw td::IoError("--out " + a.out + ": exists (a dataset goes into a new directory)");
  require_parent_directory(a.out, "--out");
  cv::setNumThreads(1);  // one frame per worker thread
  ProgressBar bar("landing_scenario", "frames");
  td::BatchOptions batch;
  batch.threads = a.threads;
  batch.progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
  const ts::DatasetSummary d = ts::write_dataset(a.options, a.count, a.out, batch);
  bar.close();
  std::cout << "dataset " << a.out << ": " << d.count << " frames (train " << d.splits[0] << ", validation "
            << d.splits[1] << ", test " << d.splits[2] << "), marker " << a.options.dictionary << " id "
            << a.options.marker_id << ", seed " << a.options.seed << "\n";
  return kExitOk;
}

// ---- detect: a detector on image files -----------------------------------------------------

struct DetectArgs {
  std::vector<std::string> images;
  std::string marker = "4X4_50:0";
  bool json = false;
  ts::DetectorOptions detector;
};

CLI::App* add_detect_command(CLI::App& app, DetectArgs& a) {
  auto* cmd = app.add_subcommand("detect", "run a marker detector on image files (any size; PNG, JPEG, ...)");
  cmd->add_option("IMAGE", a.images, "image files")->required()->check(td::app::existing_file());
  cmd->add_option("--detector", a.detector.kind, "the marker detector")
      ->check(one_of_names(ts::marker_detector_names()))
      ->capture_default_str();
  cmd->add_option("--model", a.detector.model,
                  "the learned detector's ONNX model (default: data/models/, TOUCHDOWN_MODEL)");
  cmd->add_option("--marker", a.marker, "the marker looked for, DICTIONARY:ID (aruco reports every id of it)")
      ->capture_default_str();
  cmd->add_option("--min-confidence", a.detector.min_confidence, "learned: report detections from this confidence")
      ->check(number_in(0, 1))
      ->capture_default_str();
  cmd->add_flag("--json", a.json, "one JSON object per image on stdout (JSON Lines)");
  return cmd;
}

int detect_command(DetectArgs& a) {
  std::string dictionary;
  int id = 0;
  parse_marker(a.marker, "--marker", &dictionary, &id);
  a.detector.roi = false;  // separate images: nothing to track
  cv::setNumThreads(1);
  auto detector = ts::make_marker_detector(a.detector);
  detector->reset(dictionary, id);
  // Every image is read before any is reported: a bad file is one error, no partial output.
  std::vector<cv::Mat> bgr;
  for (const std::string& path : a.images) {
    cv::Mat im = cv::imread(path, cv::IMREAD_COLOR);
    if (im.empty()) throw td::IoError(path + ": not an image OpenCV can read");
    bgr.push_back(im);
  }
  std::vector<ts::MarkerDetection> found;
  for (std::size_t i = 0; i < bgr.size(); ++i) {
    cv::Mat gray;
    cv::cvtColor(bgr[i], gray, cv::COLOR_BGR2GRAY);
    const ts::DetectorFrame frame{{bgr[i].data, bgr[i].cols, bgr[i].rows, static_cast<std::ptrdiff_t>(bgr[i].step)},
                                  {gray.data, gray.cols, gray.rows, static_cast<std::ptrdiff_t>(gray.step)}};
    const auto t0 = std::chrono::steady_clock::now();
    detector->detect(frame, found);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (a.json) {
      Json j;
      j["image"] = a.images[i];
      j["width"] = bgr[i].cols;
      j["height"] = bgr[i].rows;
      j["detector"] = detector->name();
      j["ms"] = round3(ms);
      Json list = Json::array();
      for (const ts::MarkerDetection& d : found) {
        Json x;
        x["id"] = d.id;
        x["confidence"] = round3(d.confidence);
        x["box"] = {round3(d.box_min.x()), round3(d.box_min.y()), round3(d.box_max.x()), round3(d.box_max.y())};
        if (d.has_corners) {
          Json c = Json::array();
          for (const Eigen::Vector2d& p : d.corners) c.push_back({round3(p.x()), round3(p.y())});
          x["corners"] = c;
          x["oriented"] = d.oriented;
        }
        list.push_back(x);
      }
      j["detections"] = list;
      std::cout << j.dump() << "\n";
      continue;
    }
    std::cout << a.images[i] << " (" << bgr[i].cols << "x" << bgr[i].rows << ", " << detector->name() << ", "
              << format_fixed(ms, 1) << " ms): " << count_noun(static_cast<long long>(found.size()), "detection")
              << "\n";
    for (const ts::MarkerDetection& d : found) {
      std::cout << "  id " << d.id << "  confidence " << format_fixed(d.confidence, 2) << "  box ["
                << format_fixed(d.box_min.x(), 1) << ", " << format_fixed(d.box_min.y(), 1) << "] - ["
                << format_fixed(d.box_max.x(), 1) << ", " << format_fixed(d.box_max.y(), 1) << "]";
      if (d.has_corners) {
        std::cout << "  corners";
        for (const Eigen::Vector2d& p : d.corners)
          std::cout << " (" << format_fixed(p.x(), 1) << ", " << format_fixed(p.y(), 1) << ")";
      }
      std::cout << "\n";
    }
  }
  return kExitOk;
}

// ---- detect-bench: detectors on a labelled dataset --------------------------------------

struct BenchArgs {
  std::string dataset, split = "all", plot_path, detectors = "aruco,learned";
  double threshold = 0.7;
  int limit = 0;
  bool json = false;
  std::string model;
};

CLI::App* add_bench_command(CLI::App& app, BenchArgs& a) {
  auto* cmd = app.add_subcommand(
      "detect-bench", "precision, recall, AP@0.5 and time of marker detectors on a dataset (landing_scenario dataset)");
  cmd->add_option("DATASET", a.dataset, "a dataset directory (dataset.json, labels.jsonl, images/)")
      ->required()
      ->check(td::app::existing_directory());
  cmd->add_option("--detectors", a.detectors, "comma-separated: aruco, learned")->capture_default_str();
  cmd->add_option("--model", a.model, "the learned detector's model (default: data/models/, TOUCHDOWN_MODEL)");
  cmd->add_option("--split", a.split, "frames of this split only: train, validation, test or all")
      ->check(CLI::IsMember({"all", "train", "validation", "test"}))
      ->capture_default_str();
  cmd->add_option("--threshold", a.threshold,
                  "confidence from which a detection counts (recall, precision, false "
                  "positives; AP uses every confidence)")
      ->check(number_in(0, 1))
      ->capture_default_str();
  cmd->add_option("--limit", a.limit, "the first N frames only (0: all)")->check(CLI::Range(0, 10000000));
  cmd->add_option("--plot", a.plot_path, "recall against distance, a panel per weather kind, a line per detector (SVG)")
      ->check(output_extension(".svg"));
  cmd->add_flag("--json", a.json, "the figures as one JSON object");
  return cmd;
}

int bench_command(BenchArgs& a) {
  td::StagedOutputs staged;
  const fs::path plot_tmp = stage(staged, a.plot_path, "--plot");
  const fs::path dir(a.dataset);
  const ts::DatasetMarker marker = ts::read_dataset_marker(dir);
  std::vector<ts::BenchLabel> labels = ts::read_bench_labels(dir / "labels.jsonl");
  if (a.split != "all") std::erase_if(labels, [&](const ts::BenchLabel& l) { return l.split != a.split; });
  if (a.limit > 0 && labels.size() > static_cast<std::size_t>(a.limit))
    labels.resize(static_cast<std::size_t>(a.limit));
  if (labels.empty()) throw td::InvalidArgument(a.dataset + ": no frames of split " + a.split);
  std::vector<std::string> names;
  std::stringstream list(a.detectors);
  for (std::string n; std::getline(list, n, ',');) {
    if (n != "aruco" && n != "learned") throw td::InvalidArgument("--detectors: unknown '" + n + "' (aruco, learned)");
    names.push_back(n);
  }
  if (names.empty()) throw td::InvalidArgument("--detectors: none given");
  cv::setNumThreads(1);  // one core per detector, as a companion computer's worker
  std::vector<std::unique_ptr<ts::MarkerDetector>> detectors;
  for (const std::string& n : names) {
    ts::DetectorOptions o;
    o.kind = n;
    o.roi = false;
    o.min_confidence = 0.05;
    if (!a.model.empty()) o.model = a.model;
    detectors.push_back(ts::make_marker_detector(o));
  }
  ProgressBar bar("landing_scenario", "images");
  const auto runs = ts::run_detector_bench(dir, labels, marker, detectors,
                                           [&bar](const td::Progress& p) { bar.draw(p.done, p.total); });
  bar.close();
  const ts::BenchReport report = ts::bench_report(names, runs, labels, {a.dataset, a.split, marker, a.threshold});
  if (!a.plot_path.empty())
    write_text(
        plot_tmp,
        ts::bench_recall_plot(names, runs, labels, a.threshold, "Recall of the target against distance: " + a.dataset),
        a.plot_path);
  staged.commit();
  std::cout << (a.json ? report.json + "\n" : report.text);
  return kExitOk;
}

}  // namespace

namespace touchdown::app::scenario_app {

Subcommand add_dataset(CLI::App& app) {
  return make_subcommand<DatasetArgs>(app, add_dataset_command, dataset_command);
}

Subcommand add_detect(CLI::App& app) { return make_subcommand<DetectArgs>(app, add_detect_command, detect_command); }

Subcommand add_bench(CLI::App& app) { return make_subcommand<BenchArgs>(app, add_bench_command, bench_command); }

}  // namespace touchdown::app::scenario_app
