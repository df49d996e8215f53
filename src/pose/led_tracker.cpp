#include "touchdown/pose/led_tracker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "pose/ambiguity.hpp"
#include "pose/assignment.hpp"
#include "pose/pose_filter.hpp"
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

  Impl(const CameraModel& c, const Constellation& k, const TrackerOptions& o)
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

  void set_prior(const AttitudePrior& prior) {
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

  Eigen::Isometry3d predicted() const {
    if (!options.constant_velocity || !have_velocity) return last_pose;
    // Δ = T_k T_{k−1}⁻¹ applied once more; re-orthonormalised, since the
    // extrapolation amplifies rounding in the rotation frame after frame.
    Eigen::Isometry3d T = last_pose * previous_pose.inverse() * last_pose;
    T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
    return T;
  }

  // The paper's outlier test (3-D) and a 2-D gate around the prediction.
  void gate(const Eigen::Isometry3d& T) {
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

  // k-means (k = number of LEDs) on the blob centres, then within each
  // cluster drop blobs closer than `radius` to a brighter member.
  void suppress_duplicates(double radius) {
    const std::size_t k = constellation.leds.size();
    const std::size_t m = work.size();
    if (m <= k || radius <= 0) return;
    // Deterministic farthest-point seeding from the brightest blob.
    centres[0] = work[0].uv_undistorted;
    for (std::size_t c = 1; c < k; ++c) {
      double far = -1;
      std::size_t arg = 0;
      for (std::size_t b = 0; b < m; ++b) {
        double d = kInf;
        for (std::size_t j = 0; j < c; ++j) d = std::min(d, (work[b].uv_undistorted - centres[j]).squaredNorm());
        if (d > far) {
          far = d;
          arg = b;
        }
      }
      centres[c] = work[arg].uv_undistorted;
    }
    cluster.assign(m, 0);
    for (int it = 0; it < 10; ++it) {
      bool changed = false;
      for (std::size_t b = 0; b < m; ++b) {
        int arg = 0;
        double best = kInf;
        for (std::size_t c = 0; c < k; ++c) {
          const double d = (work[b].uv_undistorted - centres[c]).squaredNorm();
          if (d < best) {
            best = d;
            arg = static_cast<int>(c);
          }
        }
        changed |= cluster[b] != arg;
        cluster[b] = arg;
      }
      for (std::size_t c = 0; c < k; ++c) {
        Eigen::Vector2d s = Eigen::Vector2d::Zero();
        int cnt = 0;
        for (std::size_t b = 0; b < m; ++b) {
          if (cluster[b] == static_cast<int>(c)) {
            s += work[b].uv_undistorted;
            ++cnt;
          }
        }
        if (cnt > 0) centres[c] = s / cnt;
      }
      if (!changed && it > 0) break;
    }
    keep.assign(m, 1);
    for (std::size_t b = 0; b < m; ++b) {  // brightest first: compare with brighter kept members
      for (std::size_t a = 0; a < b; ++a) {
        if (keep[a] && cluster[a] == cluster[b] && (work[a].uv_undistorted - work[b].uv_undistorted).norm() < radius) {
          keep[b] = 0;
          break;
        }
      }
    }
    std::size_t w = 0;
    for (std::size_t b = 0; b < m; ++b) {
      if (keep[b]) work[w++] = work[b];
    }
    work.resize(w);
  }

  // A vetted fit (branch settled, reprojection within the gate) becomes the
  // frame's answer: fused with the earlier frames (options.fuse_frames,
  // pose_filter.hpp), then Ok if its 1-σ is within the correspondence
  // options' limits, else Uncertain — no pose, but the track goes on from
  // the fit, so that the next frame is matched against its prediction
  // instead of searched from scratch (a distant board stays uncertain for
  // many frames; each search would cost more and know less). `fresh`: the
  // fit starts a new track (the filter restarts).
  void settle(const PoseRefinement& fit, int points, bool fresh) {
    const CorrespondenceOptions& co = options.correspondence;
    Matrix6d covariance = fit.covariance_for(std::max(judged_noise(fit), noise_floor()));
    if (!fresh && fit.degrees_of_freedom > 0)
      pool_noise(fit.noise_variance, fit.degrees_of_freedom);  // 3 LEDs: no estimate
    Eigen::Isometry3d T = fit.T_camera_body;
    std::pair<double, double> sigma = pose_sigmas(covariance, T);
    const std::pair<double, double> own = sigma;  // the frame's own: the limit holds for it too
    if (options.fuse_frames) {
      if (fresh) filter.reset();
      filter.update(T, covariance);
      T = filter.pose();
      covariance = filter.covariance();
      // Never more than fusion_max_frames frames' worth of certainty: blob
      // biases persist from frame to frame (a merged blob at a hover), so
      // frames are not independent measurements.
      const auto fused = pose_sigmas(covariance, T);
      const double k = 1 / std::sqrt(options.fusion_max_frames);
      sigma = {std::max(fused.first, k * sigma.first), std::max(fused.second, k * sigma.second)};
    }
    previous_pose = last_pose;
    previous_ok = estimate.status == PoseStatus::Ok;  // still the last frame's
    have_velocity = tracking;
    last_pose = fit.T_camera_body;  // the track follows the measurements
    tracking = true;
    std::tie(estimate.sigma_position_m, estimate.sigma_rotation_rad) = sigma;
    estimate.reinitialised = fresh;
    // A search's pose on fewer than search_min_leds LEDs (the constellation
    // shows few, or a wrong pose claims so) or with a loose fit is held until
    // a tracked frame confirms it: chance fits among many blobs do not
    // survive the next frame's prediction.
    const bool unconfirmed = fresh && (points < co.search_min_leds || fit.rms_px > options.confirm_rms_px);
    // Fusion lowers the σ but does not admit a frame the limit rejects on
    // its own: a track on the wrong branch fuses into a confident wrong pose
    // (measured: 14 frames wrong beyond 3 σ with --fuse on the independent
    // renderer's sequences when only the fused σ was tested).
    // A fit that explains its frame is held to complete_max_sigma_* only
    // (explains_frame) — from the second tracked frame after a search on:
    // the first is matched from the search's own pose.
    tracked_since_search = fresh ? 0 : std::min(tracked_since_search + 1, 2);  // only "2 or more" counts
    const std::pair<double, double> regular = co.sigma_limits(attitude.active());
    const std::pair<double, double> limits =
        tracked_since_search >= 2 && explains_frame(fit)
            ? std::pair{options.complete_max_sigma_position_m, options.complete_max_sigma_rotation_rad}
            : regular;
    const std::pair<double, double> tested = {std::max(sigma.first, own.first), std::max(sigma.second, own.second)};
    auto beyond = [&](double f, const std::pair<double, double>& l) {
      return tested.first > f * l.first || tested.second > f * l.second;
    };
    // A prediction for a fit on few points comes from a fit near the
    // regular limits, whether or not this one was held to them.
    last_nearly_precise = !beyond(options.few_point_prediction_sigma_factor, regular);
    if (unconfirmed || beyond(1.0, limits)) {
      // The figures that were tested (a fused frame rejected on its own σ
      // shows that σ, not the smaller fused one).
      std::tie(estimate.sigma_position_m, estimate.sigma_rotation_rad) = tested;
      estimate.status = PoseStatus::Uncertain;
      estimate.points = 0;
      estimate.rms_px = 0;
      estimate.T_camera_body = Eigen::Isometry3d::Identity();  // no pose
      estimate.covariance.setZero();
      return;
    }
    estimate.status = PoseStatus::Ok;
    estimate.T_camera_body = T;
    estimate.rms_px = fit.rms_px;
    estimate.points = points;
    estimate.covariance = covariance;
  }

  // The fit explains its whole frame (TrackerOptions::complete_fit_significance):
  // the pool vouches, enough points in the fit (a merged spot outside it
  // does not count), every LED in view matched (alone, in a merged spot
  // whose centre the LEDs' midpoint explains, on a split blob left out of
  // the fit or on a misread one whose centre its reprojection explains),
  // residuals at the pooled noise.
  bool explains_frame(const PoseRefinement& fit) {
    const double alpha = options.complete_fit_significance;
    const int n = static_cast<int>(constellation.leds.size());
    if (!(alpha > 0) || !pool_vouches()) return false;
    const double chi2_2_bound = -2.0 * std::log(alpha);  // χ²₂(1 − α): one blob outside the fit
    // The reprojection χ², each residual in its blob's own variance: the
    // pooled noise plus the blob's own bias the covariance carries
    // (crowding, split, small and large spot).
    const CorrespondenceOptions& co = options.correspondence;
    detail::MatchedSet set;
    gather_matched(set);
    // A merged spot outside the fit is checked below, but the fit itself
    // must rest on enough points: the spot's midpoint is a loose constraint
    // (merged_bias), and a 4-point fit has two redundant measurements only.
    if (static_cast<int>(set.n) < std::min(co.search_min_leds, n)) return false;
    const double floor = noise_floor();
    double chi2 = 0;
    for (std::size_t i = 0; i < set.n; ++i) {
      Eigen::Vector2d r;
      if (!reprojection_residual(pin, fit.T_camera_body, set.p[i], set.uv[i], r, nullptr)) return false;
      chi2 += r.squaredNorm() / (floor + set.bias[i]);
    }
    // A blob the fit left out, in its own variance (two more degrees of
    // freedom each): a merged spot's centre against its LEDs' midpoint,
    // merged_bias added; a split blob's (gather: out while enough whole
    // blobs remain) against its LED's reprojection, split_bias · r at
    // least, within its own χ²₂ bound. A blob inside the fit is in the χ²
    // above; a joined one left out (oversized, not split) is not tested.
    int outside = 0;
    const auto fitted_end = set.blob.begin() + static_cast<std::ptrdiff_t>(set.n);
    for (std::size_t l = 0; l < constellation.leds.size(); ++l) {
      const int b = led_to_blob[l];
      if (b < 0 || std::find(set.blob.begin(), fitted_end, b) != fitted_end) continue;
      const int j = detail::partner_of(constellation, led_to_blob, l);
      const Blob& blob = work[static_cast<std::size_t>(b)];
      if (j >= 0 ? j < static_cast<int>(l) : !blob.split) continue;  // a pair once, at its first LED
      double variance = floor + detail::blob_bias_variance(blob, work, co, floor);
      Eigen::Vector3d p = constellation.leds[l].p_body;
      if (j >= 0) {
        p = 0.5 * (p + constellation.leds[static_cast<std::size_t>(j)].p_body);
        variance += std::pow(co.merged_bias * std::max(1.0, std::sqrt(blob.area / std::numbers::pi)), 2);
      }
      Eigen::Vector2d r;
      if (!reprojection_residual(pin, fit.T_camera_body, p, blob.uv_undistorted, r, nullptr)) return false;
      const double e2 = r.squaredNorm() / variance;
      if (j < 0 && !(e2 <= chi2_2_bound)) return false;
      chi2 += e2;
      ++outside;
    }
    // Every LED the fit puts in view (in front, shining toward the camera,
    // complete_fit_border_px inside the image) has a blob. One without (a
    // drop-out, an unmodelled merge, a wrong assignment: none of which the
    // σ covers) fails the frame — unless a blob no LED holds, read White or
    // Unknown, lies at its reprojection: its colour misread (at 3 m a green
    // spot between a red and a blue one 3–5 px away is lit by both and
    // reads white). A blob of another colour is not taken (the matcher
    // refused it: it may be another source), nor the blob drop_outlier
    // took out of this fit. That blob then counts as the LED's: its
    // residual within its own χ²₂ bound, and in the χ² (two more degrees
    // of freedom), each blob for one LED.
    const Eigen::Vector3d camera_body = detail::camera_in_body(fit.T_camera_body);
    std::array<int, kMaxLeds> claimed{};
    std::size_t n_claimed = 0;
    for (std::size_t i = 0; i < constellation.leds.size(); ++i) {
      if (led_to_blob[i] >= 0) continue;
      const Led& led = constellation.leds[i];
      const Eigen::Vector3d q = fit.T_camera_body * led.p_body;
      if (!detail::faces_camera(led, q, camera_body, emission_margin) ||
          !camera.in_image(camera.project(q), options.complete_fit_border_px)) {
        continue;
      }
      const Eigen::Vector2d uv = pin.project(q);
      int nearest = -1;
      double nearest2 = std::numeric_limits<double>::infinity();
      for (std::size_t b = 0; b < work.size(); ++b) {
        const double d2 = (work[b].uv_undistorted - uv).squaredNorm();
        const bool misread = work[b].color == LedColor::White || work[b].color == LedColor::Unknown;
        if (d2 < nearest2 && misread && static_cast<int>(b) != outlier_blob && !held(b)) {
          nearest = static_cast<int>(b);
          nearest2 = d2;
        }
      }
      const auto claimed_end = claimed.begin() + static_cast<std::ptrdiff_t>(n_claimed);
      if (nearest < 0 || std::find(claimed.begin(), claimed_end, nearest) != claimed_end) return false;
      const double e2 =
          nearest2 / (floor + detail::blob_bias_variance(work[static_cast<std::size_t>(nearest)], work, co, floor));
      if (!(e2 <= chi2_2_bound)) return false;
      claimed[n_claimed++] = nearest;
      chi2 += e2;
      ++outside;
    }
    const double k = 2.0 * static_cast<double>(set.n + outside) - 6.0;
    if (!(k > 0)) return false;
    double& bound = complete_chi2_bound.at(static_cast<std::size_t>(k));
    if (!(bound > 0)) bound = detail::chi2_quantile(k, 1 - alpha);
    if (chi2 > bound) return false;
    return true;
  }

  // Some LED holds blob b.
  [[nodiscard]] bool held(std::size_t b) const {
    const auto held_end = led_to_blob.begin() + static_cast<std::ptrdiff_t>(constellation.leds.size());
    return std::find(led_to_blob.begin(), held_end, static_cast<int>(b)) != held_end;
  }

  // A blob no LED holds lies within `d` [px] of `uv`: an LED projected
  // there may have a spot of its own (unmatched: its colour read wrong),
  // not a share of a merged one.
  [[nodiscard]] bool spot_of_its_own(const Eigen::Vector2d& uv, double d) const {
    for (std::size_t b = 0; b < work.size(); ++b) {
      if ((work[b].uv_undistorted - uv).norm() < d && !held(b)) return true;
    }
    return false;
  }

  bool merge_shared_blobs(PoseRefinement& fit, detail::MatchedSet& set) {
    const CorrespondenceOptions& co = options.correspondence;
    const Eigen::Vector3d camera_body = detail::camera_in_body(fit.T_camera_body);
    const std::array<int, kMaxLeds> before = led_to_blob;
    bool merged = false;
    for (std::size_t i = 0; i < constellation.leds.size(); ++i) {
      if (before[i] < 0 || detail::partner_of(constellation, led_to_blob, i) >= 0) continue;
      const Blob& b = work[static_cast<std::size_t>(before[i])];
      const double radius = 1.5 * std::sqrt(b.area / std::numbers::pi) + options.shared_blob_margin_px;
      for (std::size_t j = 0; j < constellation.leds.size(); ++j) {
        if (j == i || led_to_blob[j] >= 0) continue;
        const Led& other = constellation.leds[j];
        const Eigen::Vector3d q = fit.T_camera_body * other.p_body;
        if (!detail::faces_camera(other, q, camera_body, emission_margin)) continue;
        const Eigen::Vector2d uv = pin.project(q);
        const double d = (uv - b.uv_undistorted).norm();
        if (d > radius || spot_of_its_own(uv, d)) continue;
        led_to_blob[j] = before[i];
        merged = true;
        break;
      }
    }
    if (!merged) return false;
    gather_matched(set);
    const PoseRefinement refit = refine_pose_gauss_newton(pin, set.points(), set.pixels(), fit.T_camera_body, co.refine,
                                                          set.depth(), attitude, set.biases());
    if (!refit.ok()) {
      led_to_blob = before;
      gather_matched(set);
      return false;
    }
    fit = refit;
    return true;
  }

  // One wrong blob in a tracked fit (a flash or a reflection next to an
  // LED's prediction): the fit reprojects far worse than the track's pooled
  // noise (TrackerOptions::outlier_rms_factor), and without one of its
  // blobs it would reproject at least twice better — that blob leaves the
  // fit (the one whose removal fits best; a merged blob with both its
  // LEDs), while search_min_leds remain (fewer points hide a wrong one's
  // pull).
  bool drop_outlier(PoseRefinement& fit, detail::MatchedSet& set) {
    const CorrespondenceOptions& co = options.correspondence;
    if (options.outlier_rms_factor <= 0 || !pool_vouches() || set.n <= static_cast<std::size_t>(co.search_min_leds) ||
        !(fit.rms_px > options.outlier_rms_factor * std::sqrt(noise_floor()))) {
      return false;
    }
    const std::array<int, kMaxLeds> before = led_to_blob;
    PoseRefinement best = fit;
    std::size_t best_led = kMaxLeds;
    for (std::size_t l = 0; l < constellation.leds.size(); ++l) {
      if (before[l] < 0 || detail::partner_of(constellation, before, l) > static_cast<int>(l)) continue;
      led_to_blob = before;
      leave_blob(before[l]);
      gather_matched(set);
      const PoseRefinement refit = refine_pose_gauss_newton(pin, set.points(), set.pixels(), fit.T_camera_body,
                                                            co.refine, set.depth(), attitude, set.biases());
      if (refit.ok() && refit.rms_px < best.rms_px) {
        best = refit;
        best_led = l;
      }
    }
    led_to_blob = before;
    const bool dropped = best_led < kMaxLeds && best.rms_px < 0.5 * fit.rms_px;
    if (dropped) {
      outlier_blob = before[best_led];
      leave_blob(before[best_led]);
      fit = best;
    }
    gather_matched(set);
    return dropped;
  }

  // The LEDs on blob b (two if merged) leave the fit.
  void leave_blob(int b) {
    for (std::size_t l = 0; l < constellation.leds.size(); ++l) {
      if (led_to_blob[l] == b) led_to_blob[l] = -1;
    }
  }

  // The pool holds enough tracked fits to stand for this camera's noise.
  [[nodiscard]] bool pool_vouches() const {
    return options.noise_pool_frames > 0 && static_cast<int>(noise_pool.size()) >= options.noise_pool_min_fits;
  }

  // The pixel noise variance a fit's covariance assumes before the floor:
  // its own σ̂², raised to its upper confidence bound while the pool does
  // not vouch (TrackerOptions::unpooled_noise_confidence).
  double judged_noise(const PoseRefinement& fit) {
    const double c = options.unpooled_noise_confidence;
    const double k = fit.degrees_of_freedom;
    if (pool_vouches() || !(c > 0) || !(k > 0)) return fit.noise_variance;
    // k is a whole number below the array's size (2n + depths + 2 − 6, n ≤ kMaxLeds).
    double& f = noise_bound_factor.at(static_cast<std::size_t>(std::lround(k)));
    if (!(f > 0)) f = k / detail::chi2_quantile(k, 1 - c);
    return fit.noise_variance * f;
  }

  // The LEDs led_to_blob holds, gathered for a fit; a small blob's own
  // error is its excess over the noise floor
  // (CorrespondenceOptions::small_blob_sigma_px3).
  void gather_matched(detail::MatchedSet& set) {
    detail::gather(constellation, work, led_to_blob, options.correspondence, set, noise_floor());
  }

  // The detection-noise variance floor (TrackerOptions::noise_pool_frames).
  double noise_floor() {
    const double sd = options.correspondence.detection_sigma_px;
    if (!pool_vouches()) return sd * sd;
    noise_sorted.assign(noise_pool.begin(), noise_pool.end());
    const double lo = options.min_detection_sigma_px;
    return std::max(upper_median_in_place(std::span(noise_sorted)), lo * lo);
  }

  // A fit's σ̂² on k degrees of freedom enters the pool over the median of
  // χ²_k / k, so that the pool's median estimates the noise variance
  // whatever the fits' k (χ²_6 / 6 has its median at 0.89 of its mean,
  // χ²_14 / 14 at 0.95; a fixed 1.25 overstated it by 11–30 %).
  void pool_noise(double variance, double k) {
    const auto cap = static_cast<std::size_t>(options.noise_pool_frames);
    if (cap == 0 || !std::isfinite(variance) || !(k > 0)) return;
    // k is a whole number below the array's size (2n + depths + 2 − 6, n ≤ kMaxLeds).
    double& median = chi2_median_fraction.at(static_cast<std::size_t>(std::lround(k)));
    if (!(median > 0)) median = detail::chi2_quantile(k, 0.5) / k;
    variance /= median;
    if (noise_pool.size() < cap) {
      noise_pool.push_back(variance);
    } else {
      noise_pool[noise_next] = variance;
    }
    noise_next = (noise_next + 1) % cap;
  }

  void lose(PoseStatus s) {
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

  // The correspondence options the search and the branch test judge a fit
  // by: the default detection noise until the noise pool vouches, then the
  // camera's pooled noise (noise_floor()), so that a branch or assignment
  // that reprojects several times worse than this camera's noise is ruled
  // out rather than weighed against the 0.2 px default.
  CorrespondenceOptions judged;
  const CorrespondenceOptions& judging_options() {
    judged = options.correspondence;
    if (pool_vouches()) {
      judged.detection_sigma_px = std::sqrt(noise_floor());
      judged.detection_sigma_measured = true;
    }
    return judged;
  }

  bool try_track() {
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
    const int search_min =
        std::min(options.correspondence.search_min_leds, static_cast<int>(constellation.leds.size()));
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

  const PoseEstimate& run(std::span<const Blob> blobs) {
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
};

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
