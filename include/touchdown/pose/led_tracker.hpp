#pragma once
/// \file
/// LED relative pose (issue 4, items 1–3): detections → correspondences →
/// EPnP → Gauss–Newton on SE(3), tracked from frame to frame.
///
/// - Initialisation (or after loss): hypothesise 4 LED ↔ 4 blob
///   correspondences allowed by the colour classes, solve EPnP for each,
///   reproject the whole constellation, match, refine, and keep the
///   hypothesis with the least MSAC score (squared reprojection error of the
///   explained LEDs plus a fixed penalty per unexplained LED) — the paper's
///   brute-force search over permutations (eq. 7), generalised so that LEDs
///   may be missing and blobs may be spurious.
/// - Tracking: reproject the constellation from the predicted pose, assign
///   detections by minimum-cost matching (Hungarian algorithm), refine with
///   Gauss–Newton; re-initialise when the reprojection error exceeds a gate.
/// - Outlier rejection as published: if the mean absolute deviation of the
///   detections' 3-D points exceeds the constellation's, drop points far from
///   the predicted constellation centre; then suppress duplicates within
///   k-means clusters (k = number of LEDs).
///
/// Allocation: none in steady-state tracking (tested). Thread-safety: one
/// tracker per camera stream.
#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/image.hpp"
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
  bool validate(std::string* why) const;
};

/// LED ↔ blob assignment and the pose it gives.
struct Correspondence {
  PoseStatus status = PoseStatus::TooFewBlobs;
  std::array<int, kMaxLeds> blob_of_led{};  ///< blob index per LED, −1 if unseen
  int matched = 0;
  PoseRefinement fit;          ///< the pose refined on the matched LEDs
  std::size_t hypotheses = 0;  ///< EPnP solves tried
};

/// Full search (no prior pose). `blobs` should be brightest first.
Correspondence find_correspondences(const PinholeCamera& camera, const Constellation& constellation,
                                    std::span<const Blob> blobs, const CorrespondenceOptions& options = {});

struct TrackerOptions {
  DetectorOptions detector;
  CorrespondenceOptions correspondence;
  bool use_depth = true;            ///< use the depth image (gate, 3-D outlier test) when given
  double track_gate_px = 15.0;      ///< tracking: a blob farther than this from its predicted LED is not it [px]
  double reinit_rms_px = 3.0;       ///< tracking fit worse than this → full search [px]
  double mad_ratio = 2.0;           ///< outlier test: detections' MAD vs the constellation's
  double centre_gate = 1.5;         ///< keep 3-D points within this × constellation radius of the predicted centre
  double duplicate_fraction = 0.3;  ///< blobs closer than this × the smallest projected LED spacing are duplicates
  bool constant_velocity = true;    ///< predict with the last inter-frame motion
  bool validate(std::string* why) const;
};

class LedTracker {
 public:
  /// Throws InvalidArgument on an invalid camera, constellation or options.
  LedTracker(const CameraModel& camera, const Constellation& constellation, const TrackerOptions& options = {});
  ~LedTracker();
  LedTracker(LedTracker&&) noexcept;
  LedTracker& operator=(LedTracker&&) noexcept;

  /// One frame: detect, gate, match (or search), refine.
  const PoseEstimate& track(const BgrImageView& colour, const DepthImageView* depth = nullptr);
  /// The same from blobs detected elsewhere (uv_undistorted and color used).
  const PoseEstimate& track_blobs(std::span<const Blob> blobs);
  /// Forget the track: the next frame runs the full search.
  void reset();

  [[nodiscard]] const PoseEstimate& last() const;
  /// The blobs of the last frame after gating (indices used by led_to_blob()).
  [[nodiscard]] const std::vector<Blob>& blobs() const;
  [[nodiscard]] const std::array<int, kMaxLeds>& led_to_blob() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
