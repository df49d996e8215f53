// LedTracker's fit checks (led_tracker_impl.hpp): duplicate blobs, settling
// a fit into the track, whether a fit explains the frame, blobs two LEDs
// share, the outlier drop and the pooled noise estimate.
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

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

void LedTracker::Impl::suppress_duplicates(double radius) {
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

void LedTracker::Impl::settle(const PoseRefinement& fit, int points, bool fresh) {
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

bool LedTracker::Impl::explains_frame(const PoseRefinement& fit) {
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

bool LedTracker::Impl::held(std::size_t b) const {
  const auto held_end = led_to_blob.begin() + static_cast<std::ptrdiff_t>(constellation.leds.size());
  return std::find(led_to_blob.begin(), held_end, static_cast<int>(b)) != held_end;
}

bool LedTracker::Impl::spot_of_its_own(const Eigen::Vector2d& uv, double d) const {
  for (std::size_t b = 0; b < work.size(); ++b) {
    if ((work[b].uv_undistorted - uv).norm() < d && !held(b)) return true;
  }
  return false;
}

bool LedTracker::Impl::merge_shared_blobs(PoseRefinement& fit, detail::MatchedSet& set) {
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

bool LedTracker::Impl::drop_outlier(PoseRefinement& fit, detail::MatchedSet& set) {
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
    const PoseRefinement refit = refine_pose_gauss_newton(pin, set.points(), set.pixels(), fit.T_camera_body, co.refine,
                                                          set.depth(), attitude, set.biases());
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

void LedTracker::Impl::leave_blob(int b) {
  for (std::size_t l = 0; l < constellation.leds.size(); ++l) {
    if (led_to_blob[l] == b) led_to_blob[l] = -1;
  }
}

bool LedTracker::Impl::pool_vouches() const {
  return options.noise_pool_frames > 0 && static_cast<int>(noise_pool.size()) >= options.noise_pool_min_fits;
}

double LedTracker::Impl::judged_noise(const PoseRefinement& fit) {
  const double c = options.unpooled_noise_confidence;
  const double k = fit.degrees_of_freedom;
  if (pool_vouches() || !(c > 0) || !(k > 0)) return fit.noise_variance;
  // k is a whole number below the array's size (2n + depths + 2 − 6, n ≤ kMaxLeds).
  double& f = noise_bound_factor.at(static_cast<std::size_t>(std::lround(k)));
  if (!(f > 0)) f = k / detail::chi2_quantile(k, 1 - c);
  return fit.noise_variance * f;
}

void LedTracker::Impl::gather_matched(detail::MatchedSet& set) {
  detail::gather(constellation, work, led_to_blob, options.correspondence, set, noise_floor());
}

double LedTracker::Impl::noise_floor() {
  const double sd = options.correspondence.detection_sigma_px;
  if (!pool_vouches()) return sd * sd;
  noise_sorted.assign(noise_pool.begin(), noise_pool.end());
  const double lo = options.min_detection_sigma_px;
  return std::max(upper_median_in_place(std::span(noise_sorted)), lo * lo);
}

void LedTracker::Impl::pool_noise(double variance, double k) {
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

}  // namespace touchdown::pose
