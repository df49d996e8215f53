#pragma once
/// \file
/// The full correspondence search (no prior pose): which blob is which LED.
/// Hypothesise 4 LED ↔ 4 blob correspondences allowed by the colour classes,
/// solve EPnP for each, reproject the whole constellation, match, refine,
/// and keep the hypothesis with the least MSAC score (squared reprojection
/// error of the explained LEDs plus a fixed penalty per unexplained LED) —
/// the paper's brute-force search over permutations (eq. 7), generalised so
/// that LEDs may be missing and blobs may be spurious.
///
/// Thread-safety: a free function without shared state. Allocation: none.
#include <array>
#include <cstddef>
#include <span>
#include <string>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/led_detector.hpp"
#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

struct CorrespondenceOptions {
  double inlier_px = 6.0;              ///< a reprojected LED within this of a blob explains it [px]
  double accept_rms_px = 3.0;          ///< the final fit must reproject better than this [px]
  std::size_t max_blobs = 10;          ///< the search uses this many brightest blobs
  std::size_t max_hypotheses = 50000;  ///< bound on the EPnP solves of one search
  int min_leds = 4;                    ///< fewest LEDs a pose may rest on
  double missing_penalty_px = 3.0;     ///< score charged per unexplained LED, as a reprojection error [px]
  double min_distance = 0.1;           ///< plausible range of the constellation's distance [m]
  double max_distance = 10.0;
  /// Largest angle between body −z (where the LEDs shine) and the direction
  /// to the camera for a pose to be plausible [deg]; 180 = any.
  double max_view_angle_deg = 90.0;
  /// A pose resting on exactly four LEDs of a larger constellation must
  /// reproject better than this [px] (four points leave little redundancy).
  double minimal_fit_rms_px = 0.5;
  GaussNewtonOptions refine{20, 1e-10, 2.0};
  /// False (with the offending field and why in *why) for an invalid value.
  bool validate(std::string* why) const;
};

/// LED ↔ blob assignment and the pose it gives.
struct Correspondence {
  PoseStatus status = PoseStatus::TooFewBlobs;
  std::array<int, kMaxLeds> blob_of_led{};  ///< blob index per LED, −1 if unseen
  int matched = 0;
  PoseRefinement fit;          ///< the pose refined on the matched LEDs
  std::size_t hypotheses = 0;  ///< EPnP solves tried
  [[nodiscard]] bool ok() const { return status == PoseStatus::Ok; }
};

/// Full search (no prior pose). `blobs` should be brightest first; only the
/// first `options.max_blobs` are used.
Correspondence find_correspondences(const PinholeCamera& camera, const Constellation& constellation,
                                    std::span<const Blob> blobs, const CorrespondenceOptions& options = {});

}  // namespace touchdown::pose
