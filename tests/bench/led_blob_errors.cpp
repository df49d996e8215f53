// How far the LED detector's blob centres are from the truth, on a sequence
// with ground truth (issue 33, item 2: the noise model of a blob centre).
//
//   led_blob_errors [--step N] [--csv] SEQUENCE_DIR CONSTELLATION.yaml [SEQUENCE_DIR CONSTELLATION.yaml ...]
//
// Over all the sequences given (each with its constellation), every N-th frame (default 1) is detected as led_pose
// detects it; each LED the ground-truth pose puts in front of the camera and inside its emission cone is paired with
// the nearest blob within 4 px (no pair when another LED's projection is within 3 px of that blob: two LEDs in one spot
// are the shared-blob rule's business, not noise). The error is the blob centre minus the LED's projection through the
// camera model, per axis. Printed: the RMS and the robust σ (1.4826 × median |e|) per axis, by blob area and by the
// distance of the nearest other blob in the blob's radii (√(area/π)) — the crowding that
// CorrespondenceOptions::crowded_* models.
// --csv prints one line per pair instead. The sequence is any led_pose
// sequence with ground_truth.jsonl (docs/formats.md), e.g. one written by
// the independent renderer (tests/bench/led_independent.py caches them).
// Exit 2 with one line on bad arguments or an unreadable sequence.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/ground_truth.hpp"
#include "touchdown/pose/led_detector.hpp"
#include "touchdown/pose/sim/sequence.hpp"

namespace {

namespace tp = touchdown::pose;

struct Pair {
  double area = 0;
  double crowding = 0;  // nearest other blob, in this blob's radii
  double ex = 0, ey = 0;
};

constexpr std::array<double, 4> kAreaEdges{0, 24, 96, 1e9};
constexpr std::array<double, 7> kCrowdEdges{0, 4, 5, 6, 8, 12, 1e9};

void print_table(const std::vector<Pair>& pairs) {
  std::printf("| area [px] | nearest blob [radii] | pairs | RMS [px] | robust σ [px] |\n|---|---|---|---|---|\n");
  for (std::size_t a = 0; a + 1 < kAreaEdges.size(); ++a) {
    for (std::size_t c = 0; c + 1 < kCrowdEdges.size(); ++c) {
      std::vector<double> abs_e;
      double sq = 0;
      for (const Pair& p : pairs) {
        if (p.area < kAreaEdges[a] || p.area >= kAreaEdges[a + 1]) continue;
        if (p.crowding < kCrowdEdges[c] || p.crowding >= kCrowdEdges[c + 1]) continue;
        for (double e : {p.ex, p.ey}) {
          abs_e.push_back(std::abs(e));
          sq += e * e;
        }
      }
      if (abs_e.size() < 10) continue;
      const auto mid = abs_e.begin() + static_cast<std::ptrdiff_t>(abs_e.size() / 2);
      std::nth_element(abs_e.begin(), mid, abs_e.end());
      const auto bound = [](double v) { return v >= 1e8 ? std::string("∞") : std::to_string(static_cast<int>(v)); };
      std::printf("| %s–%s | %s–%s | %zu | %.4f | %.4f |\n", bound(kAreaEdges[a]).c_str(),
                  bound(kAreaEdges[a + 1]).c_str(), bound(kCrowdEdges[c]).c_str(), bound(kCrowdEdges[c + 1]).c_str(),
                  abs_e.size() / 2, std::sqrt(sq / static_cast<double>(abs_e.size())), 1.4826 * *mid);
    }
  }
}

// Adds the pairs of one sequence (every `step`-th frame) to `pairs`.
void measure(const std::filesystem::path& dir, const std::filesystem::path& constellation, int step, bool csv,
             std::vector<Pair>& pairs) {
  const tp::Constellation k = tp::load_constellation(constellation);
  const tp::CameraModel camera = tp::load_camera(dir / "camera.yaml");
  const auto truth = tp::read_ground_truth(dir / "ground_truth.jsonl");
  const auto frames = tp::list_sequence(dir);
  tp::LedDetector detector(camera);
  touchdown::BgrImage colour;
  touchdown::DepthImage depth;
  std::vector<tp::Blob> blobs;
  std::vector<Eigen::Vector2d> projected(k.leds.size());
  std::vector<bool> seen(k.leds.size());
  for (std::size_t f = 0; f < frames.size() && f < truth.size(); f += static_cast<std::size_t>(step)) {
    tp::read_frame(frames[f], colour, &depth);
    const touchdown::DepthImageView dv = depth.view();
    detector.detect(colour.view(), depth.empty() ? nullptr : &dv, blobs);
    const Eigen::Isometry3d& T = truth[f].T_camera_body;
    const Eigen::Vector3d camera_in_body = T.inverse().translation();
    for (std::size_t i = 0; i < k.leds.size(); ++i) {
      const Eigen::Vector3d q = T * k.leds[i].p_body;
      seen[i] = q.z() > 0 && k.leds[i].emits_toward(camera_in_body);
      if (seen[i]) projected[i] = camera.project(q);
    }
    for (std::size_t i = 0; i < k.leds.size(); ++i) {
      if (!seen[i]) continue;
      const tp::Blob* best = nullptr;
      double best_d = 4.0;
      for (const tp::Blob& b : blobs) {
        const double d = (b.uv_px - projected[i]).norm();
        if (d < best_d) {
          best_d = d;
          best = &b;
        }
      }
      if (best == nullptr) continue;
      bool shared = false;
      for (std::size_t j = 0; j < k.leds.size(); ++j) {
        shared |= j != i && seen[j] && (projected[j] - best->uv_px).norm() < 3;
      }
      if (shared) continue;
      double nearest = 1e9;
      for (const tp::Blob& b : blobs) {
        if (&b != best) nearest = std::min(nearest, (b.uv_px - best->uv_px).norm());
      }
      Pair p;
      p.area = best->area;
      p.crowding = nearest / std::max(1.0, std::sqrt(best->area / std::numbers::pi));
      p.ex = best->uv_px.x() - projected[i].x();
      p.ey = best->uv_px.y() - projected[i].y();
      if (csv) {
        std::printf("%s,%s,%zu,%.0f,%.2f,%.5f,%.5f\n", dir.string().c_str(), frames[f].name.c_str(), i, p.area,
                    p.crowding, p.ex, p.ey);
      }
      pairs.push_back(p);
    }
  }
}

int run(int argc, char** argv) {
  int step = 1;
  bool csv = false;
  std::vector<std::string> paths;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--csv") {
      csv = true;
    } else if (a == "--step" && i + 1 < argc) {
      step = std::atoi(argv[++i]);
      if (step < 1) {
        std::fprintf(stderr, "led_blob_errors: --step: must be a positive integer\n");
        return 2;
      }
    } else if (a.starts_with("--")) {
      std::fprintf(stderr, "led_blob_errors: unknown option '%s'\n", a.c_str());
      return 2;
    } else {
      paths.push_back(a);
    }
  }
  if (paths.empty() || paths.size() % 2 != 0) {
    std::fprintf(stderr,
                 "usage: led_blob_errors [--step N] [--csv] SEQUENCE_DIR CONSTELLATION.yaml "
                 "[SEQUENCE_DIR CONSTELLATION.yaml ...]\n");
    return 2;
  }
  std::vector<Pair> pairs;
  if (csv) std::printf("sequence,frame,led,area,crowding_radii,ex_px,ey_px\n");
  for (std::size_t i = 0; i < paths.size(); i += 2) measure(paths[i], paths[i + 1], step, csv, pairs);
  if (!csv) {
    std::printf("%zu sequences, %zu blob-LED pairs\n\n", paths.size() / 2, pairs.size());
    print_table(pairs);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "led_blob_errors: %s\n", e.what());
    return 2;
  }
}
