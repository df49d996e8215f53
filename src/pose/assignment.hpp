#pragma once
// LED ↔ blob assignment shared by the correspondence search and the tracker
// (internal to touchdown::pose): gathering matched points for the solvers,
// greedy gated matching for verifying hypotheses, and minimum-cost matching
// (Hungarian algorithm) for tracking. Fixed-capacity storage: no allocation.
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <span>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/correspondence.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/led_detector.hpp"

namespace touchdown::pose::detail {

// Points of the matched LEDs, gathered into fixed arrays for the solvers.
struct MatchedSet {
  std::array<Eigen::Vector3d, kMaxLeds> p;
  std::array<Eigen::Vector2d, kMaxLeds> uv;
  std::array<double, kMaxLeds> z;      // the blob's measured depth [m], NaN = none
  std::array<double, kMaxLeds> sigma;  // its 1-σ [m]
  std::array<int, kMaxLeds> blob;      // the blob's index
  std::array<double, kMaxLeds> bias;   // the blob centre's own error variance [px²] (blob_bias_variance)
  std::array<bool, kMaxLeds> merged;   // two LEDs' merged spot: p is their midpoint
  std::size_t n = 0;
  bool has_bias = false;     // some bias[i] > 0
  std::size_t depths = 0;    // points with a measured depth
  double pixel_sigma = 0.2;  // [px] the depth residuals' scale
  [[nodiscard]] std::span<const Eigen::Vector3d> points() const { return {p.data(), n}; }
  [[nodiscard]] std::span<const Eigen::Vector2d> pixels() const { return {uv.data(), n}; }
  // The blobs' own error variances for the Gauss–Newton covariance (none when all are 0).
  [[nodiscard]] std::span<const double> biases() const {
    return has_bias ? std::span<const double>{bias.data(), n} : std::span<const double>{};
  }
  // The measured depths for the Gauss–Newton refinement (none if no blob has one).
  [[nodiscard]] DepthConstraints depth() const {
    if (depths == 0) return {};
    return {{z.data(), n}, {sigma.data(), n}, pixel_sigma};
  }
};

// The camera centre in the body frame.
Eigen::Vector3d camera_in_body(const Eigen::Isometry3d& T_camera_body);

// An LED at `q` (camera frame) is in front of the camera and shines toward
// it (`camera_body`: camera_in_body) within `emission_margin` [rad] of its cone.
inline bool faces_camera(const Led& led, const Eigen::Vector3d& q, const Eigen::Vector3d& camera_body,
                         double emission_margin) {
  return q.z() > 1e-6 && led.emits_toward(camera_body, emission_margin);
}

// True if every LED with a blob in `blob_of_led` shines toward the camera
// at `T_camera_body`, within `emission_margin` [rad] of its cone.
bool matched_leds_face_camera(const Constellation& constellation, const std::array<int, kMaxLeds>& blob_of_led,
                              const Eigen::Isometry3d& T_camera_body, double emission_margin);

// The variance [px²] of blob b's centre error of its own under o's
// crowding model (CorrespondenceOptions::crowded_bias_px): from the nearest
// other blob of `blobs` and b's split flag; plus a small spot's error above
// `noise_variance`, the pixel noise the fit is judged by
// (CorrespondenceOptions::small_blob_sigma_px3).
double blob_bias_variance(const Blob& b, std::span<const Blob> blobs, const CorrespondenceOptions& o,
                          double noise_variance);

// The other LED whose blob in `blob_of_led` is LED l's (their spots
// merged), or −1.
int partner_of(const Constellation& constellation, const std::array<int, kMaxLeds>& blob_of_led, std::size_t l);

// Fills `s` with the LEDs that have a blob in `blob_of_led` (−1: none); two
// LEDs on one blob (merged spots) give one point at their midpoint.
// The matched set for a pose fit under `o` (depths fused when o.fuse_depth,
// each blob's blob_bias_variance above `noise_variance` [px²]; without it,
// above o.detection_sigma_px²).
void gather(const Constellation& constellation, std::span<const Blob> blobs,
            const std::array<int, kMaxLeds>& blob_of_led, const CorrespondenceOptions& o, MatchedSet& s);
void gather(const Constellation& constellation, std::span<const Blob> blobs,
            const std::array<int, kMaxLeds>& blob_of_led, const CorrespondenceOptions& o, MatchedSet& s,
            double noise_variance);

// Depths come from the blobs' 3-D points (Blob::has_point) with 1-σ
// depth_sigma_k·z² + 2 mm; depth_sigma_k < 0 gathers no depths. A merged
// spot is a point only while fewer than 4 other points remain.
void gather(const Constellation& constellation, std::span<const Blob> blobs,
            const std::array<int, kMaxLeds>& blob_of_led, MatchedSet& s, double depth_sigma_k = -1,
            double pixel_sigma = 0.2);

// Greedy nearest-blob matching of every reprojected LED within `gate` [px]
// (fast; for verifying hypotheses). LEDs behind the camera or shining away
// from it by more than `emission_margin` [rad] beyond their cone are not
// matched. Returns the number matched; `sq` gets the sum of squared
// distances.
int greedy_match(const PinholeCamera& camera, const Constellation& constellation, std::span<const Blob> blobs,
                 const Eigen::Isometry3d& T_camera_body, double gate, double emission_margin,
                 std::array<int, kMaxLeds>& blob_of_led, double& sq);

// Hungarian algorithm (potentials form, O(n² m)) for an n × m cost matrix
// with n ≤ kMaxLeds rows and m ≤ kMaxCols columns, n ≤ m.
class Hungarian {
 public:
  static constexpr std::size_t kMaxCols = 64;
  // `cost` row-major n × m; `row_to_col` gets each row's column.
  void solve(const double* cost, std::size_t n, std::size_t m, std::array<int, kMaxLeds>& row_to_col);

 private:
  std::array<double, kMaxLeds + 1> u_{};
  std::array<double, kMaxCols + 1> v_{}, minv_{};
  std::array<int, kMaxCols + 1> p_{}, way_{};
  std::array<bool, kMaxCols + 1> used_{};
};

// Minimum-cost assignment of reprojected LEDs to blobs, with its workspace;
// pairs farther than the gate or of incompatible colour, and LEDs that
// greedy_match would not match, are not matched.
class OptimalMatcher {
 public:
  // Returns the number of LEDs matched.
  int match(const PinholeCamera& camera, const Constellation& constellation, std::span<const Blob> blobs,
            const Eigen::Isometry3d& T_camera_body, double gate, double emission_margin,
            std::array<int, kMaxLeds>& blob_of_led);

 private:
  Hungarian hungarian_;
  std::array<double, kMaxLeds * Hungarian::kMaxCols> cost_{};
};

}  // namespace touchdown::pose::detail
