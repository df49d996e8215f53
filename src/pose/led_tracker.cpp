#include "touchdown/pose/led_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/epnp.hpp"

namespace touchdown::pose {

std::string_view to_string(PoseStatus s) {
  switch (s) {
    case PoseStatus::Ok:
      return "ok";
    case PoseStatus::TooFewBlobs:
      return "too few blobs";
    case PoseStatus::NoConsistentCorrespondence:
      return "no consistent correspondence";
    case PoseStatus::ReprojectionTooLarge:
      return "reprojection error too large";
    case PoseStatus::MarkerNotFound:
      return "marker not found";
    case PoseStatus::Degenerate:
      return "degenerate geometry";
  }
  return "unknown";
}

bool CorrespondenceOptions::validate(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!(inlier_px > 0)) return fail("inlier_px: must be positive");
  if (!(accept_rms_px > 0)) return fail("accept_rms_px: must be positive");
  if (max_blobs < 4 || max_blobs > 32) return fail("max_blobs: must be in 4..32");
  if (max_hypotheses < 1) return fail("max_hypotheses: must be positive");
  if (min_leds < 4) return fail("min_leds: must be at least 4");
  if (!(max_view_angle_deg > 0 && max_view_angle_deg <= 180)) return fail("max_view_angle_deg: must be in (0, 180]");
  if (!(minimal_fit_rms_px > 0)) return fail("minimal_fit_rms_px: must be positive");
  if (!(missing_penalty_px > 0)) return fail("missing_penalty_px: must be positive");
  if (!(min_distance >= 0 && max_distance > min_distance))
    return fail("min_distance/max_distance: need 0 <= min < max");
  if (refine.max_iterations < 1) return fail("refine.max_iterations: must be positive");
  return true;
}

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
  if (!(duplicate_fraction >= 0 && duplicate_fraction < 1)) return fail("duplicate_fraction: must be in [0, 1)");
  return true;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Points of the matched LEDs, gathered into fixed arrays for the solvers.
struct MatchedSet {
  std::array<Eigen::Vector3d, kMaxLeds> p;
  std::array<Eigen::Vector2d, kMaxLeds> uv;
  std::size_t n = 0;
};

void gather(const Constellation& k, std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
            MatchedSet& s) {
  s.n = 0;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    if (blob_of_led[l] < 0) continue;
    s.p[s.n] = k.leds[l].p_body;
    s.uv[s.n] = blobs[static_cast<std::size_t>(blob_of_led[l])].uv_undistorted;
    ++s.n;
  }
}

// Greedy nearest-blob matching of every reprojected LED within `gate`
// (fast; for verifying hypotheses). Returns the number matched and the sum
// of squared distances.
int greedy_match(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs,
                 const Eigen::Isometry3d& T, double gate, std::array<int, kMaxLeds>& blob_of_led, double& sq) {
  std::array<bool, 64> used{};
  int matched = 0;
  sq = 0;
  const double gate2 = gate * gate;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    blob_of_led[l] = -1;
    const Eigen::Vector3d q = T * k.leds[l].p_body;
    if (!(q.z() > 1e-6)) continue;
    const Eigen::Vector2d uv = cam.project(q);
    double best = gate2;
    int arg = -1;
    for (std::size_t b = 0; b < blobs.size() && b < used.size(); ++b) {
      if (used[b] || !colors_compatible(k.leds[l].color, blobs[b].color)) continue;
      const double d2 = (blobs[b].uv_undistorted - uv).squaredNorm();
      if (d2 < best) {
        best = d2;
        arg = static_cast<int>(b);
      }
    }
    if (arg >= 0) {
      used[static_cast<std::size_t>(arg)] = true;
      blob_of_led[l] = arg;
      ++matched;
      sq += best;
    }
  }
  return matched;
}

// Hungarian algorithm (potentials form, O(n² m)) for an n × m cost matrix
// with n ≤ m, row-major in `cost`; `row_to_col` gets each row's column.
// Written from Kuhn (1955) / Munkres (1957) in the shortest-augmenting-path
// formulation. Fixed-capacity workspace: no allocation.
struct Hungarian {
  static constexpr std::size_t kMaxCols = 64;
  std::array<double, kMaxLeds + 1> u{};
  std::array<double, kMaxCols + 1> v{}, minv{};
  std::array<int, kMaxCols + 1> p{}, way{};
  std::array<bool, kMaxCols + 1> used{};

  void solve(const double* cost, std::size_t n, std::size_t m, std::array<int, kMaxLeds>& row_to_col) {
    std::fill(u.begin(), u.begin() + static_cast<std::ptrdiff_t>(n + 1), 0.0);
    std::fill(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m + 1), 0.0);
    std::fill(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(m + 1), 0);
    for (std::size_t i = 1; i <= n; ++i) {
      p[0] = static_cast<int>(i);
      std::size_t j0 = 0;
      std::fill(minv.begin(), minv.begin() + static_cast<std::ptrdiff_t>(m + 1), kInf);
      std::fill(used.begin(), used.begin() + static_cast<std::ptrdiff_t>(m + 1), false);
      do {
        used[j0] = true;
        const auto i0 = static_cast<std::size_t>(p[j0]);
        double delta = kInf;
        std::size_t j1 = 0;
        for (std::size_t j = 1; j <= m; ++j) {
          if (used[j]) continue;
          const double cur = cost[(i0 - 1) * m + (j - 1)] - u[i0] - v[j];
          if (cur < minv[j]) {
            minv[j] = cur;
            way[j] = static_cast<int>(j0);
          }
          if (minv[j] < delta) {
            delta = minv[j];
            j1 = j;
          }
        }
        for (std::size_t j = 0; j <= m; ++j) {
          if (used[j]) {
            u[static_cast<std::size_t>(p[j])] += delta;
            v[j] -= delta;
          } else {
            minv[j] -= delta;
          }
        }
        j0 = j1;
      } while (p[j0] != 0);
      do {
        const auto j1 = static_cast<std::size_t>(way[j0]);
        p[j0] = p[j1];
        j0 = j1;
      } while (j0 != 0);
    }
    for (std::size_t i = 0; i < n; ++i) row_to_col[i] = -1;
    for (std::size_t j = 1; j <= m; ++j) {
      if (p[j] != 0) row_to_col[static_cast<std::size_t>(p[j] - 1)] = static_cast<int>(j - 1);
    }
  }
};

// Minimum-cost assignment of reprojected LEDs to blobs; pairs farther than
// `gate` or of incompatible colour are not matched. Returns the count.
int optimal_match(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs,
                  const Eigen::Isometry3d& T, double gate, Hungarian& h, std::array<double, kMaxLeds * 64>& cost,
                  std::array<int, kMaxLeds>& blob_of_led) {
  const std::size_t n = k.leds.size();
  const std::size_t m = std::min<std::size_t>(blobs.size(), Hungarian::kMaxCols);
  for (std::size_t l = 0; l < n; ++l) blob_of_led[l] = -1;
  if (m == 0) return 0;
  // Unmatchable pairs cost more than any gated pair; dummy columns (when
  // fewer blobs than LEDs) cost the same, so they absorb unseen LEDs.
  const double big = 4.0 * gate * gate + 1.0;
  const std::size_t cols = std::max(n, m);
  for (std::size_t l = 0; l < n; ++l) {
    const Eigen::Vector3d q = T * k.leds[l].p_body;
    const bool front = q.z() > 1e-6;
    const Eigen::Vector2d uv = front ? cam.project(q) : Eigen::Vector2d::Zero();
    for (std::size_t b = 0; b < cols; ++b) {
      double c = big;
      if (front && b < m && colors_compatible(k.leds[l].color, blobs[b].color)) {
        const double d2 = (blobs[b].uv_undistorted - uv).squaredNorm();
        if (d2 <= gate * gate) c = d2;
      }
      cost[l * cols + b] = c;
    }
  }
  std::array<int, kMaxLeds> col{};
  h.solve(cost.data(), n, cols, col);
  int matched = 0;
  for (std::size_t l = 0; l < n; ++l) {
    const int b = col[l];
    if (b >= 0 && static_cast<std::size_t>(b) < m && cost[l * cols + static_cast<std::size_t>(b)] < big) {
      blob_of_led[l] = b;
      ++matched;
    }
  }
  return matched;
}

}  // namespace

Correspondence find_correspondences(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> all_blobs,
                                    const CorrespondenceOptions& o) {
  Correspondence best;
  best.blob_of_led.fill(-1);
  const std::size_t n = k.leds.size();
  const std::span<const Blob> blobs = all_blobs.first(std::min(all_blobs.size(), o.max_blobs));
  const std::size_t m = blobs.size();
  if (m < static_cast<std::size_t>(o.min_leds) || n < 4) {
    best.status = PoseStatus::TooFewBlobs;
    return best;
  }
  best.status = PoseStatus::NoConsistentCorrespondence;
  double best_rms = kInf;
  std::array<Eigen::Vector3d, 4> p4;
  std::array<Eigen::Vector2d, 4> uv4;
  std::array<int, kMaxLeds> assign{};
  MatchedSet set;
  const std::size_t target = std::min(n, m);
  const double penalty2 = o.missing_penalty_px * o.missing_penalty_px;
  double best_score = kInf;
  const Eigen::Vector3d centroid = k.centroid();
  const double cos_view = std::cos(deg_to_rad(o.max_view_angle_deg));
  bool done = false;
  // Every 4-subset of LEDs (non-degenerate) against every ordered 4-tuple
  // of distinct, colour-compatible blobs.
  std::array<std::size_t, 4> L{};
  for (L[0] = 0; L[0] < n && !done; ++L[0]) {
    for (L[1] = L[0] + 1; L[1] < n && !done; ++L[1]) {
      for (L[2] = L[1] + 1; L[2] < n && !done; ++L[2]) {
        for (L[3] = L[2] + 1; L[3] < n && !done; ++L[3]) {
          for (int i = 0; i < 4; ++i) p4[static_cast<std::size_t>(i)] = k.leds[L[static_cast<std::size_t>(i)]].p_body;
          std::array<std::size_t, 4> B{};
          auto ok_blob = [&](int level, std::size_t b) {
            for (int j = 0; j < level; ++j) {
              if (B[static_cast<std::size_t>(j)] == b) return false;
            }
            return colors_compatible(k.leds[L[static_cast<std::size_t>(level)]].color, blobs[b].color);
          };
          for (B[0] = 0; B[0] < m && !done; ++B[0]) {
            if (!ok_blob(0, B[0])) continue;
            for (B[1] = 0; B[1] < m && !done; ++B[1]) {
              if (!ok_blob(1, B[1])) continue;
              for (B[2] = 0; B[2] < m && !done; ++B[2]) {
                if (!ok_blob(2, B[2])) continue;
                for (B[3] = 0; B[3] < m && !done; ++B[3]) {
                  if (!ok_blob(3, B[3])) continue;
                  if (best.hypotheses >= o.max_hypotheses) {
                    done = true;
                    break;
                  }
                  ++best.hypotheses;
                  for (int i = 0; i < 4; ++i)
                    uv4[static_cast<std::size_t>(i)] = blobs[B[static_cast<std::size_t>(i)]].uv_undistorted;
                  const EpnpResult e = solve_epnp(cam, p4, uv4);
                  if (!e.ok || e.rms_px > o.inlier_px) continue;
                  double sq = 0;
                  const int matched = greedy_match(cam, k, blobs, e.T_camera_body, o.inlier_px, assign, sq);
                  if (matched < o.min_leds) continue;
                  // MSAC-style score: squared error of the explained LEDs
                  // plus a fixed penalty per unexplained one, so that a
                  // wrong pose cannot win by stretching onto a spurious blob.
                  if (sq + (static_cast<double>(n) - matched) * penalty2 >= best_score) continue;
                  gather(k, blobs, assign, set);
                  PoseRefinement fit = refine_pose_gauss_newton(
                      cam, std::span(set.p.data(), set.n), std::span(set.uv.data(), set.n), e.T_camera_body, o.refine);
                  if (!fit.ok()) continue;
                  // Re-match from the refined pose and refine once more if it changed.
                  std::array<int, kMaxLeds> again{};
                  const int rematched = greedy_match(cam, k, blobs, fit.T_camera_body, o.inlier_px, again, sq);
                  if (rematched >= o.min_leds && again != assign) {
                    assign = again;
                    gather(k, blobs, assign, set);
                    const PoseRefinement f2 =
                        refine_pose_gauss_newton(cam, std::span(set.p.data(), set.n), std::span(set.uv.data(), set.n),
                                                 fit.T_camera_body, o.refine);
                    if (!f2.ok()) continue;
                    fit = f2;
                  }
                  const double depth = (fit.T_camera_body * centroid).z();
                  if (depth < o.min_distance || depth > o.max_distance) continue;
                  // The LEDs shine into the hemisphere around body −z: the
                  // camera must lie inside the emission cone.
                  const Eigen::Vector3d cam_in_body = fit.T_camera_body.inverse().translation() - centroid;
                  if (-cam_in_body.z() < cos_view * cam_in_body.norm()) continue;
                  // Four LEDs leave 2 redundant measurements: random blobs
                  // can fit them, so a four-LED pose (of a larger
                  // constellation) must fit tightly.
                  if (set.n == 4 && n > 4 && fit.rms_px > o.minimal_fit_rms_px) continue;
                  const double count = static_cast<double>(set.n);
                  const double score = fit.rms_px * fit.rms_px * count + (static_cast<double>(n) - count) * penalty2;
                  if (score < best_score) {
                    best_score = score;
                    best.matched = static_cast<int>(set.n);
                    best.blob_of_led = assign;
                    best.fit = fit;
                    best_rms = fit.rms_px;
                    // Every LED (or every blob) explained, well: stop.
                    if (set.n == target && fit.rms_px < 0.5 * o.accept_rms_px) done = true;
                  }
                }
              }
            }
          }
        }
      }
    }
  }
  if (best.matched >= o.min_leds) {
    best.status = best_rms <= o.accept_rms_px ? PoseStatus::Ok : PoseStatus::ReprojectionTooLarge;
  }
  return best;
}

struct LedTracker::Impl {
  CameraModel camera;
  PinholeCamera pin;
  Constellation constellation;
  TrackerOptions options;
  LedDetector detector;
  std::vector<Blob> detected, work;
  PoseEstimate estimate;
  std::array<int, kMaxLeds> led_to_blob{};
  bool tracking = false;
  bool have_velocity = false;
  Eigen::Isometry3d last_pose = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d previous_pose = Eigen::Isometry3d::Identity();
  Hungarian hungarian;
  std::array<double, kMaxLeds * 64> cost{};
  double min_led_spacing = 0;
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
    min_led_spacing = kInf;
    for (std::size_t i = 0; i < k.leds.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j)
        min_led_spacing = std::min(min_led_spacing, (k.leds[i].p_body - k.leds[j].p_body).norm());
    }
    const_mad = k.mean_absolute_deviation();
    const_radius = k.radius();
    const_centroid = k.centroid();
    led_to_blob.fill(-1);
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

  void accept(const PoseRefinement& fit, int points, bool reinit) {
    estimate.status = PoseStatus::Ok;
    estimate.T_camera_body = fit.T_camera_body;
    estimate.rms_px = fit.rms_px;
    estimate.points = points;
    estimate.reinitialised = reinit;
    estimate.covariance = fit.covariance;
    previous_pose = last_pose;
    have_velocity = tracking;
    last_pose = fit.T_camera_body;
    tracking = true;
  }

  void lose(PoseStatus s) {
    estimate.status = s;
    estimate.points = 0;
    estimate.rms_px = 0;
    estimate.T_camera_body = Eigen::Isometry3d::Identity();  // never a stale pose
    estimate.covariance.setZero();
    tracking = false;
    have_velocity = false;
    led_to_blob.fill(-1);
  }

  bool try_track() {
    const Eigen::Isometry3d T = predicted();
    const Eigen::Vector3d c = T * const_centroid;
    if (!(c.z() > 1e-6)) return false;
    gate(T);
    suppress_duplicates(options.duplicate_fraction * min_led_spacing * pin.fx / c.z());
    int matched = optimal_match(pin, constellation, work, T, options.track_gate_px, hungarian, cost, led_to_blob);
    if (matched < options.correspondence.min_leds) return false;
    MatchedSet set;
    gather(constellation, work, led_to_blob, set);
    PoseRefinement fit = refine_pose_gauss_newton(pin, std::span(set.p.data(), set.n), std::span(set.uv.data(), set.n),
                                                  T, options.correspondence.refine);
    if (!fit.ok() || fit.rms_px > options.reinit_rms_px) return false;
    // Re-match from the refined pose with the tighter inlier gate: picks up
    // LEDs the prediction missed and drops ones it mismatched.
    std::array<int, kMaxLeds> again{};
    matched = optimal_match(pin, constellation, work, fit.T_camera_body, options.correspondence.inlier_px, hungarian,
                            cost, again);
    if (matched >= options.correspondence.min_leds && again != led_to_blob) {
      led_to_blob = again;
      gather(constellation, work, led_to_blob, set);
      const PoseRefinement f2 =
          refine_pose_gauss_newton(pin, std::span(set.p.data(), set.n), std::span(set.uv.data(), set.n),
                                   fit.T_camera_body, options.correspondence.refine);
      if (f2.ok()) fit = f2;
    }
    if (fit.rms_px > options.reinit_rms_px) return false;
    accept(fit, static_cast<int>(set.n), false);
    return true;
  }

  const PoseEstimate& run(std::span<const Blob> blobs) {
    work.assign(blobs.begin(), blobs.end());
    estimate.reinitialised = false;
    if (!options.use_depth) {
      for (auto& b : work) b.has_point = false;
    }
    if (tracking && work.size() >= static_cast<std::size_t>(options.correspondence.min_leds) && try_track()) {
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
    const Correspondence c = find_correspondences(pin, constellation, work, options.correspondence);
    if (c.status != PoseStatus::Ok) {
      lose(c.status);
      return estimate;
    }
    led_to_blob = c.blob_of_led;
    tracking = false;  // a fresh track: no velocity yet
    have_velocity = false;
    accept(c.fit, c.matched, true);
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
  impl_->detector.detect(colour, impl_->options.use_depth ? depth : nullptr, impl_->detected);
  return impl_->run(impl_->detected);
}

const PoseEstimate& LedTracker::track_blobs(std::span<const Blob> blobs) { return impl_->run(blobs); }

void LedTracker::reset() { impl_->lose(PoseStatus::TooFewBlobs); }

const PoseEstimate& LedTracker::last() const { return impl_->estimate; }
const std::vector<Blob>& LedTracker::blobs() const { return impl_->work; }
const std::array<int, kMaxLeds>& LedTracker::led_to_blob() const { return impl_->led_to_blob; }

}  // namespace touchdown::pose
