#include "pose/assignment.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "touchdown/core/statistics.hpp"

namespace touchdown::pose::detail {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

constexpr int kMinPoseLeds = 4;  // EPnP and a redundant fit
// A blob more than this many times the median matched LED's area holds two
// sources. The LEDs of one board differ by up to ~1.6x in area at one range
// (halo, emission angle); measured on the harsh chase sequences and the 20x40
// robustness suite, 2 keeps the most poses (4: 0.839, 3, 2.5, 2: 0.864, 1.5
// fewer again), all with no wrong-ok.
constexpr double kMergedAreaRatio = 2;

// The other LED on LED l's blob (a merged spot), or −1.
int partner_of(const Constellation& k, const std::array<int, kMaxLeds>& blob_of_led, std::size_t l) {
  if (blob_of_led[l] < 0) return -1;
  for (std::size_t j = 0; j < k.leds.size(); ++j) {
    if (j != l && blob_of_led[j] == blob_of_led[l]) return static_cast<int>(j);
  }
  return -1;
}

void gather(const Constellation& k, std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
            MatchedSet& s, double depth_sigma_k, double pixel_sigma) {
  s.n = 0;
  s.depths = 0;
  s.has_bias = false;
  s.pixel_sigma = pixel_sigma;
  // Merged blobs only when the others are too few for a pose: first ones
  // far larger than the other matched LEDs' (an LED and its reflection or
  // a neighbour joined without a dip between them: the centre lies between
  // the sources), then split ones (their centres pulled by up to a pixel by
  // the neighbour they were split from). A blob two LEDs share is a merge
  // the tracker found: left out first (the tracker tests it against the
  // fit: explains_frame), kept only when the others are too few for a
  // pose, as one point at the LEDs' midpoint (merged_bias); each of its
  // LEDs counts half its area in the median.
  std::array<int, kMaxLeds> partner{};
  std::array<double, kMaxLeds> areas{};
  std::size_t n_areas = 0;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    partner[l] = partner_of(k, blob_of_led, l);
    if (blob_of_led[l] >= 0) {
      areas[n_areas++] = blobs[static_cast<std::size_t>(blob_of_led[l])].area / (partner[l] >= 0 ? 2.0 : 1.0);
    }
  }
  const double oversized =
      n_areas > 0 ? kMergedAreaRatio * upper_median_in_place(std::span(areas).first(n_areas)) : kInf;
  int joined = 0, split = 0, merged = 0, points = 0;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    if (blob_of_led[l] < 0 || (partner[l] >= 0 && partner[l] < static_cast<int>(l))) continue;
    const Blob& b = blobs[static_cast<std::size_t>(blob_of_led[l])];
    merged += partner[l] >= 0;
    const bool is_joined = partner[l] < 0 && b.area > oversized;
    joined += is_joined;
    split += !is_joined && partner[l] < 0 && b.split;
    ++points;
  }
  const bool skip_merged = points - merged >= kMinPoseLeds;
  const int rest = points - merged * static_cast<int>(skip_merged);
  const bool skip_joined = rest - joined >= kMinPoseLeds;
  const bool skip_split = skip_joined && rest - joined - split >= kMinPoseLeds;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    const int other = partner[l];
    if (blob_of_led[l] < 0 || (other >= 0 && other < static_cast<int>(l))) continue;
    const Blob& b = blobs[static_cast<std::size_t>(blob_of_led[l])];
    if (other >= 0 ? skip_merged : (skip_joined && b.area > oversized) || (skip_split && b.split)) continue;
    s.merged[s.n] = other >= 0;
    s.p[s.n] = other >= 0 ? (0.5 * (k.leds[l].p_body + k.leds[static_cast<std::size_t>(other)].p_body)).eval()
                          : k.leds[l].p_body;
    s.uv[s.n] = b.uv_undistorted;
    s.blob[s.n] = blob_of_led[l];
    s.bias[s.n] = 0;
    s.z[s.n] = std::numeric_limits<double>::quiet_NaN();
    s.sigma[s.n] = 1;
    // A merged blob's depth is of neither LED (nor surely of their midpoint).
    if (depth_sigma_k >= 0 && b.has_point && other < 0) {
      const double z = b.p_camera.z();
      s.z[s.n] = z;
      s.sigma[s.n] = depth_sigma_k * z * z + 0.002;
      ++s.depths;
    }
    ++s.n;
  }
}

double blob_bias_variance(const Blob& b, std::span<const Blob> blobs, const CorrespondenceOptions& o,
                          double noise_variance) {
  const double r = std::max(1.0, std::sqrt(b.area / std::numbers::pi));
  double nearest2 = kInf;
  for (const Blob& other : blobs) {
    if (&other == &b) continue;
    nearest2 = std::min(nearest2, (other.uv_px - b.uv_px).squaredNorm());
  }
  const double q = std::sqrt(nearest2) / r;  // the nearest blob's distance in b's radii
  const double half = 0.5 * o.crowded_radii;
  const double f = q >= o.crowded_radii ? 0.0 : std::pow(std::min(1.0, (o.crowded_radii - q) / half), 2);
  double sigma = o.crowded_bias_px * f;
  if (b.split) sigma = std::max(sigma, o.split_bias * r);
  // The spot's own centre error (small_blob_sigma_px3, large_blob_sigma_px):
  // its excess over the noise the fit is judged by.
  const double small = o.small_blob_sigma_px3 / std::max(1.0, b.area);
  const double large = o.large_blob_sigma_px * std::sqrt(std::max(0.0, b.area));
  return sigma * sigma + std::max(0.0, small * small + large * large - noise_variance);
}

void gather(const Constellation& k, std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
            const CorrespondenceOptions& o, MatchedSet& s) {
  gather(k, blobs, blob_of_led, o, s, o.detection_sigma_px * o.detection_sigma_px);
}

void gather(const Constellation& k, std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
            const CorrespondenceOptions& o, MatchedSet& s, double noise_variance) {
  gather(k, blobs, blob_of_led, s, o.fuse_depth ? o.depth_sigma_k : -1.0, o.detection_sigma_px);
  for (std::size_t i = 0; i < s.n; ++i) {
    const Blob& b = blobs[static_cast<std::size_t>(s.blob[i])];
    s.bias[i] = blob_bias_variance(b, blobs, o, noise_variance);
    if (s.merged[i]) s.bias[i] += std::pow(o.merged_bias * std::max(1.0, std::sqrt(b.area / std::numbers::pi)), 2);
    s.has_bias |= s.bias[i] > 0;
  }
}

Eigen::Vector3d camera_in_body(const Eigen::Isometry3d& T_camera_body) {
  return -(T_camera_body.linear().transpose() * T_camera_body.translation());
}

bool matched_leds_face_camera(const Constellation& k, const std::array<int, kMaxLeds>& blob_of_led,
                              const Eigen::Isometry3d& T, double emission_margin) {
  const Eigen::Vector3d camera_body = camera_in_body(T);
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    if (blob_of_led[l] >= 0 && !k.leds[l].emits_toward(camera_body, emission_margin)) return false;
  }
  return true;
}

int greedy_match(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs,
                 const Eigen::Isometry3d& T, double gate, double emission_margin,
                 std::array<int, kMaxLeds>& blob_of_led, double& sq) {
  std::array<bool, 64> used{};
  int matched = 0;
  sq = 0;
  const double gate2 = gate * gate;
  const Eigen::Vector3d camera_body = camera_in_body(T);
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    blob_of_led[l] = -1;
    const Eigen::Vector3d q = T * k.leds[l].p_body;
    if (!faces_camera(k.leds[l], q, camera_body, emission_margin)) continue;
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

// Written from Kuhn (1955) / Munkres (1957) in the shortest-augmenting-path
// formulation with row and column potentials.
void Hungarian::solve(const double* cost, std::size_t n, std::size_t m, std::array<int, kMaxLeds>& row_to_col) {
  std::fill(u_.begin(), u_.begin() + static_cast<std::ptrdiff_t>(n + 1), 0.0);
  std::fill(v_.begin(), v_.begin() + static_cast<std::ptrdiff_t>(m + 1), 0.0);
  std::fill(p_.begin(), p_.begin() + static_cast<std::ptrdiff_t>(m + 1), 0);
  for (std::size_t i = 1; i <= n; ++i) {
    p_[0] = static_cast<int>(i);
    std::size_t j0 = 0;
    std::fill(minv_.begin(), minv_.begin() + static_cast<std::ptrdiff_t>(m + 1), kInf);
    std::fill(used_.begin(), used_.begin() + static_cast<std::ptrdiff_t>(m + 1), false);
    do {
      used_[j0] = true;
      const auto i0 = static_cast<std::size_t>(p_[j0]);
      double delta = kInf;
      std::size_t j1 = 0;
      for (std::size_t j = 1; j <= m; ++j) {
        if (used_[j]) continue;
        const double cur = cost[(i0 - 1) * m + (j - 1)] - u_[i0] - v_[j];
        if (cur < minv_[j]) {
          minv_[j] = cur;
          way_[j] = static_cast<int>(j0);
        }
        if (minv_[j] < delta) {
          delta = minv_[j];
          j1 = j;
        }
      }
      for (std::size_t j = 0; j <= m; ++j) {
        if (used_[j]) {
          u_[static_cast<std::size_t>(p_[j])] += delta;
          v_[j] -= delta;
        } else {
          minv_[j] -= delta;
        }
      }
      j0 = j1;
    } while (p_[j0] != 0);
    do {
      const auto j1 = static_cast<std::size_t>(way_[j0]);
      p_[j0] = p_[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  for (std::size_t i = 0; i < n; ++i) row_to_col[i] = -1;
  for (std::size_t j = 1; j <= m; ++j) {
    if (p_[j] != 0) row_to_col[static_cast<std::size_t>(p_[j] - 1)] = static_cast<int>(j - 1);
  }
}

int OptimalMatcher::match(const PinholeCamera& cam, const Constellation& k, std::span<const Blob> blobs,
                          const Eigen::Isometry3d& T, double gate, double emission_margin,
                          std::array<int, kMaxLeds>& blob_of_led) {
  const std::size_t n = k.leds.size();
  const std::size_t m = std::min<std::size_t>(blobs.size(), Hungarian::kMaxCols);
  for (std::size_t l = 0; l < n; ++l) blob_of_led[l] = -1;
  if (m == 0) return 0;
  // Unmatchable pairs cost more than any gated pair; dummy columns (when
  // fewer blobs than LEDs) cost the same, so they absorb unseen LEDs.
  const double big = 4.0 * gate * gate + 1.0;
  const std::size_t cols = std::max(n, m);
  const Eigen::Vector3d camera_body = camera_in_body(T);
  for (std::size_t l = 0; l < n; ++l) {
    const Eigen::Vector3d q = T * k.leds[l].p_body;
    const bool front = faces_camera(k.leds[l], q, camera_body, emission_margin);
    const Eigen::Vector2d uv = front ? cam.project(q) : Eigen::Vector2d::Zero();
    for (std::size_t b = 0; b < cols; ++b) {
      double c = big;
      if (front && b < m && colors_compatible(k.leds[l].color, blobs[b].color)) {
        const double d2 = (blobs[b].uv_undistorted - uv).squaredNorm();
        if (d2 <= gate * gate) c = d2;
      }
      cost_[l * cols + b] = c;
    }
  }
  std::array<int, kMaxLeds> col{};
  hungarian_.solve(cost_.data(), n, cols, col);
  int matched = 0;
  for (std::size_t l = 0; l < n; ++l) {
    const int b = col[l];
    if (b >= 0 && static_cast<std::size_t>(b) < m && cost_[l * cols + static_cast<std::size_t>(b)] < big) {
      blob_of_led[l] = b;
      ++matched;
    }
  }
  return matched;
}

}  // namespace touchdown::pose::detail
