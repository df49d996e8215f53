#include "touchdown/pose/led_tracker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "pose/led_tracker_impl.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::pose {

bool TrackerOptions::validate(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!detector.validate(why)) return false;
  if (!correspondence.validate(why)) return false;
  if (!(track_gate_px > 0)) return fail("track_gate_px: must be positive");
  if (!(reinit_rms_px > 0)) return fail("reinit_rms_px: must be positive");
  if (!(mad_ratio > 0)) return fail("mad_ratio: must be positive");
  if (!(centre_gate > 0)) return fail("centre_gate: must be positive");
  if (!(max_jump_m > 0)) return fail("max_jump_m: must be positive");
  if (!(max_jump_rad > 0)) return fail("max_jump_rad: must be positive");
  if (!(duplicate_fraction >= 0 && duplicate_fraction < 1)) return fail("duplicate_fraction: must be in [0, 1)");
  if (!(confirm_rms_px > 0)) return fail("confirm_rms_px: must be positive");
  if (!(fusion_max_frames >= 1 && fusion_max_frames <= 1e6)) return fail("fusion_max_frames: must be in [1, 1e6]");
  if (noise_pool_frames < 0 || noise_pool_frames > 1000) return fail("noise_pool_frames: must be in 0..1000");
  if (noise_pool_min_fits < 1 || (noise_pool_frames > 0 && noise_pool_min_fits > noise_pool_frames)) {
    return fail("noise_pool_min_fits: must be in 1..noise_pool_frames");
  }
  if (track_min_leds < 3 || track_min_leds > correspondence.min_leds) {
    return fail("track_min_leds: must be in 3..correspondence.min_leds");
  }
  if (!(outlier_rms_factor >= 0) || !std::isfinite(outlier_rms_factor)) {
    return fail("outlier_rms_factor: must be >= 0 (0 = off)");
  }
  if (!(few_led_jump_m > 0)) return fail("few_led_jump_m: must be positive");
  if (!(few_led_jump_rad > 0)) return fail("few_led_jump_rad: must be positive");
  if (!(few_point_prediction_sigma_factor >= 1) || !std::isfinite(few_point_prediction_sigma_factor)) {
    return fail("few_point_prediction_sigma_factor: must be >= 1 and finite");
  }
  if (!(unpooled_noise_confidence >= 0 && unpooled_noise_confidence < 1)) {
    return fail("unpooled_noise_confidence: must be in [0, 1)");
  }
  if (!std::isfinite(shared_blob_margin_px)) return fail("shared_blob_margin_px: must be finite (< 0 = off)");
  if (!(min_detection_sigma_px > 0 && min_detection_sigma_px <= correspondence.detection_sigma_px)) {
    return fail("min_detection_sigma_px: must be in (0, correspondence.detection_sigma_px]");
  }
  if (!(complete_fit_significance >= 0 && complete_fit_significance < 1)) {
    return fail("complete_fit_significance: must be in [0, 1) (0 = off)");
  }
  if (!(complete_fit_border_px >= 0) || !std::isfinite(complete_fit_border_px)) {
    return fail("complete_fit_border_px: must be >= 0 and finite");
  }
  if (!(complete_max_sigma_position_m > 0)) return fail("complete_max_sigma_position_m: must be positive");
  if (!(complete_max_sigma_rotation_rad > 0)) return fail("complete_max_sigma_rotation_rad: must be positive");
  return true;
}

bool AttitudePrior::validate(std::string* why) const {
  auto unit = [](const Eigen::Vector3d& v) { return v.allFinite() && std::abs(v.norm() - 1) <= 1e-3; };
  if (!unit(g_camera)) return invalid(why, "attitude prior: g_camera must be a finite unit vector");
  if (!unit(g_body)) return invalid(why, "attitude prior: g_body must be a finite unit vector");
  if (!(sigma_rad > 0 && sigma_rad <= std::numbers::pi / 2)) {
    return invalid(why, "attitude prior: sigma_rad must be in (0, pi/2]");
  }
  return true;
}

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

LedTracker::Impl::Impl(const CameraModel& c, const Constellation& k, const TrackerOptions& o)
    : camera(c), pin(c.pinhole()), constellation(k), options(o), detector(c, o.detector) {
  detected.reserve(o.detector.max_blobs);
  work.reserve(o.detector.max_blobs);
  cluster.reserve(o.detector.max_blobs);
  keep.reserve(o.detector.max_blobs);
  noise_pool.reserve(static_cast<std::size_t>(o.noise_pool_frames));
  noise_sorted.reserve(static_cast<std::size_t>(o.noise_pool_frames));
  min_led_spacing = kInf;
  for (std::size_t i = 0; i < k.leds.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j)
      min_led_spacing = std::min(min_led_spacing, (k.leds[i].p_body - k.leds[j].p_body).norm());
  }
  emission_margin = deg_to_rad(o.correspondence.emission_margin_deg);
  shape = detail::ConstellationShape::of(k);
  const_mad = k.mean_absolute_deviation();
  const_radius = k.radius();
  const_centroid = k.centroid();
  led_to_blob.fill(-1);
}

void LedTracker::Impl::set_prior(const AttitudePrior& prior) {
  std::string why;
  if (!prior.validate(nullptr)) {
    (void)prior.validate(&why);  // false again: called only for the message
    throw InvalidArgument(why);
  }
  attitude.g_camera = prior.g_camera.normalized();
  attitude.g_body = prior.g_body.normalized();
  attitude.sigma_rad = std::sqrt(2.0) * prior.sigma_rad;  // the difference of two directions
  // Weighed against the reprojections by the pixel noise they have: the
  // track's pooled estimate (noise_floor()), else the default floor.
  attitude.pixel_sigma_px = std::sqrt(noise_floor());
}

Eigen::Isometry3d LedTracker::Impl::predicted() const {
  if (!options.constant_velocity || !have_velocity) return last_pose;
  // Δ = T_k T_{k−1}⁻¹ applied once more; re-orthonormalised, since the
  // extrapolation amplifies rounding in the rotation frame after frame.
  Eigen::Isometry3d T = last_pose * previous_pose.inverse() * last_pose;
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return T;
}

void LedTracker::Impl::gate(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d c = T * const_centroid;
  if (options.use_depth) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    int np = 0;
    for (const auto& b : work) {
      if (b.has_point) {
        mean += b.p_camera;
        ++np;
      }
    }
    if (np >= 2) {
      mean /= np;
      double mad = 0;
      for (const auto& b : work) {
        if (b.has_point) mad += (b.p_camera - mean).norm();
      }
      mad /= np;
      if (mad > options.mad_ratio * const_mad) {
        const double r = options.centre_gate * const_radius;
        std::erase_if(work, [&](const Blob& b) { return b.has_point && (b.p_camera - c).norm() > r; });
      }
    }
  }
  if (c.z() > 1e-6) {
    const Eigen::Vector2d uc = pin.project(c);
    const double r_px = options.centre_gate * const_radius * pin.fx / c.z() + options.track_gate_px;
    std::erase_if(work, [&](const Blob& b) { return (b.uv_undistorted - uc).norm() > r_px; });
  }
}

void LedTracker::Impl::lose(PoseStatus s) {
  filter.reset();
  estimate.status = s;
  estimate.points = 0;
  estimate.rms_px = 0;
  estimate.T_camera_body = Eigen::Isometry3d::Identity();  // never a stale pose
  estimate.covariance.setZero();
  estimate.sigma_position_m = estimate.sigma_rotation_rad = 0;
  tracking = false;
  have_velocity = false;
  previous_ok = false;
  last_nearly_precise = false;
  tracked_since_search = 0;
  led_to_blob.fill(-1);
}

const CorrespondenceOptions& LedTracker::Impl::judging_options() {
  judged = options.correspondence;
  if (pool_vouches()) {
    judged.detection_sigma_px = std::sqrt(noise_floor());
    judged.detection_sigma_measured = true;
  }
  return judged;
}

bool LedTracker::Impl::try_track() {
  const Eigen::Isometry3d T = predicted();
  const Eigen::Vector3d c = T * const_centroid;
  if (!(c.z() > 1e-6)) return false;
  gate(T);
  suppress_duplicates(options.duplicate_fraction * min_led_spacing * pin.fx / c.z());
  // Fewer LEDs than a pose may otherwise rest on only right after an Ok
  // frame of this track (TrackerOptions::track_min_leds).
  const bool last_ok = estimate.status == PoseStatus::Ok;
  const int need = last_ok ? options.track_min_leds : options.correspondence.min_leds;
  int matched = matcher.match(pin, constellation, work, T, options.track_gate_px, emission_margin, led_to_blob);
  if (matched < need) return false;
  // Most of the blobs around the prediction unexplained: the track may
  // have locked onto a wrong assignment; let the full search decide.
  const int explainable = static_cast<int>(std::min(constellation.leds.size(), work.size()));
  if (matched < explainable - 2) return false;
  detail::MatchedSet set;
  gather_matched(set);
  PoseRefinement fit = refine_pose_gauss_newton(pin, set.points(), set.pixels(), T, options.correspondence.refine,
                                                set.depth(), attitude, set.biases());
  if (!fit.ok() || fit.rms_px > options.reinit_rms_px) return false;
  // Re-match from the refined pose with the tighter inlier gate: picks up
  // LEDs the prediction missed and drops ones it mismatched.
  std::array<int, kMaxLeds> again{};
  matched = matcher.match(pin, constellation, work, fit.T_camera_body, options.correspondence.inlier_px,
                          emission_margin, again);
  if (matched >= need && again != led_to_blob) {
    led_to_blob = again;
    gather_matched(set);
    const PoseRefinement f2 =
        refine_pose_gauss_newton(pin, set.points(), set.pixels(), fit.T_camera_body, options.correspondence.refine,
                                 set.depth(), attitude, set.biases());
    if (f2.ok()) fit = f2;
  }
  if (options.shared_blob_margin_px >= 0) merge_shared_blobs(fit, set);
  drop_outlier(fit, set);
  if (fit.rms_px > options.reinit_rms_px) return false;
  // Four LEDs of a larger constellation leave two residual degrees of
  // freedom: the search's rule (minimal_fit_rms_px) holds for a tracked
  // fit too — a wrong blob among four is absorbed into a fit that
  // reprojects at a pixel or two (own renderer, harsh profile: 0.37 rad
  // wrong at 1.6 px with σ_rot 0.057).
  if (static_cast<int>(set.n) == 4 && constellation.leds.size() > 4 &&
      fit.rms_px > options.correspondence.minimal_fit_rms_px) {
    return false;
  }
  // Not the board if it jumped off a prediction made from vouched-for
  // poses; a prediction from an uncertain fit (or a velocity from one)
  // may itself be wrong.
  const bool vouched =
      estimate.status == PoseStatus::Ok && (previous_ok || !(options.constant_velocity && have_velocity));
  auto jumped = [&](double m, double rad) {
    return (fit.T_camera_body.translation() - T.translation()).norm() > m ||
           detail::rotation_angle(fit.T_camera_body.linear(), T.linear()) > rad;
  };
  if (vouched && jumped(options.max_jump_m, options.max_jump_rad)) return false;
  const bool few = static_cast<int>(set.n) < options.correspondence.min_leds;
  if (few && !vouched) return false;
  // Fewer points than the search accepts on its own (of a board that has
  // more) rest on the prediction: only on one from a fit whose σ was near
  // the limits (TrackerOptions::few_point_prediction_sigma_factor; own
  // renderer, harsh profile: four points after a too-uncertain frame, two
  // centres 2.5 px off in the blur and a neighbour's glow, absorbed by the
  // fit's two redundant measurements — 0.75 rad wrong at 0.07 px with
  // σ_rot 0.022; holding such a frame back and letting the next one
  // report did not help: the same biased blobs confirmed it, three frames
  // 0.2 rad wrong at σ_rot 0.014).
  const int search_min = std::min(options.correspondence.search_min_leds, static_cast<int>(constellation.leds.size()));
  if (static_cast<int>(set.n) < search_min && !last_nearly_precise) return false;
  // The search's rule (ambiguity.hpp), with the prediction to settle the
  // mirrored branch (weighed by whether Ok poses vouch for it); anything
  // but Ok ends the track.
  const PoseStatus verdict = detail::vet_fit(pin, constellation, shape, work, led_to_blob, fit, &T,
                                             options.reinit_rms_px, judging_options(), attitude, vouched);
  // Uncertain on its own may still be Ok fused with the earlier frames.
  if (verdict != PoseStatus::Ok && verdict != PoseStatus::Uncertain) return false;
  // On fewer LEDs the prediction is the only check: the fit the branch
  // test settled on (it may have switched to the other branch by the
  // depth pattern) must still be the prediction's.
  if (few && jumped(options.few_led_jump_m, options.few_led_jump_rad)) return false;
  settle(fit, static_cast<int>(set.n), false);
  return true;
}

const PoseEstimate& LedTracker::Impl::run(std::span<const Blob> blobs) {
  work.assign(blobs.begin(), blobs.end());
  outlier_blob = -1;
  estimate.reinitialised = false;
  if (!options.use_depth) {
    for (auto& b : work) b.has_point = false;
  }
  if (tracking && work.size() >= static_cast<std::size_t>(options.track_min_leds) && try_track()) {
    estimate.blobs = static_cast<int>(work.size());
    return estimate;
  }
  // Full search on all blobs (the gate assumed the track was right).
  work.assign(blobs.begin(), blobs.end());
  if (!options.use_depth) {
    for (auto& b : work) b.has_point = false;
  }
  suppress_duplicates(2.0);
  estimate.blobs = static_cast<int>(work.size());
  if (work.size() < static_cast<std::size_t>(options.correspondence.min_leds)) {
    lose(PoseStatus::TooFewBlobs);
    return estimate;
  }
  const Correspondence c = detail::find_correspondences(pin, constellation, shape, work, judging_options(), attitude);
  if (c.status != PoseStatus::Ok && c.status != PoseStatus::Uncertain) {
    lose(c.status);
    return estimate;
  }
  led_to_blob = c.blob_of_led;
  PoseRefinement fit = c.fit;
  int matched = c.matched;
  detail::MatchedSet set;
  if (options.shared_blob_margin_px >= 0 && merge_shared_blobs(fit, set)) {
    const PoseStatus verdict = detail::vet_fit(pin, constellation, shape, work, led_to_blob, fit, nullptr,
                                               options.correspondence.accept_rms_px, judging_options(), attitude);
    if (verdict != PoseStatus::Ok && verdict != PoseStatus::Uncertain) {
      lose(verdict);
      return estimate;
    }
    matched = static_cast<int>(set.n);
  }
  // A fresh track, whose velocity comes from the previous frame's pose if
  // that frame had one (settle(): `tracking`). A board moving faster than
  // the tracking gate per frame loses its track every frame; without the
  // velocity the next prediction would lose it again, and every frame
  // would need the full search (measured: 100 ms frames at 0.5 m).
  settle(fit, matched, true);
  return estimate;
}

LedTracker::LedTracker(const CameraModel& camera, const Constellation& constellation, const TrackerOptions& options) {
  std::string why;
  if (!camera.validate(&why)) throw InvalidArgument("camera: " + why);
  if (!constellation.validate(&why)) throw InvalidArgument("constellation: " + why);
  if (!options.validate(&why)) throw InvalidArgument("tracker options: " + why);
  impl_ = std::make_unique<Impl>(camera, constellation, options);
}

LedTracker::~LedTracker() = default;
LedTracker::LedTracker(LedTracker&&) noexcept = default;
LedTracker& LedTracker::operator=(LedTracker&&) noexcept = default;

const PoseEstimate& LedTracker::track(const BgrImageView& colour, const DepthImageView* depth) {
  impl_->attitude = {};
  impl_->detector.detect(colour, impl_->options.use_depth ? depth : nullptr, impl_->detected);
  return impl_->run(impl_->detected);
}

const PoseEstimate& LedTracker::track(const BgrImageView& colour, const DepthImageView* depth,
                                      const AttitudePrior& prior) {
  impl_->set_prior(prior);
  impl_->detector.detect(colour, impl_->options.use_depth ? depth : nullptr, impl_->detected);
  return impl_->run(impl_->detected);
}

const PoseEstimate& LedTracker::track_blobs(std::span<const Blob> blobs) {
  impl_->attitude = {};
  return impl_->run(blobs);
}

const PoseEstimate& LedTracker::track_blobs(std::span<const Blob> blobs, const AttitudePrior& prior) {
  impl_->set_prior(prior);
  return impl_->run(blobs);
}

void LedTracker::reset() { impl_->lose(PoseStatus::TooFewBlobs); }

const PoseEstimate& LedTracker::last() const { return impl_->estimate; }
const std::vector<Blob>& LedTracker::blobs() const { return impl_->work; }
const std::array<int, kMaxLeds>& LedTracker::led_to_blob() const { return impl_->led_to_blob; }

}  // namespace touchdown::pose
