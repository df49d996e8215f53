// Marker detectors: options, the factory, the shipped model's path
// (touchdown/scenario/marker_detector.hpp).
#include "touchdown/scenario/marker_detector.hpp"

#include <cmath>
#include <cstdlib>

#include "core/hash.hpp"
#include "core/io_util.hpp"
#include "scenario/aruco_detector.hpp"
#include "scenario/learned_detector.hpp"
#include "touchdown/core/error.hpp"

#ifndef TOUCHDOWN_MODEL_PATH
#error "TOUCHDOWN_MODEL_PATH (the shipped model) is defined by src/CMakeLists.txt"
#endif

namespace touchdown::scenario {

bool DetectorOptions::validate(std::string* why) const {
  if (!detector_registry().find(kind)) return invalid(why, "detector: " + detector_registry().unknown(kind));
  if (full_frame_period < 1 || full_frame_period > 1000)
    return invalid(why, "detector.full_frame_period: must be in [1, 1000] frames");
  if (!(std::isfinite(min_confidence) && min_confidence >= 0 && min_confidence <= 1))
    return invalid(why, "detector.min_confidence: must be in [0, 1]");
  if (!(std::isfinite(nms_iou) && nms_iou > 0 && nms_iou <= 1))
    return invalid(why, "detector.nms_iou: must be in (0, 1]");
  return true;
}

std::filesystem::path default_model_path() {
  if (const char* env = std::getenv("TOUCHDOWN_MODEL"); env && *env) return env;
  // The source tree's (a build tree), else the installed copy (data/ is
  // installed to share/touchdown); neither: the source tree's, which the
  // detector's error then names.
  std::error_code ec;
  if (std::filesystem::exists(TOUCHDOWN_MODEL_PATH, ec)) return TOUCHDOWN_MODEL_PATH;
  if (std::filesystem::exists(TOUCHDOWN_INSTALLED_MODEL_PATH, ec)) return TOUCHDOWN_INSTALLED_MODEL_PATH;
  return TOUCHDOWN_MODEL_PATH;
}

std::string learned_model_id(const std::filesystem::path& model) {
  namespace core = touchdown::detail;
  const std::uint64_t h = core::fnv1a64(core::read_text_file(model));
  return core::fnv1a64_id(core::fnv1a64(core::read_text_file(detail::manifest_path(model)), h));
}

Registry<MakeDetector>& detector_registry() {
  static Registry<MakeDetector>* registry = [] {
    auto* r = new Registry<MakeDetector>("marker detector");  // never destroyed: used until exit
    r->add("aruco", "OpenCV's ArUco detector with region-of-interest tracking", [](const DetectorOptions& o) {
      return std::make_unique<detail::ArucoDetector>(o.roi, o.full_frame_period);
    });
    r->add("learned", "the learned marker detector (an ONNX model through OpenCV DNN; data/models/)",
           [](const DetectorOptions& o) {
             return std::make_unique<detail::LearnedDetector>(o.model.empty() ? default_model_path() : o.model,
                                                              o.min_confidence, o.nms_iou, o.roi, o.full_frame_period);
           });
    return r;
  }();
  return *registry;
}

std::unique_ptr<MarkerDetector> make_marker_detector(const DetectorOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  auto d = detector_registry().get(options.kind).factory(options);
  if (!d) throw InvalidArgument("detector '" + options.kind + "': its factory returned no detector");
  return d;
}

std::vector<std::string> marker_detector_names() { return detector_registry().names(); }

}  // namespace touchdown::scenario
