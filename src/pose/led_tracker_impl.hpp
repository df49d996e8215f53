#pragma once
// LedTracker's state and steps (private to the pose module): the tracker
// (led_tracker.cpp: set-up, prediction, gating, tracking, the frame's run)
// and its fit checks (led_tracker_fit.cpp: duplicates, settling a fit,
// whether a fit explains the frame, shared blobs, outliers, the noise pool).
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "pose/ambiguity.hpp"
#include "pose/assignment.hpp"
#include "pose/pose_filter.hpp"
#include "touchdown/pose/led_tracker.hpp"

namespace touchdown::pose {

struct LedTracker::Impl {
  CameraModel camera;
  PinholeCamera pin;
  Constellation constellation;
  TrackerOptions options;
  LedDetector detector;
  std::vector<Blob> detected, work;
  PoseEstimate estimate;
  std::array<int, kMaxLeds> led_to_blob{};
  // The blob drop_outlier took out of this frame's fit (−1: none): not an
  // LED's misread spot for explains_frame.
  int outlier_blob = -1;
  std::vector<double> noise_pool, noise_sorted;  // tracked fits' σ̂² (ring), scratch
  // k / χ²_k(1 − c) by k (judged_noise; 0 = not computed yet): k ≤ 2 per
  // LED + 1 per depth + 2 for the attitude − 6. Fixed size: tracking a frame
  // does not allocate.
  std::array<double, 3 * kMaxLeds> noise_bound_factor{};
  // χ²_k(1 − complete_fit_significance) by k = 2n − 6 (explains_frame; 0 =
  // not computed yet).
  std::array<double, 2 * kMaxLeds> complete_chi2_bound{};
  // The median of χ²_k / k by k (pool_noise), computed on first use.
  std::array<double, 3 * kMaxLeds> chi2_median_fraction{};
  std::size_t noise_next = 0;
  bool tracking = false;
  bool have_velocity = false;
  // The one-before-last frame's pose was reported Ok (the last frame's is
  // `estimate`): with it, a prediction is vouched for (try_track()'s jump
  // test).
  bool previous_ok = false;
  // The last frame's fit had its σ within few_point_prediction_sigma_factor
  // × the limits: a tracked fit on fewer points than the search accepts
  // may rest on its prediction (try_track()).
  bool last_nearly_precise = false;
  // Tracked fits settled since the last search's, counted up to 2 (0: this
  // track's pose came from the search).
  int tracked_since_search = 0;
  Eigen::Isometry3d last_pose = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d previous_pose = Eigen::Isometry3d::Identity();
  detail::OptimalMatcher matcher;
  detail::PoseFilter filter;
  detail::ConstellationShape shape;  // best-fit plane, symmetry: for the ambiguity checks
  AttitudeConstraint attitude;       // this frame's prior (inactive without one)
  double min_led_spacing = 0;
  double emission_margin = 0;  // [rad] slack on the LEDs' emission cones
  double const_mad = 0, const_radius = 0;
  Eigen::Vector3d const_centroid = Eigen::Vector3d::Zero();
  std::array<Eigen::Vector2d, kMaxLeds> centres{};
  std::vector<int> cluster;
  std::vector<char> keep;

  Impl(const CameraModel& c, const Constellation& k, const TrackerOptions& o);

  void set_prior(const AttitudePrior& prior);

  Eigen::Isometry3d predicted() const;

  // The paper's outlier test (3-D) and a 2-D gate around the prediction.
  void gate(const Eigen::Isometry3d& T);

  // k-means (k = number of LEDs) on the blob centres, then within each
  // cluster drop blobs closer than `radius` to a brighter member.
  void suppress_duplicates(double radius);

  // A vetted fit (branch settled, reprojection within the gate) becomes the
  // frame's answer: fused with the earlier frames (options.fuse_frames,
  // pose_filter.hpp), then Ok if its 1-σ is within the correspondence
  // options' limits, else Uncertain — no pose, but the track goes on from
  // the fit, so that the next frame is matched against its prediction
  // instead of searched from scratch (a distant board stays uncertain for
  // many frames; each search would cost more and know less). `fresh`: the
  // fit starts a new track (the filter restarts).
  void settle(const PoseRefinement& fit, int points, bool fresh);

  // The fit explains its whole frame (TrackerOptions::complete_fit_significance):
  // the pool vouches, enough points in the fit (a merged spot outside it
  // does not count), every LED in view matched (alone, in a merged spot
  // whose centre the LEDs' midpoint explains, on a split blob left out of
  // the fit or on a misread one whose centre its reprojection explains),
  // residuals at the pooled noise.
  bool explains_frame(const PoseRefinement& fit);

  // Some LED holds blob b.
  [[nodiscard]] bool held(std::size_t b) const;

  // A blob no LED holds lies within `d` [px] of `uv`: an LED projected
  // there may have a spot of its own (unmatched: its colour read wrong),
  // not a share of a merged one.
  [[nodiscard]] bool spot_of_its_own(const Eigen::Vector2d& uv, double d) const;

  bool merge_shared_blobs(PoseRefinement& fit, detail::MatchedSet& set);

  // One wrong blob in a tracked fit (a flash or a reflection next to an
  // LED's prediction): the fit reprojects far worse than the track's pooled
  // noise (TrackerOptions::outlier_rms_factor), and without one of its
  // blobs it would reproject at least twice better — that blob leaves the
  // fit (the one whose removal fits best; a merged blob with both its
  // LEDs), while search_min_leds remain (fewer points hide a wrong one's
  // pull).
  bool drop_outlier(PoseRefinement& fit, detail::MatchedSet& set);

  // The LEDs on blob b (two if merged) leave the fit.
  void leave_blob(int b);

  // The pool holds enough tracked fits to stand for this camera's noise.
  [[nodiscard]] bool pool_vouches() const;

  // The pixel noise variance a fit's covariance assumes before the floor:
  // its own σ̂², raised to its upper confidence bound while the pool does
  // not vouch (TrackerOptions::unpooled_noise_confidence).
  double judged_noise(const PoseRefinement& fit);

  // The LEDs led_to_blob holds, gathered for a fit; a small blob's own
  // error is its excess over the noise floor
  // (CorrespondenceOptions::small_blob_sigma_px3).
  void gather_matched(detail::MatchedSet& set);

  // The detection-noise variance floor (TrackerOptions::noise_pool_frames).
  double noise_floor();

  // A fit's σ̂² on k degrees of freedom enters the pool over the median of
  // χ²_k / k, so that the pool's median estimates the noise variance
  // whatever the fits' k (χ²_6 / 6 has its median at 0.89 of its mean,
  // χ²_14 / 14 at 0.95; a fixed 1.25 overstated it by 11–30 %).
  void pool_noise(double variance, double k);

  void lose(PoseStatus s);

  // The correspondence options the search and the branch test judge a fit
  // by: the default detection noise until the noise pool vouches, then the
  // camera's pooled noise (noise_floor()), so that a branch or assignment
  // that reprojects several times worse than this camera's noise is ruled
  // out rather than weighed against the 0.2 px default.
  CorrespondenceOptions judged;
  const CorrespondenceOptions& judging_options();

  bool try_track();

  const PoseEstimate& run(std::span<const Blob> blobs);
};

}  // namespace touchdown::pose
