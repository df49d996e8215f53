#pragma once
/// \file
/// Part of touchdown::pose.
/// LED relative pose: detections → correspondences → EPnP → Gauss–Newton
/// on SE(3), tracked from frame to frame.
///
/// - Initialisation (or after loss): the full correspondence search of
///   correspondence.hpp.
/// - Tracking: reproject the constellation from the predicted pose, assign
///   detections by minimum-cost matching (Hungarian algorithm), refine with
///   Gauss–Newton; re-initialise when the reprojection error exceeds a gate.
///   A fit too uncertain to report (PoseStatus::Uncertain, e.g. a distant
///   board) gives the frame no pose but keeps the track: the next frame is
///   matched against its prediction rather than searched from scratch.
/// - Outlier rejection as published: if the mean absolute deviation of the
///   detections' 3-D points exceeds the constellation's, drop points far from
///   the predicted constellation centre; then suppress duplicates within
///   k-means clusters (k = number of LEDs).
///
/// Allocation: none in steady-state tracking (tested). Thread-safety: one
/// tracker per camera stream.
#include <array>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "touchdown/core/image.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/correspondence.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/led_detector.hpp"
#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

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
  /// A tracked fit farther than this from the prediction is not the board
  /// (it moved in one frame beyond what a multirotor can: 0.25 m or
  /// 0.25 rad off a constant-velocity prediction in 1/30 s is ~450 m/s² or
  /// ~450 rad/s²): the track is dropped and the full search decides. A
  /// tracked fit on few LEDs can be far off yet reproject well (an example:
  /// docs/journal/led-pose.md, "LED pose: joined blobs out of the fit").
  double max_jump_m = 0.25;
  double max_jump_rad = 0.25;  ///< see max_jump_m [rad]
  /// A tracked frame may rest on this many LEDs (3 or more; below
  /// correspondence.min_leds) when the previous frame was Ok on the same
  /// track: an LED dropped out or left the image for a frame. Three LEDs fix
  /// a pose exactly — no residual left to check it by, and up to four P3P
  /// solutions — so the constant-velocity prediction must vouch for it: the
  /// fit is refined from the prediction (the nearest solution), the branch
  /// test's tracked-motion rule weighs the mirrored one, and the fit must lie
  /// within few_led_jump_m / few_led_jump_rad of the prediction (a 1 g
  /// acceleration moves 5.5 mm off it in 1/30 s). Its σ is the track's
  /// pooled noise through the three LEDs' geometry. = correspondence.min_leds
  /// turns it off.
  int track_min_leds = 3;
  /// A tracked fit reprojecting worse than this × the track's pooled noise
  /// (once the pool vouches) is tested for one wrong blob: the blob without
  /// which the fit reprojects best leaves it if that halves the RMS (own
  /// renderer, harsh profile: a 7-LED fit at 2.4 px among 11 blobs, where
  /// the track's fits reproject at 0.05–0.1 px, was 0.19 rad wrong with
  /// σ_rot 0.05). 0 = off, the default: at 5 it removed that frame and
  /// raised our harsh profile's Ok share by 1–2 % with no new wrong frame,
  /// but on the independent renderer it drops crowded blobs whose bias the
  /// covariance carried, and the share of frames beyond the NEES 99.9 %
  /// bound rose to 0.56 % (docs/journal/led-pose.md, "LED pose: a tracked frame
  /// on three LEDs").
  double outlier_rms_factor = 0;
  double few_led_jump_m = 0.05;
  double few_led_jump_rad = 0.05;  ///< see track_min_leds [rad]
  /// A tracked fit on fewer LEDs than the search accepts on its own
  /// (correspondence.search_min_leds, of a constellation that has more)
  /// rests on the prediction, so the last frame's fit must have had its σ
  /// within this × the σ limits (correspondence.sigma_limits); else the
  /// full search decides. A fit well beyond the limits may itself be wrong,
  /// and four points absorb a few biased centres: own renderer, harsh
  /// profile, four points tracked from a fit at 2–3 × the limit were
  /// reported 0.2–0.75 rad wrong with σ_rot 0.014–0.022 (docs/journal/led-pose.md,
  /// "LED pose: the own renderer's harsh frames"; 3 lets them through, 1
  /// costs the harsh chase sequence 4 % more frames than 1.5).
  double few_point_prediction_sigma_factor = 1.5;
  /// Fuse each frame's fit with the earlier frames of the track (an
  /// extended Kalman filter on SE(3) with constant body velocity; a jump
  /// beyond its χ² gate restarts it): the reported pose and its sigma are
  /// the fused ones, so a distant board that no single frame pins down can
  /// become certain over a few frames, at the price of some lag in fast
  /// motion. Off by default: a flight stack that fuses the poses in its own
  /// estimator needs each frame's independent measurement, not a filtered
  /// one (whose errors are correlated from frame to frame).
  bool fuse_frames = false;
  /// A pose from the full search is reported only once a tracked frame
  /// confirms it when it rests on fewer than
  /// correspondence.search_min_leds LEDs or reprojects worse than this
  /// [px]: such fits among many blobs are where chance poses hide, and a
  /// chance pose does not survive the next frame's prediction (figures:
  /// docs/journal/led-pose.md, "Data it was not tuned to").
  double confirm_rms_px = 1.0;
  /// The fused 1-σ is never below the frame's own / √fusion_max_frames:
  /// blob biases persist from frame to frame, so frames are not independent.
  double fusion_max_frames = 4;
  /// The detection noise a fit's covariance assumes is at least the frame's
  /// own residual σ̂² = cost / dof and a floor. Until the pool holds
  /// noise_pool_min_fits tracked fits the floor is
  /// correspondence.detection_sigma_px; then it is the noise scale measured
  /// on this camera: the median of the last noise_pool_frames tracked
  /// fits' σ̂², each over the median of χ²_k / k for its k degrees of
  /// freedom (0.89 for k = 6: a χ²'s median lies below its mean; a fixed
  /// 1.25 before 2026-11-28 overstated it by 11–30 %), at least
  /// min_detection_sigma_px² — and
  /// above detection_sigma_px² when the camera is noisier than that default
  /// (before issue 33 the pool was capped there, and a 0.5 px camera's σ
  /// then came from single frames' σ̂²). One frame's σ̂² rests
  /// on 6–14 degrees of freedom and can be small by chance; the pool's
  /// median cannot, and a sensor quieter than the default floor no longer
  /// has its poses' sigma overstated (docs/journal/led-pose.md, "Data it was not
  /// tuned to", the sigma calibration). 0 = off.
  int noise_pool_frames = 30;
  /// Fits the pool needs before it replaces the default floor: the median
  /// of 5 σ̂² with 6–14 degrees of freedom each is within a factor 2 of the
  /// noise; waiting for more fits would leave more of a sequence's first
  /// frames judged at the default floor (docs/journal/led-pose.md, "LED pose:
  /// physical reflections").
  int noise_pool_min_fits = 5;
  /// Until the pool vouches, a frame noisier than the default floor is
  /// judged by its own σ̂², which rests on a few degrees of freedom and is
  /// often well below the noise by chance (σ̂² ~ σ² χ²_k / k: with k = 6,
  /// below half of σ² one time in five): the σ it would give does not cover
  /// the error (a board at 3 m with 0.5 px noise came out 0.155 rad wrong
  /// with σ_rot 0.039). The covariance then assumes the upper bound
  /// σ̂² k / χ²_k(1 − c) of the noise at this confidence c instead (k = 6:
  /// 3.7 σ̂²). 0 = off (the point estimate).
  double unpooled_noise_confidence = 0.95;
  /// A matched blob within 1.5 × its radius √(area/π) + this [px] of an
  /// unmatched, facing LED's reprojection (and no unmatched blob nearer to
  /// it) is the two LEDs' spots merged: both LEDs hold it (led_to_blob()),
  /// it leaves the fit while 4 other points remain (else it is one point
  /// at the LEDs' midpoint, CorrespondenceOptions::merged_bias), and a fit
  /// that explains its frame must reproject that midpoint onto it. < 0 = off.
  double shared_blob_margin_px = 0.5;
  /// [px] the pooled floor's lower bound, just above the best a centroid
  /// of an 8-bit spot does: large isolated spots' centres are 0.006 px off
  /// per axis (robust σ, on the independent renderer and on our own); the
  /// pool's median is what counts above it. 0.05 overstated the sigma of
  /// an independent renderer's poses ~1.6x (NEES mean 2.1 instead of 6),
  /// 0.01 that of near frames (NEES 3.2 at 0.4–1 m; docs/journal/led-pose.md,
  /// "LED pose: a small spot's centre").
  double min_detection_sigma_px = 0.007;
  /// "Ok means unimodal" (issue 33, item 1): a tracked fit that explains
  /// its whole frame is held to the complete_max_sigma_* limits (none by
  /// default) instead of correspondence.sigma_limits, which stay as the
  /// safety net for every other fit. It explains the frame when
  /// - it is tracked, from the second tracked frame after a search on (the
  ///   first is matched from the search's own pose), and the noise pool
  ///   vouches (the camera's noise is measured, noise_pool_min_fits);
  /// - it rests on at least min(correspondence.search_min_leds, LEDs)
  ///   points (a merged spot left out of it, shared_blob_margin_px, does
  ///   not count);
  /// - every LED the fit puts in front of the camera, shining toward it
  ///   (emission cone + correspondence.emission_margin_deg) and at least
  ///   complete_fit_border_px inside the image has a blob: its own (a
  ///   split one the fit left out is tested at the LED's reprojection in
  ///   its split_bias variance, within its own χ²₂ bound), a merged spot's
  ///   whose centre the two LEDs' midpoint explains, or one no LED holds,
  ///   read White or Unknown, at its reprojection within its own χ²₂ bound
  ///   (its colour misread: a spot lit by two neighbours of other colours
  ///   reads white; not a blob of another colour, nor the one drop_outlier
  ///   took out of the fit) — an LED in view without one is a drop-out, an
  ///   unmodelled merge or a wrong assignment, none of which the σ covers;
  /// - its reprojections are the camera's noise: Σ |rᵢ|² / (pooled floor +
  ///   blob i's own bias variance: crowding, split, small and large spot),
  ///   over the fit and the blobs above, is within the χ² quantile with
  ///   2m − 6 degrees of freedom (m points) at 1 − complete_fit_significance (a wrong
  ///   blob in the fit reprojects at many times the noise; depths and the
  ///   attitude prior, which add degrees of freedom, are left out: the test
  ///   is the stricter for it).
  /// A fit held to these limits still gives the next frame's few-point
  /// rules (few_point_prediction_sigma_factor) only a prediction within
  /// the regular limits.
  /// Measured (docs/journal/led-pose.md, "LED pose: a fit that explains its
  /// frame"): the independent renderer's 14 400 frames gain 0.8 % (single)
  /// and 0.5 % (attitude) with no wrong frame; on our own renderer the
  /// fits that lifting the limits let through wrong carried a wrong blob, a
  /// merged pair or a fresh search's pose — the rules above; what is left
  /// there is 1 frame in 25 600 at 3.06 σ (a true σ's tail). Split and
  /// misread blobs (docs/journal/led-pose.md, "LED pose: a split or misread
  /// blob, a large spot"): held-out success 0.970 → 0.993, none wrong.
  /// complete_fit_significance = 0 turns it off (every fit within
  /// correspondence.sigma_limits).
  double complete_fit_significance = 1e-3;
  double complete_fit_border_px = 5;
  double complete_max_sigma_position_m = std::numeric_limits<double>::infinity();
  double complete_max_sigma_rotation_rad = std::numeric_limits<double>::infinity();
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The gravity ("down") direction measured on both sides of the link, for
/// one frame: by the camera's own IMU (the vehicle's) in the camera frame
/// and by the drone's IMU (its flight controller's attitude) in the body
/// frame, each a unit vector with `sigma_rad` of noise (1-σ per axis).
/// With it the tracker fixes the board's tilt (the two rotation angles
/// about horizontal axes) that a small, distant or nearly flat board's
/// image leaves loose: the correspondence search drops hypotheses that
/// contradict it (CorrespondenceOptions::attitude_gate_chi2), the mirrored
/// branch is judged with it, and it is a term of every Gauss–Newton fit
/// (AttitudeConstraint, σ = √2·sigma_rad for the difference of the two).
struct AttitudePrior {
  Eigen::Vector3d g_camera = Eigen::Vector3d::Zero();
  Eigen::Vector3d g_body = Eigen::Vector3d::Zero();
  double sigma_rad = 0;  ///< > 0 [rad]
  /// False (and why) unless both vectors are finite and unit (within 1e-3)
  /// and sigma_rad is in (0, π/2].
  [[nodiscard]] bool validate(std::string* why) const;
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
  /// The same with the frame's attitude prior. Throws InvalidArgument if
  /// `prior` does not validate.
  const PoseEstimate& track(const BgrImageView& colour, const DepthImageView* depth, const AttitudePrior& prior);
  /// The same from blobs detected elsewhere (uv_undistorted and color used).
  const PoseEstimate& track_blobs(std::span<const Blob> blobs);
  const PoseEstimate& track_blobs(std::span<const Blob> blobs, const AttitudePrior& prior);
  /// Forget the track: the next frame runs the full search.
  void reset();

  [[nodiscard]] const PoseEstimate& last() const;
  /// The blobs of the last frame after gating (indices used by led_to_blob()).
  [[nodiscard]] const std::vector<Blob>& blobs() const;
  /// Each LED's blob in blobs() (−1: none); two LEDs whose spots merged hold
  /// the same blob.
  [[nodiscard]] const std::array<int, kMaxLeds>& led_to_blob() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
