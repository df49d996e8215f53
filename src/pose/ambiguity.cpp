#include "pose/ambiguity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pose/dense_solvers.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::pose::detail {

namespace {

// An orthonormal frame from three non-collinear points: origin a, x toward
// b, z normal to the triangle. Columns of the rotation; false if collinear.
bool triangle_frame(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Matrix3d& R) {
  const Eigen::Vector3d x = b - a;
  const Eigen::Vector3d z = x.cross(c - a);
  if (x.norm() < 1e-9 || z.norm() < 1e-12 * x.squaredNorm() || z.norm() < 1e-12) return false;
  R.col(0) = x.normalized();
  R.col(2) = z.normalized();
  R.col(1) = R.col(2).cross(R.col(0));
  return true;
}

}  // namespace

double rotation_angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

bool has_rigid_symmetry(const Constellation& k) {
  const std::size_t n = k.leds.size();
  if (n < 3) return false;
  const double tol = std::max(0.003, 0.03 * k.radius());
  const double cos_normal = std::cos(deg_to_rad(10.0));
  // The base triangle: the largest one (well conditioned).
  std::array<std::size_t, 3> base{0, 1, 2};
  double best_area = -1;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      for (std::size_t l = j + 1; l < n; ++l) {
        const double area =
            (k.leds[j].p_body - k.leds[i].p_body).cross(k.leds[l].p_body - k.leds[i].p_body).squaredNorm();
        if (area > best_area) {
          best_area = area;
          base = {i, j, l};
        }
      }
    }
  }
  const auto& P = [&](std::size_t i) -> const Eigen::Vector3d& { return k.leds[i].p_body; };
  Eigen::Matrix3d F_base;
  if (!triangle_frame(P(base[0]), P(base[1]), P(base[2]), F_base)) return false;
  // Map the base triangle onto every congruent, colour-matched ordered
  // triple; a rigid motion that maps every LED onto a matching LED (and is
  // not the identity) is a symmetry.
  for (std::size_t i = 0; i < n; ++i) {
    if (k.leds[i].color != k.leds[base[0]].color) continue;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i || k.leds[j].color != k.leds[base[1]].color) continue;
      if (std::abs((P(j) - P(i)).norm() - (P(base[1]) - P(base[0])).norm()) > 2 * tol) continue;
      for (std::size_t l = 0; l < n; ++l) {
        if (l == i || l == j || k.leds[l].color != k.leds[base[2]].color) continue;
        if (i == base[0] && j == base[1] && l == base[2]) continue;  // the identity
        if (std::abs((P(l) - P(i)).norm() - (P(base[2]) - P(base[0])).norm()) > 2 * tol) continue;
        if (std::abs((P(l) - P(j)).norm() - (P(base[2]) - P(base[1])).norm()) > 2 * tol) continue;
        Eigen::Matrix3d F;
        if (!triangle_frame(P(i), P(j), P(l), F)) continue;
        const Eigen::Matrix3d R = F * F_base.transpose();
        const Eigen::Vector3d t = P(i) - R * P(base[0]);
        // Two LEDs closer than the tolerance swapped: not a pose ambiguity.
        if (Eigen::AngleAxisd(R).angle() < deg_to_rad(5.0)) continue;
        bool all = true;
        for (std::size_t a = 0; a < n && all; ++a) {
          const Eigen::Vector3d q = R * P(a) + t;
          const Eigen::Vector3d m = R * k.leds[a].normal;
          bool found = false;
          for (std::size_t b = 0; b < n && !found; ++b) {
            const Led& led = k.leds[b];
            if (led.color != k.leds[a].color || (q - led.p_body).norm() > tol) continue;
            if (led.has_normal() != k.leds[a].has_normal()) continue;
            found = !led.has_normal() || m.dot(led.normal) >= cos_normal;
          }
          all = found;
        }
        if (all) return true;
      }
    }
  }
  return false;
}

ConstellationShape ConstellationShape::of(const Constellation& k) {
  ConstellationShape s;
  s.centroid = k.centroid();
  SymmetricMatrix S = SymmetricMatrix::Zero(3, 3);
  for (const auto& l : k.leds) S.noalias() += (l.p_body - s.centroid) * (l.p_body - s.centroid).transpose();
  SymmetricVector values;
  SymmetricMatrix vectors;
  if (symmetric_eigen(S, values, vectors)) s.plane_normal = vectors.col(0).head<3>().normalized();
  s.symmetric = has_rigid_symmetry(k);
  return s;
}

Eigen::Isometry3d mirrored_branch(const Eigen::Isometry3d& T, const ConstellationShape& shape) {
  const Eigen::Vector3d c = T * shape.centroid;
  const Eigen::Vector3d v = c.normalized();  // line of sight
  const Eigen::Vector3d n = T.linear() * shape.plane_normal;
  const Eigen::Vector3d mirrored = 2 * n.dot(v) * v - n;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond::FromTwoVectors(n, mirrored).toRotationMatrix() * T.linear();
  out.translation() = c - out.linear() * shape.centroid;
  return out;
}

double depth_misfit(const Constellation& k, std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
                    const Eigen::Isometry3d& T, const CorrespondenceOptions& o) {
  std::array<double, kMaxLeds> r{}, s{}, sorted{};
  std::size_t n = 0;
  for (std::size_t l = 0; l < k.leds.size(); ++l) {
    if (blob_of_led[l] < 0 || partner_of(k, blob_of_led, l) >= 0) continue;  // a merged spot's depth is neither's
    const Blob& b = blobs[static_cast<std::size_t>(blob_of_led[l])];
    if (!b.has_point) continue;
    const double z = (T * k.leds[l].p_body).z();
    r[n] = b.p_camera.z() - z;
    s[n] = o.depth_sigma_k * z * z + 0.002;  // stereo noise k·z² + quantisation
    sorted[n] = r[n];
    ++n;
  }
  if (n < 3) return -1;
  // The depth measured at a blob may sit on the LED's housing or board, a
  // common offset: the branches differ in the pattern (the tilt), so the
  // median offset is removed first.
  const double offset = upper_median_in_place(std::span(sorted).first(n));
  double chi2 = 0;
  for (std::size_t i = 0; i < n; ++i) chi2 += std::pow((r[i] - offset) / s[i], 2);
  return chi2;
}

namespace {
// P(a, x) = γ(a, x) / Γ(a) = x^a e^−x / Γ(a + 1) · Σₙ xⁿ / ((a + 1)…(a + n)).
double lower_gamma_regularised(double a, double x) {
  if (x <= 0) return 0;
  double term = 1, sum = 1;
  for (int n = 1; n < 1000 && term > 1e-16 * sum; ++n) {
    term *= x / (a + n);
    sum += term;
  }
  return std::min(1.0, std::exp(a * std::log(x) - x - std::lgamma(a + 1)) * sum);
}
}  // namespace

double chi2_quantile(double dof, double p) {
  double lo = 0, hi = dof + 20 * std::sqrt(2 * dof) + 20;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (lower_gamma_regularised(0.5 * dof, 0.5 * mid) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Matrix6d fit_covariance(const PoseRefinement& fit, double floor_variance) {
  return fit.covariance_for(std::max(fit.noise_variance, floor_variance));
}

std::pair<double, double> fit_sigmas(const PoseRefinement& fit, const CorrespondenceOptions& o) {
  return pose_sigmas(fit_covariance(fit, o.detection_sigma_px * o.detection_sigma_px), fit.T_camera_body);
}

bool too_uncertain(const PoseRefinement& fit, const CorrespondenceOptions& o, bool with_attitude) {
  const auto [position, rotation] = fit_sigmas(fit, o);
  const auto [max_position, max_rotation] = o.sigma_limits(with_attitude);
  return position > max_position || rotation > max_rotation;
}

bool distinct_poses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const CorrespondenceOptions& o) {
  return (a.translation() - b.translation()).norm() > o.branch_distinct_m ||
         rotation_angle(a.linear(), b.linear()) > deg_to_rad(o.branch_distinct_deg);
}

BranchDecision resolve_branches(const PinholeCamera& cam, const Constellation& k, const ConstellationShape& shape,
                                std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led,
                                const MatchedSet& set, const PoseRefinement& fit, const Eigen::Isometry3d* predicted,
                                const CorrespondenceOptions& o, const AttitudeConstraint& attitude,
                                bool prediction_vouched) {
  BranchDecision d;
  d.alternative =
      refine_pose_gauss_newton(cam, set.points(), set.pixels(), mirrored_branch(fit.T_camera_body, shape), o.refine);
  if (!d.alternative.ok() || !distinct_poses(d.alternative.T_camera_body, fit.T_camera_body, o)) return d;
  // The other branch must also be a pose the LEDs could be seen from.
  if (!matched_leds_face_camera(k, blob_of_led, d.alternative.T_camera_body, deg_to_rad(o.emission_margin_deg))) {
    return d;
  }
  if ((d.alternative.T_camera_body * shape.centroid).z() <= 0) return d;
  // 1. Reprojection: Σr² of each branch against the detection noise, and
  // with an attitude prior its χ² (the other branch is refined on the image
  // alone, so that the prior cannot pull it back onto the fit).
  const double count = static_cast<double>(set.n);
  // The noise both are judged by, at least detection_sigma_px²: the larger
  // of the two branches' residual variances — unless detection_sigma_px is
  // the camera's measured noise (the tracker's noise pool), then the better
  // branch's. A wrong branch's residuals are its misfit, not noise; taking
  // them as the noise made every misfit look like noise (seen on an
  // independent renderer's 6-LED board at 3.2 m: the track's branch at
  // 0.035 px RMS against the mirrored one at 0.139 px scored χ² 2.7 and the
  // depth pattern then chose the wrong one; docs/journal/led-pose.md, "LED pose:
  // the sigma made true"). Without a measured noise the larger is kept: two
  // residual variances of a few degrees of freedom each are too noisy to
  // trust the smaller.
  const double floor = o.detection_sigma_px * o.detection_sigma_px;
  const double sigma2 = o.detection_sigma_measured
                            ? std::max(std::min(fit.noise_variance, d.alternative.noise_variance), floor)
                            : std::max({fit.noise_variance, d.alternative.noise_variance, floor});
  const double delta =  // > 0: fit better
      count * (d.alternative.rms_px * d.alternative.rms_px - fit.rms_px * fit.rms_px) / sigma2 +
      attitude.chi2(d.alternative.T_camera_body.linear()) - attitude.chi2(fit.T_camera_body.linear());
  // 2. Depth at the blobs: the same χ² test on the depth pattern (> 0:
  // fit better; 0 without depths).
  const double depth_fit = depth_misfit(k, blobs, blob_of_led, fit.T_camera_body, o);
  const double depth_alt = depth_misfit(k, blobs, blob_of_led, d.alternative.T_camera_body, o);
  const double depth_delta = depth_fit >= 0 && depth_alt >= 0 ? depth_alt - depth_fit : 0;
  // The two tests each rule out a different branch: independent
  // measurements, so their log-likelihood ratios add and the sum decides
  // (Ambiguous when it is not decisive). The image alone had decided
  // before: own renderer, harsh profile, a blurred 7-LED board at 2.7 m
  // whose two split blobs left the fit — the wrong branch reprojected at
  // 0.056 px against 0.123 px, χ² 15 on the pooled noise, while the depths
  // ruled it out at χ² 102: reported 1.17 rad wrong with σ_rot 0.009.
  // Ambiguous on every such conflict instead cost 1.9 % of the independent
  // suite's frames: its depths lean against the image's branch at χ² 10–45
  // where the image rules the other out at χ² 100–1 800.
  d.contradicted = (delta > o.branch_chi2 && depth_delta < -o.branch_chi2) ||
                   (delta < -o.branch_chi2 && depth_delta > o.branch_chi2);
  if (d.contradicted) {
    const double sum = delta + depth_delta;
    if (sum > o.branch_chi2) return d;
    d.verdict = sum < -o.branch_chi2 ? BranchVerdict::Switch : BranchVerdict::Ambiguous;
    return d;
  }
  if (delta > o.branch_chi2) return d;
  if (delta < -o.branch_chi2) {
    d.verdict = BranchVerdict::Switch;
    return d;
  }
  if (depth_delta > o.branch_chi2) return d;
  if (depth_delta < -o.branch_chi2) {
    d.verdict = BranchVerdict::Switch;
    return d;
  }
  // 3. Temporal consistency with the tracked motion. A prediction not made
  // from Ok poses (one from a too-uncertain fit) may sit on the wrong branch
  // itself: it settles the branch only where the image and the depths do
  // not lean the other way (own renderer, clean profile: a 5-LED board at
  // 3.1 m after a too-uncertain 4-point frame, the image and the depths
  // leaning toward the other branch at χ² 3.0 and 3.6 — the prediction's
  // branch was 0.41 rad wrong, reported at σ_rot 0.031).
  if (predicted) {
    const double to_fit = rotation_angle(predicted->linear(), fit.T_camera_body.linear());
    const double to_alt = rotation_angle(predicted->linear(), d.alternative.T_camera_body.linear());
    const double margin = deg_to_rad(o.branch_track_deg);
    const double lean = delta + depth_delta;  // > 0: toward fit
    if (to_fit + margin < to_alt && (prediction_vouched || lean >= 0)) return d;
    if (to_alt + margin < to_fit && (prediction_vouched || lean <= 0)) {
      d.verdict = BranchVerdict::Switch;
      return d;
    }
  }
  d.verdict = BranchVerdict::Ambiguous;
  return d;
}

PoseStatus vet_fit(const PinholeCamera& cam, const Constellation& k, const ConstellationShape& shape,
                   std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led, PoseRefinement& fit,
                   const Eigen::Isometry3d* predicted, double max_rms_px, const CorrespondenceOptions& o,
                   const AttitudeConstraint& attitude, bool prediction_vouched) {
  if (shape.symmetric) return PoseStatus::Ambiguous;
  MatchedSet set;
  gather(k, blobs, blob_of_led, set);
  const BranchDecision d =
      resolve_branches(cam, k, shape, blobs, blob_of_led, set, fit, predicted, o, attitude, prediction_vouched);
  if (d.verdict == BranchVerdict::Ambiguous) return PoseStatus::Ambiguous;
  if (d.verdict == BranchVerdict::Switch) {
    // The other branch, refined as the fit was (with the measured depths).
    MatchedSet fused;
    gather(k, blobs, blob_of_led, o, fused);
    const PoseRefinement refined =
        refine_pose_gauss_newton(cam, fused.points(), fused.pixels(), d.alternative.T_camera_body, o.refine,
                                 fused.depth(), attitude, fused.biases());
    fit = refined.ok() ? refined : d.alternative;
  }
  if (fit.rms_px > max_rms_px) return PoseStatus::ReprojectionTooLarge;
  if (too_uncertain(fit, o, attitude.active())) return PoseStatus::Uncertain;
  return PoseStatus::Ok;
}

}  // namespace touchdown::pose::detail
