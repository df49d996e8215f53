#include "touchdown/pose/correspondence.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "pose/ambiguity.hpp"
#include "pose/assignment.hpp"
#include "pose/p3p.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/epnp.hpp"

namespace touchdown::pose {

bool CorrespondenceOptions::validate(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(inlier_px > 0)) return fail("inlier_px: must be positive");
  if (!(accept_rms_px > 0)) return fail("accept_rms_px: must be positive");
  if (max_blobs < 4 || max_blobs > 32) return fail("max_blobs: must be in 4..32");
  if (max_blobs_retry < max_blobs || max_blobs_retry > 32) {
    return fail("max_blobs_retry: must be in max_blobs..32");
  }
  if (max_hypotheses < 1) return fail("max_hypotheses: must be positive");
  if (!(p3p_gate >= 0) || !std::isfinite(p3p_gate)) return fail("p3p_gate: must be >= 0");
  if (min_leds < 4) return fail("min_leds: must be at least 4");
  if (search_min_leds < 4 || search_min_leds > static_cast<int>(kMaxLeds)) {
    return fail("search_min_leds: must be in 4..16");
  }
  if (!(emission_margin_deg >= 0 && emission_margin_deg <= 90)) return fail("emission_margin_deg: must be in [0, 90]");
  if (!(minimal_fit_rms_px > 0)) return fail("minimal_fit_rms_px: must be positive");
  if (!(missing_penalty_px > 0)) return fail("missing_penalty_px: must be positive");
  if (!(min_distance >= 0 && max_distance > min_distance))
    return fail("min_distance/max_distance: need 0 <= min < max");
  if (refine.max_iterations < 1) return fail("refine.max_iterations: must be positive");
  if (!(detection_sigma_px > 0) || !std::isfinite(detection_sigma_px))
    return fail("detection_sigma_px: must be positive");
  if (!(crowded_radii > 0) || !std::isfinite(crowded_radii)) return fail("crowded_radii: must be positive");
  if (!(crowded_bias_px >= 0) || !std::isfinite(crowded_bias_px)) {
    return fail("crowded_bias_px: must be >= 0 (0 = off)");
  }
  if (!(split_bias >= 0) || !std::isfinite(split_bias)) return fail("split_bias: must be >= 0");
  if (!(merged_bias > 0) || !std::isfinite(merged_bias)) return fail("merged_bias: must be positive");
  if (!(small_blob_sigma_px3 >= 0) || !std::isfinite(small_blob_sigma_px3)) {
    return fail("small_blob_sigma_px3: must be >= 0 (0 = off)");
  }
  if (!(large_blob_sigma_px >= 0) || !std::isfinite(large_blob_sigma_px)) {
    return fail("large_blob_sigma_px: must be >= 0 (0 = off)");
  }
  if (!(branch_chi2 > 0) || !std::isfinite(branch_chi2)) return fail("branch_chi2: must be positive");
  if (!(depth_sigma_k >= 0) || !std::isfinite(depth_sigma_k)) return fail("depth_sigma_k: must be >= 0");
  if (!(max_sigma_position_m > 0)) return fail("max_sigma_position_m: must be positive");
  if (!(max_sigma_rotation_rad > 0)) return fail("max_sigma_rotation_rad: must be positive");
  if (!(attitude_max_sigma_position_m > 0)) return fail("attitude_max_sigma_position_m: must be positive");
  if (!(attitude_max_sigma_rotation_rad > 0)) return fail("attitude_max_sigma_rotation_rad: must be positive");
  if (!(branch_track_deg >= 0 && branch_track_deg <= 180)) return fail("branch_track_deg: must be in [0, 180]");
  if (!(branch_distinct_m >= 0) || !std::isfinite(branch_distinct_m)) return fail("branch_distinct_m: must be >= 0");
  if (!(branch_distinct_deg >= 0 && branch_distinct_deg <= 180))
    return fail("branch_distinct_deg: must be in [0, 180]");
  if (!(attitude_gate_chi2 > 0) || !std::isfinite(attitude_gate_chi2))
    return fail("attitude_gate_chi2: must be positive");
  return true;
}

namespace {

using Quad = std::array<std::size_t, 4>;
constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// Every 4-subset of {0, …, n−1} in lexicographic order, until `visit`
// returns false. Returns false when stopped.
template <class Visit>
bool for_each_subset(std::size_t n, Visit&& visit) {
  Quad L{};
  for (L[0] = 0; L[0] < n; ++L[0]) {
    for (L[1] = L[0] + 1; L[1] < n; ++L[1]) {
      for (L[2] = L[1] + 1; L[2] < n; ++L[2]) {
        for (L[3] = L[2] + 1; L[3] < n; ++L[3]) {
          if (!visit(L)) return false;
        }
      }
    }
  }
  return true;
}

// Every ordered tuple of distinct blobs B[level..3] whose colours are
// compatible with LEDs L[level..3], depth-first in ascending blob order,
// until `visit` returns false. Returns false when stopped.
template <class Visit>
bool for_each_blob_tuple(const Constellation& k, std::span<const Blob> blobs, const Quad& L, Quad& B, std::size_t level,
                         Visit&& visit) {
  if (level == 4) return visit(B);
  for (B[level] = 0; B[level] < blobs.size(); ++B[level]) {
    if (std::find(B.begin(), B.begin() + static_cast<std::ptrdiff_t>(level), B[level]) !=
        B.begin() + static_cast<std::ptrdiff_t>(level))
      continue;
    if (!colors_compatible(k.leds[L[level]].color, blobs[B[level]].color)) continue;
    if (!for_each_blob_tuple(k, blobs, L, B, level + 1, visit)) return false;
  }
  return true;
}

// The state one search shares between its hypotheses.
class Search {
 public:
  Search(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs, const CorrespondenceOptions& o,
         const AttitudeConstraint& attitude)
      : cam_(cam),
        k_(k),
        blobs_(blobs),
        o_(o),
        attitude_(attitude),
        n_(k.leds.size()),
        penalty2_(o.missing_penalty_px * o.missing_penalty_px),
        centroid_(k.centroid()),
        margin_(deg_to_rad(o.emission_margin_deg)) {
    best_.blob_of_led.fill(-1);
    best_.status = PoseStatus::NoConsistentCorrespondence;
  }

  // LEDs L ↔ blobs B: solve, verify against every LED, refine, score.
  // Returns false to stop the search (hypothesis budget spent, or every
  // LED explained well).
  bool consider(const Quad& L, const Quad& B) {
    if (best_.hypotheses >= o_.max_hypotheses) return false;
    if (!fourth_fits(L, B)) return true;
    ++best_.hypotheses;
    std::array<Eigen::Vector3d, 4> p4;
    std::array<Eigen::Vector2d, 4> uv4;
    for (std::size_t i = 0; i < 4; ++i) {
      p4[i] = k_.leds[L[i]].p_body;
      uv4[i] = blobs_[B[i]].uv_undistorted;
    }
    const EpnpResult e = solve_epnp(cam_, p4, uv4);
    if (!e.ok() || e.rms_px > o_.inlier_px) return true;
    std::array<int, kMaxLeds> assign{};
    double sq = 0;
    const int matched = detail::greedy_match(cam_, k_, blobs_, e.T_camera_body, o_.inlier_px, margin_, assign, sq);
    if (matched < o_.min_leds) return true;
    // MSAC-style score: squared error of the explained LEDs plus a fixed
    // penalty per unexplained one, so that a wrong pose cannot win by
    // stretching onto a spurious blob.
    if (sq + (static_cast<double>(n_) - matched) * penalty2_ >= best_score_) return true;
    detail::MatchedSet set;
    detail::gather(k_, blobs_, assign, o_, set);
    PoseRefinement fit = refine_pose_gauss_newton(cam_, set.points(), set.pixels(), e.T_camera_body, o_.refine,
                                                  set.depth(), attitude_, set.biases());
    if (!fit.ok()) return true;
    // Re-match from the refined pose and refine once more if it changed.
    std::array<int, kMaxLeds> again{};
    const int rematched = detail::greedy_match(cam_, k_, blobs_, fit.T_camera_body, o_.inlier_px, margin_, again, sq);
    if (rematched >= o_.min_leds && again != assign) {
      assign = again;
      detail::gather(k_, blobs_, assign, o_, set);
      const PoseRefinement f2 = refine_pose_gauss_newton(cam_, set.points(), set.pixels(), fit.T_camera_body, o_.refine,
                                                         set.depth(), attitude_, set.biases());
      if (!f2.ok()) return true;
      fit = f2;
    }
    if (!plausible(fit, assign, set.n)) return true;
    // Every unexplained LED is charged, also one the pose turns away from
    // the camera: charging only the LEDs a pose "expects" lets a wrong pose
    // explain missing LEDs away by turning the board (seen in the
    // randomised probe: 1.4 rad wrong on four of eight LEDs).
    const double count = static_cast<double>(set.n);
    const double score = fit.rms_px * fit.rms_px * count + (static_cast<double>(n_) - count) * penalty2_;
    if (score < best_score_) {
      best_score_ = score;
      best_.matched = static_cast<int>(set.n);
      best_.blob_of_led = assign;
      best_.fit = fit;
      // Every LED (or every blob) explained, well: stop. Not "every LED
      // that shines toward the camera": a wrong pose that turns the board
      // away expects few LEDs and would end the search early.
      if (set.n >= std::min(n_, blobs_.size()) && fit.rms_px < 0.5 * o_.accept_rms_px) return false;
    }
    return true;
  }

  // True when the hypotheses so far hold a pose finish() could accept.
  [[nodiscard]] bool found() const { return best_.matched >= o_.min_leds && best_.fit.rms_px <= o_.accept_rms_px; }

  Correspondence finish(const detail::ConstellationShape& shape) {
    if (best_.matched < o_.min_leds) return best_;
    if (best_.fit.rms_px > o_.accept_rms_px) {
      best_.status = PoseStatus::ReprojectionTooLarge;
      return best_;
    }
    // Never a confident wrong pose (ambiguity.hpp).
    best_.status = detail::vet_fit(cam_, k_, shape, blobs_, best_.blob_of_led, best_.fit, nullptr, o_.accept_rms_px, o_,
                                   attitude_);
    return best_;
  }

 private:
  // The P3P pre-test (p3p.hpp): the poses that put LEDs L[0..2] on blobs
  // B[0..2] exactly (up to four) must put LED L[3] within p3p_gate ×
  // inlier_px of blob B[3], else the hypothesis is dropped before EPnP
  // (which costs ~10× as much). The solutions depend on L and B[0..2] only, and the search
  // varies B[3] innermost: they are cached. No solution (noise can turn a
  // double root complex; collinear LEDs) admits every B[3].
  bool fourth_fits(const Quad& L, const Quad& B) {
    if (o_.p3p_gate <= 0) return true;
    if (L != cached_leds_) {
      cached_leds_ = L;
      const Eigen::Vector3d& p1 = k_.leds[L[0]].p_body;
      const Eigen::Vector3d e1 = k_.leds[L[1]].p_body - p1, e2 = k_.leds[L[2]].p_body - p1;
      Eigen::Matrix3d basis;
      basis << e1, e2, e1.cross(e2);
      // LED L[3] in the frame of the triangle (edges and their normal),
      // which a rigid motion preserves.
      const Eigen::FullPivLU<Eigen::Matrix3d> lu(basis);
      leds_usable_ = lu.isInvertible() && e1.cross(e2).norm() > 1e-3 * e1.norm() * e2.norm();
      if (leds_usable_) fourth_in_triangle_ = lu.solve(k_.leds[L[3]].p_body - p1);
      sides_ = {(k_.leds[L[1]].p_body - k_.leds[L[2]].p_body).norm(), e2.norm(), e1.norm()};
      cached_blobs_valid_ = false;
    }
    if (!leds_usable_) return true;
    if (!cached_blobs_valid_ || cached_blobs_[0] != B[0] || cached_blobs_[1] != B[1] || cached_blobs_[2] != B[2]) {
      cached_blobs_ = B;
      cached_blobs_valid_ = true;
      std::array<Eigen::Vector3d, 3> j;
      for (std::size_t i = 0; i < 3; ++i) {
        const Eigen::Vector2d& uv = blobs_[B[i]].uv_undistorted;
        j[i] = Eigen::Vector3d((uv.x() - cam_.cx) / cam_.fx, (uv.y() - cam_.cy) / cam_.fy, 1).normalized();
      }
      const detail::P3pSolutions sol = detail::solve_p3p(j[0], j[1], j[2], sides_[0], sides_[1], sides_[2]);
      predicted_count_ = 0;
      for (int k = 0; k < sol.count; ++k) {
        const Eigen::Vector3d& d = sol.s[static_cast<std::size_t>(k)];
        const Eigen::Vector3d q1 = d(0) * j[0], f1 = d(1) * j[1] - q1, f2 = d(2) * j[2] - q1;
        const Eigen::Vector3d q4 =
            q1 + fourth_in_triangle_(0) * f1 + fourth_in_triangle_(1) * f2 + fourth_in_triangle_(2) * f1.cross(f2);
        if (q4.z() > 1e-6) predicted_[static_cast<std::size_t>(predicted_count_++)] = cam_.project(q4);
      }
      no_solution_ = sol.count == 0;
    }
    if (no_solution_) return true;
    const double gate = o_.p3p_gate * o_.inlier_px;
    for (int k = 0; k < predicted_count_; ++k) {
      if ((predicted_[static_cast<std::size_t>(k)] - blobs_[B[3]].uv_undistorted).squaredNorm() <= gate * gate)
        return true;
    }
    return false;
  }

  // Gates a refined pose with the LED assignment `assign` (`matched` LEDs)
  // must pass.
  bool plausible(const PoseRefinement& fit, const std::array<int, kMaxLeds>& assign, std::size_t matched) const {
    const double depth = (fit.T_camera_body * centroid_).z();
    if (depth < o_.min_distance || depth > o_.max_distance) return false;
    // The measured gravity direction: a pose that tilts the board against
    // it is not the board.
    if (attitude_.chi2(fit.T_camera_body.linear()) > o_.attitude_gate_chi2) return false;
    // Emission geometry (Led::normal, half_angle_deg): every matched LED
    // must shine toward the camera, within the margin.
    if (!detail::matched_leds_face_camera(k_, assign, fit.T_camera_body, margin_)) return false;
    // Four LEDs leave 2 redundant measurements: random blobs can fit them,
    // so a four-LED pose (of a larger constellation) must fit tightly.
    if (matched == 4 && n_ > 4 && fit.rms_px > o_.minimal_fit_rms_px) return false;
    // Without a prior, a pose that should show more LEDs needs more
    // (search_min_leds): the search tries thousands of 4-tuples. Expected:
    // in front of the camera and shining toward it within the margin (the
    // wide cone, so that a wrong pose cannot expect fewer by turning).
    if (matched < static_cast<std::size_t>(o_.search_min_leds)) {
      const Eigen::Vector3d camera_body = detail::camera_in_body(fit.T_camera_body);
      std::size_t expected = 0;
      for (const Led& led : k_.leds) {
        expected += (fit.T_camera_body * led.p_body).z() > 0 && led.emits_toward(camera_body, margin_) ? 1 : 0;
      }
      if (matched < std::min(static_cast<std::size_t>(o_.search_min_leds), expected > 0 ? expected - 1 : 0))
        return false;
    }
    return true;
  }

  const PinholeCamera& cam_;
  const Constellation& k_;
  std::span<const Blob> blobs_;
  const CorrespondenceOptions& o_;
  const AttitudeConstraint& attitude_;
  std::size_t n_;
  double penalty2_;
  Eigen::Vector3d centroid_;
  double margin_;
  Correspondence best_;
  double best_score_ = std::numeric_limits<double>::infinity();
  // fourth_fits()'s caches.
  Quad cached_leds_{{kNone, kNone, kNone, kNone}}, cached_blobs_{};
  bool cached_blobs_valid_ = false, leds_usable_ = false, no_solution_ = true;
  Eigen::Vector3d fourth_in_triangle_ = Eigen::Vector3d::Zero();
  std::array<double, 3> sides_{};
  std::array<Eigen::Vector2d, 4> predicted_{};
  int predicted_count_ = 0;
};

}  // namespace

namespace detail {

Correspondence find_correspondences(const PinholeCamera& cam, const Constellation& k, const ConstellationShape& shape,
                                    std::span<const Blob> all_blobs, const CorrespondenceOptions& o,
                                    const AttitudeConstraint& attitude) {
  const std::size_t first = std::min(all_blobs.size(), o.max_blobs);
  const std::span<const Blob> blobs = all_blobs.first(std::max(first, std::min(all_blobs.size(), o.max_blobs_retry)));
  if (blobs.size() < static_cast<std::size_t>(o.min_leds) || k.leds.size() < 4) {
    Correspondence none;
    none.blob_of_led.fill(-1);
    none.status = PoseStatus::TooFewBlobs;
    return none;
  }
  // Every 4-subset of LEDs against every ordered 4-tuple of distinct,
  // colour-compatible blobs: first among the `first` brightest blobs, then,
  // if that gave no pose, the tuples that use one of the next ones
  // (max_blobs_retry). Every hypothesis is verified against all of them.
  Search search(cam, k, blobs, o, attitude);
  const auto pass = [&](bool retry) {
    for_each_subset(k.leds.size(), [&](const Quad& L) {
      Quad B{};
      return for_each_blob_tuple(k, blobs, L, B, 0, [&](const Quad& b) {
        const bool uses_next = *std::max_element(b.begin(), b.end()) >= first;
        return uses_next == retry ? search.consider(L, b) : true;
      });
    });
  };
  pass(false);
  if (blobs.size() > first && !search.found()) pass(true);
  return search.finish(shape);
}

}  // namespace detail

Correspondence find_correspondences(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs,
                                    const CorrespondenceOptions& o) {
  return detail::find_correspondences(cam, k, detail::ConstellationShape::of(k), blobs, o);
}

}  // namespace touchdown::pose
