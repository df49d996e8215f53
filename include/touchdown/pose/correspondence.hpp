#pragma once
/// \file
/// Part of touchdown::pose.
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
#include <utility>

#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/led_detector.hpp"
#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

struct CorrespondenceOptions {
  double inlier_px = 6.0;      ///< a reprojected LED within this of a blob explains it [px]
  double accept_rms_px = 3.0;  ///< the final fit must reproject better than this [px]
  std::size_t max_blobs = 10;  ///< the search uses this many brightest blobs
  /// When the max_blobs brightest give no pose and more were detected, the
  /// search goes on with the 4-tuples that use the next ones, up to this
  /// many blobs in all (within the same max_hypotheses). Airframe
  /// reflections and lamps can outshine the LEDs themselves: a clipped LED
  /// core caps its summed brightness, a wider reflection's is not
  /// (docs/journal/led-pose.md, "Data it was not tuned to").
  std::size_t max_blobs_retry = 16;
  std::size_t max_hypotheses = 50000;  ///< bound on the EPnP solves of one search
  /// Before EPnP, a hypothesis' fourth LED must lie within p3p_gate ×
  /// inlier_px of where a P3P pose of its first three puts it (0 = off).
  /// P3P leaves all the noise to the fourth point, so the gate stays wider
  /// than inlier_px; 1.5 keeps a margin over the fourth point's error on
  /// harsh frames while skipping most EPnP solves (the gate scan:
  /// docs/journal/led-pose.md, "LED pose: joined blobs out of the fit").
  double p3p_gate = 1.5;
  int min_leds = 4;  ///< fewest LEDs a pose may rest on
  /// Fewest LEDs a pose found by the full search (no prior) may rest on,
  /// when it expects more than this (LEDs in front of the camera shining
  /// toward it within emission_margin_deg): min(search_min_leds,
  /// expected − 1).
  /// Four points leave two redundant measurements, and of the thousands of
  /// wrong 4-tuples a search tries some fit by chance (docs/journal/led-pose.md,
  /// "Data it was not tuned to"). Tracking (with a prior) needs min_leds.
  int search_min_leds = 5;
  double missing_penalty_px = 3.0;  ///< score charged per unexplained LED, as a reprojection error [px]
  double min_distance = 0.1;        ///< plausible range of the constellation's distance [m]
  double max_distance = 10.0;
  /// Slack on each LED's emission cone (Led::half_angle_deg) [deg]: an LED
  /// is matched only if it shines toward the camera within this, and a pose
  /// is implausible if a matched LED would shine away by more.
  double emission_margin_deg = 15.0;
  /// A pose resting on exactly four LEDs of a larger constellation must
  /// reproject better than this [px] (four points leave little redundancy).
  double minimal_fit_rms_px = 0.5;
  GaussNewtonOptions refine{20, 1e-10, 2.0};

  // --- ambiguity (never a confident wrong pose) ---
  /// Floor of the 1-σ noise of a blob centre [px]: the noise the residuals
  /// estimate (Σr² / (2n − 6)) is raised to at least this, for the
  /// reprojection test between pose branches and the reported sigma.
  double detection_sigma_px = 0.2;
  /// detection_sigma_px is this camera's measured noise, not a default (the
  /// tracker sets it from its noise pool): the branch test then judges both
  /// branches by the better one's residual variance (floored at it) rather
  /// than the worse one's.
  bool detection_sigma_measured = false;
  /// A blob whose centre lies within crowded_radii of its own radii
  /// (r = √(area/π)) of another blob's centre is pulled by that blob's
  /// glow: an error of its own, not the common pixel noise, which does not
  /// average out over the LEDs and which the fit's residuals hide (the fit
  /// leans toward it). Its variance is added to the fit's covariance (not
  /// to its weights; GaussNewton's bias_variance): (crowded_bias_px · f)²,
  /// f = 1 at half crowded_radii or closer, falling to 0 at crowded_radii
  /// as ((crowded_radii − q) / (crowded_radii / 2))², q the distance in
  /// radii. Measured on an independent renderer's frames (docs/journal/led-pose.md,
  /// "LED pose: the sigma made true"): isolated centres 0.008–0.03 px off
  /// (RMS), centres 4–5 radii from another 0.04–0.08 px, 3–4 radii 0.14 px.
  /// 0 = off.
  double crowded_radii = 8;
  double crowded_bias_px = 0.05;
  /// A blob split from a larger one (Blob::split; its neighbour's glow
  /// pulls it by up to a pixel) has a bias of at least split_bias · r.
  double split_bias = 0.25;
  /// One blob that holds two LEDs' spots (the tracker assigns both LEDs to
  /// it: their spots touch at range or grazing) is fitted as the two LEDs'
  /// midpoint, with a bias of merged_bias · r (r of the merged blob): its
  /// centre is the spots' brightness-weighted mean, and the two LEDs'
  /// brightness differs (emission angle, halo), so the mean lies off the
  /// midpoint along the line between them (docs/journal/led-pose.md, "LED pose:
  /// a merged spot").
  double merged_bias = 0.3;
  /// A small spot's centre is less sure than a large one's (pixel sampling
  /// of a spot a few pixels wide, the threshold's edge): its error is about
  /// small_blob_sigma_px3 / area [px] per axis, area in px. Where that
  /// exceeds the pixel noise the fit is judged by (the tracker's pooled
  /// noise; detection_sigma_px without a pool), the excess variance is the
  /// blob's own, like the crowding bias: (k/area)² − noise², when positive.
  /// Only the excess, so that a pool that has caught up with a distant
  /// board's small spots is not counted twice. Measured (docs/journal/led-pose.md,
  /// "LED pose: a small spot's centre"): per-axis RMS of isolated centres
  /// ≈ 0.28/area on the independent renderer, 0.16–0.33/area on ours
  /// (clean/harsh); 0 = off.
  double small_blob_sigma_px3 = 0.3;
  /// A large spot's centre is less sure again: its core clips (a flat top
  /// whose edge alone places it) and its halo spreads the sensor noise over
  /// a wider ring — per-axis error ≈ large_blob_sigma_px · √area [px],
  /// added in variance to the small-spot term and counted like it (the
  /// excess over the noise the fit is judged by). Measured
  /// (docs/journal/led-pose.md, "LED pose: a split or misread blob, a large
  /// spot"): robust σ of isolated centres 0.0064–0.0069 px at 50–200 px,
  /// 0.008 at 200–250, 0.010–0.013 at 250–700 on the independent renderer
  /// at 0.4–0.6 m (our renderer's spots stay below 250 px). 0.0005 matches
  /// it up to ~250 px and underpredicts above (0.0087 px at 300, 0.0100 at
  /// 400, total with a 0.007 px floor): 0.0006 fits there but put the
  /// benchmark's attitude-mode NEES at 0.4–1 m under its lower bound. 0 =
  /// off.
  double large_blob_sigma_px = 0.0005;
  /// A branch whose Σ squared reprojection error exceeds the other's by more
  /// than this × detection_sigma_px² is ruled out (χ², 3σ = 9).
  double branch_chi2 = 9.0;
  /// Depth noise of the depth camera, σ_z = depth_sigma_k·z² (+ 2 mm)
  /// [1/m]: the scale of the depth test between pose branches.
  double depth_sigma_k = 0.0025;
  /// Fuse the blobs' measured depths (σ_z above) into the Gauss–Newton
  /// refinement (DepthConstraints): pins the distance and the tilt a
  /// quasi-planar board's reprojection leaves loose — when the depth at an
  /// LED is the LED's. Off by default (issue 33): on sequences from a
  /// renderer that is not ours the depth read around a small LED spot at
  /// range mixes in the drone's body behind it, and the fused fits came
  /// out 4–5 cm too far at 2 m with a σ of 1 cm (dangerous frames, NEES
  /// 89 on the position at 2–3 m); without fusion, success over 0.4–3 m
  /// went from 0.62 to 0.94 with no dangerous frame (docs/journal/led-pose.md,
  /// "LED pose on an independent renderer"). The depth still gates blobs,
  /// tests 3-D outliers and settles the mirrored branch (depth_misfit,
  /// which removes a common offset).
  bool fuse_depth = false;
  /// The tracked motion rules a branch out when its rotation is farther from
  /// the prediction than the other's by more than this [deg] (a constant-
  /// velocity prediction is good to a degree or two per frame).
  double branch_track_deg = 3.0;
  /// Two poses closer than these are the same answer, not an ambiguity
  /// [m], [deg] (either is within the 0.1 m / 0.1 rad a wrong pose is
  /// counted from).
  double branch_distinct_m = 0.05;
  double branch_distinct_deg = 5.0;
  /// With an attitude prior (LedTracker::track's AttitudePrior), a pose
  /// whose gravity misfit χ² = |R g_body − g_camera|² / σ² (2 degrees of
  /// freedom) exceeds this is not the board: 13.8 is the 99.9 % point.
  double attitude_gate_chi2 = 13.8;
  /// A pose whose 1-σ position [m] or rotation [rad] (root of the
  /// covariance's trace: the RMS of the 3-D error) exceeds these is
  /// Uncertain, not Ok (`led_pose --max-sigma`). On by default without an
  /// attitude prior, as a safety net: the branch and correspondence tests
  /// do not yet exclude every other explanation of a frame, and a wrong
  /// branch comes with a σ that does not cover it. Measured on 14 400
  /// frames from the independent renderer (docs/journal/led-pose.md, "LED pose on
  /// an independent renderer"): without the limit success rises from 0.907
  /// to 0.932 but 226 frames are wrong beyond 3 σ (4- and 6-LED boards at
  /// 2–3 m); 0.03 and 0.04 give none. First set from a scan on our own
  /// renderer ("Data it was not tuned to"). With fuse_frames the frame's
  /// own σ must pass as well as the fused one. The tracker does not hold a
  /// tracked fit that explains its whole frame to these limits
  /// (TrackerOptions::complete_fit_significance).
  double max_sigma_position_m = 0.03;
  double max_sigma_rotation_rad = 0.03;
  /// The limits when an attitude prior is given (LedTracker::track with an
  /// AttitudePrior): the same 0.03 by default. On the independent
  /// renderer's frames the prior without a limit gave 0.986 success and no
  /// frame wrong beyond 3 σ; on our own renderer's harsh profile 2 of 1 524
  /// Ok frames were (tracked fits reprojecting at 1.6–2.4 px: a wrong blob
  /// in the fit, which no noise model covers) — so the limit stays
  /// (docs/journal/led-pose.md, "LED pose: a noisy camera's sigma").
  double attitude_max_sigma_position_m = 0.03;
  double attitude_max_sigma_rotation_rad = 0.03;
  /// The limits (position [m], rotation [rad]) that apply with or without
  /// an attitude prior.
  [[nodiscard]] std::pair<double, double> sigma_limits(bool with_attitude) const {
    return with_attitude ? std::pair{attitude_max_sigma_position_m, attitude_max_sigma_rotation_rad}
                         : std::pair{max_sigma_position_m, max_sigma_rotation_rad};
  }
  /// False (with the offending field and why in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
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
/// first `options.max_blobs` are used. The winner is checked for ambiguity
/// (the mirrored branch of a quasi-planar constellation, a rigidly
/// symmetric constellation): status Ambiguous when no evidence — the
/// reprojection error, the depth at the blobs — tells the branches apart.
Correspondence find_correspondences(const PinholeCamera& camera, const Constellation& constellation,
                                    std::span<const Blob> blobs, const CorrespondenceOptions& options = {});

}  // namespace touchdown::pose
