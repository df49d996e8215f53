// The learned marker detector through OpenCV DNN (learned_detector.hpp).
#include "scenario/learned_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "core/json_read.hpp"
#include "scenario/aruco_detector.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario::detail {

namespace {

[[noreturn]] void model_error(const std::filesystem::path& path, const std::string& what) {
  throw InvalidArgument("model " + path.string() + ": " + what);
}

}  // namespace

std::filesystem::path manifest_path(const std::filesystem::path& model) {
  std::filesystem::path p = model;
  return p.replace_extension(".json");
}

ModelManifest read_model_manifest(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) model_error(path, "cannot read the manifest");
  std::stringstream text;
  text << in.rdbuf();
  return parse_model_manifest(text.str(), path);
}

ModelManifest parse_model_manifest(std::string_view text, const std::filesystem::path& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    model_error(path, std::string("not JSON (") + e.what() + ")");
  }
  ModelManifest m;
  const auto get = [&](const char* group, const char* key, auto& value) {
    const auto g = j.find(group);
    if (g == j.end() || !g->is_object() || !g->contains(key))
      model_error(path, std::string(group) + "." + key + ": missing");
    const nlohmann::json& v = (*g)[key];
    if constexpr (std::is_same_v<std::decay_t<decltype(value)>, int>) {
      const std::optional<int> i = touchdown::detail::json_int(v);
      if (!i) model_error(path, std::string(group) + "." + key + ": " + touchdown::detail::json_int_problem(v));
      value = *i;
    } else {
      try {
        v.get_to(value);
      } catch (const nlohmann::json::exception&) {
        model_error(path, std::string(group) + "." + key + ": wrong type");
      }
    }
  };
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (!j.is_object() || format == j.end() || !format->is_string() ||
      (*format != "touchdown-detector/1" && *format != "touchdown-detector/2"))
    model_error(path, "format: expected \"touchdown-detector/1\" or \"touchdown-detector/2\"");
  const bool two_stage = *format == "touchdown-detector/2";
  get("marker", "dictionary", m.dictionary);
  get("marker", "id", m.marker_id);
  get("input", "width", m.width);
  get("input", "height", m.height);
  get("input", "pad_value", m.pad_value);
  get("output", "stride", m.stride);
  get("output", "channels", m.channels);
  get("output", "corner_scale", m.corner_scale);
  const auto* dict = pose::find_aruco_dictionary(m.dictionary);
  if (!dict) model_error(path, "marker.dictionary: unknown " + m.dictionary);
  if (m.marker_id < 0 || m.marker_id >= dict->codes) model_error(path, "marker.id: not in the dictionary");
  if (m.stride < 1 || m.stride > 64) model_error(path, "output.stride: must be in [1, 64]");
  if (m.width < m.stride || m.width > 4096 || m.width % m.stride != 0)
    model_error(path, "input.width: must be a multiple of output.stride in [stride, 4096]");
  if (m.height < m.stride || m.height > 4096 || m.height % m.stride != 0)
    model_error(path, "input.height: must be a multiple of output.stride in [stride, 4096]");
  if (m.channels != 11) model_error(path, "output.channels: must be 11");
  if (!(std::isfinite(m.corner_scale) && m.corner_scale > 0)) model_error(path, "output.corner_scale: must be > 0");
  if (!(std::isfinite(m.pad_value) && m.pad_value >= 0 && m.pad_value <= 1))
    model_error(path, "input.pad_value: must be in [0, 1]");
  if (!two_stage) {
    if (j.contains("verifier")) model_error(path, "verifier: only in format \"touchdown-detector/2\"");
    return m;
  }
  VerifierManifest v;
  std::string file;
  get("verifier", "file", file);
  get("verifier", "patch", v.patch);
  get("verifier", "margin_cells", v.margin_cells);
  get("verifier", "min_range", v.min_range);
  get("verifier", "proposal_threshold", v.proposal_threshold);
  get("verifier", "max_proposals", v.max_proposals);
  // A bare file name beside the manifest: a manifest cannot point the
  // detector at a file elsewhere.
  if (file.empty() || std::filesystem::path(file).filename() != file || file == "." || file == "..")
    model_error(path, "verifier.file: must be a file name beside the manifest");
  v.file = path.parent_path() / file;
  v.cells = dict->bits + 2;
  if (v.patch < 8 || v.patch > 256) model_error(path, "verifier.patch: must be in [8, 256]");
  if (v.margin_cells < 0 || v.margin_cells > 4) model_error(path, "verifier.margin_cells: must be in [0, 4]");
  if (!(std::isfinite(v.min_range) && v.min_range >= 1 && v.min_range <= 255))
    model_error(path, "verifier.min_range: must be in [1, 255]");
  if (!(std::isfinite(v.proposal_threshold) && v.proposal_threshold > 0 && v.proposal_threshold <= 1))
    model_error(path, "verifier.proposal_threshold: must be in (0, 1]");
  if (v.max_proposals < 1 || v.max_proposals > 64) model_error(path, "verifier.max_proposals: must be in [1, 64]");
  m.verifier = v;
  return m;
}

bool extract_patch(const cv::Mat& gray, const std::array<Eigen::Vector2d, 4>& corners, const VerifierManifest& v,
                   cv::Mat& patch) {
  TD_ASSERT(gray.type() == CV_8UC1);
  const double total = v.cells + 2.0 * v.margin_cells;
  const double m = v.patch * v.margin_cells / total, inner = v.patch - 2 * m;
  double side = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < 4; ++i) {
    side += (corners[i] - corners[(i + 1) % 4]).norm() / 4;
    centre += corners[i] / 4;
  }
  if (!(std::isfinite(side) && side >= 1)) return false;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (const auto& c : corners) {
    const Eigen::Vector2d q = centre + (c - centre) * (total / v.cells);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  // Far outside the frame (a wild corner regression): nothing to read.
  if (!(lo.allFinite() && hi.allFinite()) || hi.x() < 0 || hi.y() < 0 || lo.x() > gray.cols || lo.y() > gray.rows)
    return false;
  const int x0 = std::max(0, static_cast<int>(std::floor(lo.x())) - 1);
  const int y0 = std::max(0, static_cast<int>(std::floor(lo.y())) - 1);
  const int x1 = std::min(gray.cols, static_cast<int>(std::ceil(hi.x())) + 2);
  const int y1 = std::min(gray.rows, static_cast<int>(std::ceil(hi.y())) + 2);
  if (x1 - x0 < 2 || y1 - y0 < 2) return false;
  cv::Mat crop = gray(cv::Rect(x0, y0, x1 - x0, y1 - y0));
  std::array<cv::Point2f, 4> src{};
  Eigen::Vector2d scale(1, 1);
  const double r = 2 * inner / side;
  if (r < 1) {
    const int nw = std::max(2, static_cast<int>(std::lround(crop.cols * r)));
    const int nh = std::max(2, static_cast<int>(std::lround(crop.rows * r)));
    scale = Eigen::Vector2d(static_cast<double>(nw) / crop.cols, static_cast<double>(nh) / crop.rows);
    cv::Mat shrunk;
    cv::resize(crop, shrunk, cv::Size(nw, nh), 0, 0, cv::INTER_AREA);
    crop = shrunk;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    Eigen::Vector2d c = corners[i] - Eigen::Vector2d(x0, y0);
    if (r < 1) c = (c.array() + 0.5).matrix().cwiseProduct(scale) - Eigen::Vector2d::Constant(0.5);
    src[i] = cv::Point2f(static_cast<float>(c.x()), static_cast<float>(c.y()));
  }
  const auto a = static_cast<float>(m - 0.5), b = static_cast<float>(v.patch - m - 0.5);
  const std::array<cv::Point2f, 4> dst{cv::Point2f(a, a), cv::Point2f(b, a), cv::Point2f(b, b), cv::Point2f(a, b)};
  const cv::Mat M = cv::getPerspectiveTransform(src.data(), dst.data());
  cv::Mat warped;
  cv::warpPerspective(crop, warped, M, cv::Size(v.patch, v.patch), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  double vmin = 0, vmax = 0;
  cv::minMaxLoc(warped, &vmin, &vmax);
  // (v - lo) / stretch in float, as numpy computes it (tools/detector_model.py).
  const auto lo_f = static_cast<float>(vmin), stretch = static_cast<float>(std::max(vmax - vmin, v.min_range));
  patch.create(v.patch, v.patch, CV_32FC1);
  for (int y = 0; y < v.patch; ++y) {
    const auto* in = warped.ptr<std::uint8_t>(y);
    auto* out = patch.ptr<float>(y);
    for (int x = 0; x < v.patch; ++x) out[x] = (static_cast<float>(in[x]) - lo_f) / stretch;
  }
  return true;
}

Letterbox letterbox(int frame_width, int frame_height, int input_width, int input_height) {
  Letterbox b;
  b.scale = std::min(static_cast<double>(input_width) / frame_width, static_cast<double>(input_height) / frame_height);
  b.width = std::clamp(static_cast<int>(std::lround(frame_width * b.scale)), 1, input_width);
  b.height = std::clamp(static_cast<int>(std::lround(frame_height * b.scale)), 1, input_height);
  b.offset = Eigen::Vector2d((input_width - b.width) / 2, (input_height - b.height) / 2);
  return b;
}

double box_iou(const Eigen::Vector2d& a_min, const Eigen::Vector2d& a_max, const Eigen::Vector2d& b_min,
               const Eigen::Vector2d& b_max) {
  const Eigen::Vector2d lo = a_min.cwiseMax(b_min), hi = a_max.cwiseMin(b_max);
  const double inter = std::max(0.0, hi.x() - lo.x()) * std::max(0.0, hi.y() - lo.y());
  const auto area = [](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    return std::max(0.0, to.x() - from.x()) * std::max(0.0, to.y() - from.y());
  };
  const double uni = area(a_min, a_max) + area(b_min, b_max) - inter;
  return uni > 0 ? inter / uni : 0.0;
}

double box_iou(const MarkerDetection& a, const MarkerDetection& b) {
  return box_iou(a.box_min, a.box_max, b.box_min, b.box_max);
}

std::vector<MarkerDetection> decode_heatmap(const float* out, int rows, int cols, const ModelManifest& m,
                                            const Letterbox& box, double min_confidence, double nms_iou, int id) {
  const std::size_t plane = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
  const auto at = [&](int c, int r, int q) {
    return out[static_cast<std::size_t>(c) * plane + static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) +
               static_cast<std::size_t>(q)];
  };
  std::vector<MarkerDetection> candidates;
  for (int r = 0; r < rows; ++r) {
    for (int q = 0; q < cols; ++q) {
      const float heat = at(0, r, q);
      if (!(heat >= min_confidence)) continue;  // NaN too
      bool peak = true;
      for (int dr = -1; dr <= 1 && peak; ++dr) {
        for (int dq = -1; dq <= 1; ++dq) {
          const int rr = r + dr, qq = q + dq;
          if ((dr || dq) && rr >= 0 && rr < rows && qq >= 0 && qq < cols && at(0, rr, qq) > heat) {
            peak = false;
            break;
          }
        }
      }
      if (!peak) continue;
      MarkerDetection d;
      d.id = id;
      d.confidence = std::clamp(static_cast<double>(heat), 0.0, 1.0);
      d.has_corners = true;
      d.oriented = false;
      const Eigen::Vector2d centre_in((q + static_cast<double>(at(1, r, q))) * m.stride,
                                      (r + static_cast<double>(at(2, r, q))) * m.stride);
      d.box_min = Eigen::Vector2d::Constant(1e300);
      d.box_max = Eigen::Vector2d::Constant(-1e300);
      bool finite = centre_in.allFinite();
      for (std::size_t k = 0; k < 4; ++k) {
        const int c = 3 + 2 * static_cast<int>(k);
        const Eigen::Vector2d in =
            centre_in + m.corner_scale * Eigen::Vector2d(at(c, r, q), at(c + 1, r, q)).cast<double>();
        d.corners[k] = (in - box.offset) / box.scale;
        finite = finite && d.corners[k].allFinite();
        d.box_min = d.box_min.cwiseMin(d.corners[k]);
        d.box_max = d.box_max.cwiseMax(d.corners[k]);
      }
      if (finite) candidates.push_back(d);
    }
  }
  // Greedy NMS, highest confidence first; the stable sort keeps the cell
  // order among equal confidences.
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return candidates[a].confidence > candidates[b].confidence; });
  std::vector<MarkerDetection> kept;
  for (std::size_t i : order) {
    const MarkerDetection& c = candidates[i];
    if (std::none_of(kept.begin(), kept.end(), [&](const MarkerDetection& k) { return box_iou(k, c) > nms_iou; }))
      kept.push_back(c);
  }
  return kept;
}

LearnedDetector::LearnedDetector(std::filesystem::path model, double min_confidence, double nms_iou, bool roi,
                                 int full_frame_period)
    : path_(std::move(model)),
      min_confidence_(min_confidence),
      nms_iou_(nms_iou),
      // The tracked box grown by 1.5 times its size (at least 48 px) on
      // every side, then out to the 32-px grid of the network's deepest
      // stride: a region on the whole frame's grid reads the marker as the
      // whole frame does (off the grid, the stored frame's confidence fell
      // from 0.72 to 0.59; on it, 0.726).
      region_(roi, full_frame_period, TrackingRegion::Shape{1.5, 48.0, 32, 32}) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path_, ec)) model_error(path_, "no such file");
  manifest_ = read_model_manifest(manifest_path(path_));
  try {
    net_ = cv::dnn::readNetFromONNX(path_.string());
  } catch (const cv::Exception& e) {
    model_error(path_, "not a readable ONNX model (" + std::string(e.err) + ")");
  }
  if (net_.empty()) model_error(path_, "not a readable ONNX model");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  // One blank frame: the output must be 1 × 11 × H/s × W/s.
  const cv::Mat blank(manifest_.height, manifest_.width, CV_8UC1, cv::Scalar(0));
  try {
    forward(blank);
  } catch (const cv::Exception& e) {
    model_error(path_, "does not run on a " + std::to_string(manifest_.width) + "×" + std::to_string(manifest_.height) +
                           " input (" + std::string(e.err) + ")");
  }
  const int rows = manifest_.height / manifest_.stride, cols = manifest_.width / manifest_.stride;
  if (output_.dims != 4 || output_.size[0] != 1 || output_.size[1] != manifest_.channels || output_.size[2] != rows ||
      output_.size[3] != cols) {
    std::string shape;
    for (int i = 0; i < output_.dims; ++i) shape += (i ? "×" : "") + std::to_string(output_.size[i]);
    model_error(path_, "output shape " + shape + ", expected 1×" + std::to_string(manifest_.channels) + "×" +
                           std::to_string(rows) + "×" + std::to_string(cols) + " (its manifest's)");
  }
  if (manifest_.verifier) load_verifier();
}

void LearnedDetector::load_verifier() {
  const VerifierManifest& v = *manifest_.verifier;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(v.file, ec))
    model_error(v.file, "no such file (the verifier its manifest names)");
  try {
    verifier_ = cv::dnn::readNetFromONNX(v.file.string());
  } catch (const cv::Exception& e) {
    model_error(v.file, "not a readable ONNX model (" + std::string(e.err) + ")");
  }
  if (verifier_.empty()) model_error(v.file, "not a readable ONNX model");
  verifier_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  verifier_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  // One blank patch: the output must be one probability.
  const cv::Mat blank(v.patch, v.patch, CV_32FC1, cv::Scalar(0));
  double p = -1;
  try {
    p = verify_patch(blank);
  } catch (const cv::Exception& e) {
    model_error(v.file, "does not run on a " + std::to_string(v.patch) + "×" + std::to_string(v.patch) + " patch (" +
                            std::string(e.err) + ")");
  }
  if (!(p >= 0 && p <= 1)) model_error(v.file, "its output is not one probability in [0, 1]");
}

double LearnedDetector::verify_patch(const cv::Mat& patch) {
  if (verifier_.empty()) throw std::logic_error("LearnedDetector::verify_patch: the model has no verifier");
  TD_ASSERT(patch.type() == CV_32FC1 && patch.isContinuous());
  const int shape[4] = {1, 1, patch.rows, patch.cols};
  patch_blob_ = patch.reshape(1, 4, shape);
  verifier_.setInput(patch_blob_);
  const cv::Mat p = verifier_.forward();
  if (p.total() != 1) return -1;
  return static_cast<double>(p.ptr<float>()[0]);
}

void LearnedDetector::verify(const cv::Mat& gray, std::vector<MarkerDetection>& out) {
  if (verifier_.empty()) return;
  const VerifierManifest& v = *manifest_.verifier;
  // decode_heatmap sorted the proposals by heat (highest first).
  if (out.size() > static_cast<std::size_t>(v.max_proposals)) out.resize(static_cast<std::size_t>(v.max_proposals));
  for (MarkerDetection& d : out) {
    d.confidence = extract_patch(gray, d.corners, v, patch_) ? std::clamp(verify_patch(patch_), 0.0, 1.0) : 0.0;
  }
  out.erase(std::remove_if(out.begin(), out.end(),
                           [&](const MarkerDetection& d) { return !(d.confidence >= min_confidence_); }),
            out.end());
  std::stable_sort(out.begin(), out.end(),
                   [](const MarkerDetection& a, const MarkerDetection& b) { return a.confidence > b.confidence; });
}

void LearnedDetector::reset(std::string_view dictionary, int marker_id) {
  const auto* want = pose::find_aruco_dictionary(dictionary);
  const auto* have = pose::find_aruco_dictionary(manifest_.dictionary);
  if (!want || want != have || marker_id != manifest_.marker_id)
    throw InvalidArgument(
        "learned detector: model " + path_.string() + " detects " + manifest_.dictionary + " id " +
        std::to_string(manifest_.marker_id) + ", not " + std::string(dictionary) + " id " + std::to_string(marker_id) +
        ": give the scenarios its marker (landing_scenario campaign --marker " + manifest_.dictionary + ":" +
        std::to_string(manifest_.marker_id) + ") or train a model for theirs (tools/train_detector.py)");
  region_.reset();
}

const cv::Mat& LearnedDetector::forward(const cv::Mat& gray) {
  box_ = letterbox(gray.cols, gray.rows, manifest_.width, manifest_.height);
  const auto pad = static_cast<float>(manifest_.pad_value);
  input_.create(manifest_.height, manifest_.width, CV_32FC1);
  // The padding only where the frame leaves some (a frame of the network's
  // size fills it: every frame of a campaign).
  if (box_.width != manifest_.width || box_.height != manifest_.height) input_.setTo(cv::Scalar(pad));
  cv::Mat roi =
      input_(cv::Rect(static_cast<int>(box_.offset.x()), static_cast<int>(box_.offset.y()), box_.width, box_.height));
  if (box_.width == gray.cols && box_.height == gray.rows) {
    gray.convertTo(roi, CV_32F, 1.0 / 255);
  } else {
    cv::Mat scaled;
    cv::resize(gray, scaled, cv::Size(box_.width, box_.height), 0, 0,
               box_.scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    scaled.convertTo(roi, CV_32F, 1.0 / 255);
  }
  return run_input();
}

const cv::Mat& LearnedDetector::run_input() {
  const int shape[4] = {1, 1, input_.rows, input_.cols};
  blob_ = cv::Mat(4, shape, CV_32F, input_.data);
  net_.setInput(blob_);
  output_ = net_.forward();
  return output_;
}

std::vector<MarkerDetection> LearnedDetector::decode_output() const {
  // Two stages: every peak above the proposal threshold is a candidate
  // for the verifier, which sets the confidence.
  const double threshold = manifest_.verifier ? manifest_.verifier->proposal_threshold : min_confidence_;
  return decode_heatmap(output_.ptr<float>(), output_.size[2], output_.size[3], manifest_, box_, threshold, nms_iou_,
                        manifest_.marker_id);
}

void LearnedDetector::forward_region(const cv::Mat& gray, const cv::Rect& region) {
  box_ = Letterbox{1, Eigen::Vector2d(-region.x, -region.y), region.width, region.height};
  input_.create(region.height, region.width, CV_32FC1);
  gray(region).convertTo(input_, CV_32F, 1.0 / 255);
  run_input();
}

void LearnedDetector::detect(const DetectorFrame& frame, std::vector<MarkerDetection>& out) {
  const cv::Mat gray = as_mat(frame.gray);
  cv::Rect region = region_.next(gray.cols, gray.rows);
  // Only at the network's own scale (no letterbox), so a region is read
  // exactly as the whole frame would be.
  if (gray.cols != manifest_.width || gray.rows != manifest_.height) region = {};
  if (!region.empty()) {
    forward_region(gray, region);
    out = decode_output();
    verify(gray, out);
    if (!out.empty()) {
      last_region_ = region;
      return;
    }
  }
  region_.searched_whole();
  last_region_ = cv::Rect(0, 0, gray.cols, gray.rows);
  forward(gray);
  out = decode_output();
  verify(gray, out);
}

void LearnedDetector::track(const MarkerDetection* accepted) {
  region_.track(accepted ? &accepted->box_min : nullptr, accepted ? &accepted->box_max : nullptr);
}

}  // namespace touchdown::scenario::detail
