#include "touchdown/pose/gauss_newton.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "touchdown/core/error.hpp"

namespace touchdown::pose {

namespace {
// Most depths GaussNewtonOptions::depth_outlier_sigma leaves out of one fit.
constexpr std::size_t kMaxDepthOutliers = 3;
}  // namespace

bool reprojection_residual(const PinholeCamera& cam, const Eigen::Isometry3d& T, const Eigen::Vector3d& p_body,
                           const Eigen::Vector2d& uv, Eigen::Vector2d& r, Eigen::Matrix<double, 2, 6>* J) {
  const Eigen::Vector3d p = T * p_body;
  if (!(p.z() > 1e-9)) return false;
  const double iz = 1.0 / p.z();
  r = Eigen::Vector2d(cam.fx * p.x() * iz + cam.cx, cam.fy * p.y() * iz + cam.cy) - uv;
  if (J) {
    // ∂π/∂p · ∂p/∂ξ, with ∂p/∂ξ = [I | −[p]×] for T ← exp(ξ^) T (eq. 8).
    Eigen::Matrix<double, 2, 3> dpi;
    dpi << cam.fx * iz, 0, -cam.fx * p.x() * iz * iz, 0, cam.fy * iz, -cam.fy * p.y() * iz * iz;
    J->leftCols<3>() = dpi;
    J->rightCols<3>() = -dpi * hat(p);
  }
  return true;
}

bool depth_residual(const Eigen::Isometry3d& T, const Eigen::Vector3d& p_body, double z_m, double scale, double& r,
                    Eigen::Matrix<double, 1, 6>* J) {
  const Eigen::Vector3d p = T * p_body;
  if (!(p.z() > 1e-9)) return false;
  r = (p.z() - z_m) * scale;
  // ∂z/∂ξ: the third row of [I | −[p]×] = (0, 0, 1, p_y, −p_x, 0).
  if (J) *J << 0, 0, scale, scale * p.y(), -scale * p.x(), 0;
  return true;
}

double AttitudeConstraint::chi2(const Eigen::Matrix3d& R) const {
  if (!active()) return 0;
  return (R * g_body - g_camera).squaredNorm() / (sigma_rad * sigma_rad);
}

void attitude_residual(const Eigen::Isometry3d& T, const AttitudeConstraint& a, Eigen::Vector3d& r,
                       Eigen::Matrix<double, 3, 6>* J) {
  const double scale = a.pixel_sigma_px / a.sigma_rad;
  const Eigen::Vector3d g = T.linear() * a.g_body;
  r = (g - a.g_camera) * scale;
  if (J) {
    // R ← exp(φ^) R moves R g by φ × R g = −[R g]× φ; ρ does not move it.
    J->leftCols<3>().setZero();
    J->rightCols<3>() = -scale * hat(g);
  }
}

Matrix6d PoseRefinement::covariance_for(double pixel_variance) const {
  const Matrix6d information = pixel_information / pixel_variance + constraint_information;
  const Matrix6d inverse = information.ldlt().solve(Matrix6d::Identity());
  if (pixel_bias_moment.isZero(0)) return inverse;
  // The blobs' own errors (bias_variance) through the estimator's gain
  // I⁻¹ Jᵢᵀ / σ²: I⁻¹ (Σ vᵢ JᵢᵀJᵢ / σ⁴) I⁻¹.
  const Matrix6d extra = inverse * (pixel_bias_moment / (pixel_variance * pixel_variance)) * inverse;
  return inverse + 0.5 * (extra + extra.transpose());
}

bool GaussNewtonOptions::validate(std::string* why) const {
  if (max_iterations < 1 || max_iterations > 1000) return invalid(why, "max_iterations: must be in 1..1000");
  if (!(step_tolerance >= 0) || !std::isfinite(step_tolerance)) return invalid(why, "step_tolerance: must be >= 0");
  if (!(huber_px >= 0) || !std::isfinite(huber_px)) return invalid(why, "huber_px: must be >= 0 px (0 = off)");
  if (!(depth_outlier_sigma >= 0) || !std::isfinite(depth_outlier_sigma)) {
    return invalid(why, "depth_outlier_sigma: must be >= 0 (0 = off)");
  }
  return true;
}

namespace {

// Throws InvalidArgument on options or constraints the fit cannot use.
void check_inputs(std::size_t n, const GaussNewtonOptions& o, const DepthConstraints& depth,
                  const AttitudeConstraint& attitude, std::span<const double> bias_variance) {
  if (!o.validate(nullptr)) {  // cheap on the hot path; the message only on failure
    std::string why;
    (void)o.validate(&why);  // false again: called only for the message
    throw InvalidArgument("gauss-newton options: " + why);
  }
  if (!depth.z_m.empty() && (depth.z_m.size() != n || depth.sigma_m.size() != n || !(depth.pixel_sigma_px > 0))) {
    throw InvalidArgument("gauss-newton depth constraints: need one depth and one sigma per point");
  }
  if (!bias_variance.empty() &&
      (bias_variance.size() != n ||
       !std::all_of(bias_variance.begin(), bias_variance.end(), [](double v) { return v >= 0 && std::isfinite(v); }))) {
    throw InvalidArgument("gauss-newton bias_variance: need one finite variance >= 0 per point");
  }
  if (attitude.active() &&
      (!std::isfinite(attitude.sigma_rad) || !(attitude.pixel_sigma_px > 0) || !attitude.g_camera.allFinite() ||
       !attitude.g_body.allFinite() || std::abs(attitude.g_camera.norm() - 1) > 1e-3 ||
       std::abs(attitude.g_body.norm() - 1) > 1e-3)) {
    throw InvalidArgument(
        "gauss-newton attitude constraint: need unit gravity vectors, finite sigma_rad and pixel_sigma_px > 0");
  }
}

// The fit's summary at its final pose T: reprojection RMS, covariances and
// the two parts of the information.
void finish_refinement(const PinholeCamera& cam, std::span<const Eigen::Vector3d> p_body,
                       std::span<const Eigen::Vector2d> uv, const Eigen::Isometry3d& T, const Matrix6d& H,
                       const Matrix6d& H_pixels, const Matrix6d& H_constraints, double sigma2,
                       std::span<const double> bias_variance, PoseRefinement& out) {
  out.T_camera_body = T;
  double sq = 0;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  out.pixel_bias_moment.setZero();
  for (std::size_t i = 0; i < p_body.size(); ++i) {
    reprojection_residual(cam, T, p_body[i], uv[i], r, bias_variance.empty() ? nullptr : &J);
    sq += r.squaredNorm();
    if (!bias_variance.empty() && bias_variance[i] > 0) {
      out.pixel_bias_moment.noalias() += bias_variance[i] * J.transpose() * J;
    }
  }
  out.rms_px = std::sqrt(sq / static_cast<double>(p_body.size()));
  out.unit_covariance = H.ldlt().solve(Matrix6d::Identity());
  out.noise_variance = sigma2;
  out.pixel_information = H_pixels;
  out.constraint_information = H_constraints;
  out.covariance = sigma2 * out.unit_covariance;
  if (!out.pixel_bias_moment.isZero(0)) {  // (H/σ²)⁻¹ (M/σ⁴) (H/σ²)⁻¹ = H⁻¹ M H⁻¹
    const Matrix6d extra = out.unit_covariance * out.pixel_bias_moment * out.unit_covariance;
    out.covariance += 0.5 * (extra + extra.transpose());
  }
}

}  // namespace

PoseRefinement refine_pose_gauss_newton(const PinholeCamera& cam, std::span<const Eigen::Vector3d> p_body,
                                        std::span<const Eigen::Vector2d> uv, const Eigen::Isometry3d& initial,
                                        const GaussNewtonOptions& o, const DepthConstraints& depth,
                                        const AttitudeConstraint& attitude, std::span<const double> bias_variance) {
  const std::size_t n = p_body.size();
  check_inputs(n, o, depth, attitude, bias_variance);
  PoseRefinement out;
  out.T_camera_body = initial;
  if (n < 3 || uv.size() != n) return out;
  const bool with_depth = !depth.z_m.empty();
  const bool with_attitude = attitude.active();
  std::size_t depth_count = 0;  // depth residuals in use
  Eigen::Isometry3d T = initial;
  // H_pixels: the reprojections' part of H; H_constraints: the depths' and
  // the attitude's, in their own σ (their pixel scale taken out).
  Matrix6d H, H_pixels, H_constraints;
  Vector6d g;
  Eigen::Vector3d ra;
  Eigen::Matrix<double, 3, 6> Ja;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  Eigen::Matrix<double, 1, 6> Jd;
  // Depths left out as outliers (GaussNewtonOptions::depth_outlier_sigma).
  std::array<std::size_t, kMaxDepthOutliers> dropped{};
  std::size_t n_dropped = 0;
  auto is_dropped = [&](std::size_t i) {
    return std::find(dropped.begin(), dropped.begin() + static_cast<std::ptrdiff_t>(n_dropped), i) !=
           dropped.begin() + static_cast<std::ptrdiff_t>(n_dropped);
  };
  auto accumulate = [&](const Eigen::Isometry3d& pose, double& cost, bool with_jacobian) {
    H.setZero();
    H_pixels.setZero();
    H_constraints.setZero();
    g.setZero();
    cost = 0;
    depth_count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!reprojection_residual(cam, pose, p_body[i], uv[i], r, with_jacobian ? &J : nullptr)) return false;
      const double e = r.norm();
      double w = 1.0;
      if (o.huber_px > 0 && e > o.huber_px) w = o.huber_px / e;  // IRLS weight of the Huber loss
      cost += w * r.squaredNorm();
      if (with_jacobian) {
        H.noalias() += w * J.transpose() * J;
        H_pixels.noalias() += w * J.transpose() * J;
        g.noalias() += w * J.transpose() * r;
      }
      if (!with_depth || !std::isfinite(depth.z_m[i]) || !(depth.sigma_m[i] > 0)) continue;
      double rd = 0;
      if (!depth_residual(pose, p_body[i], depth.z_m[i], depth.pixel_sigma_px / depth.sigma_m[i], rd,
                          with_jacobian ? &Jd : nullptr)) {
        return false;
      }
      if (is_dropped(i)) continue;
      ++depth_count;
      const double ed = std::abs(rd);
      const double wd = o.huber_px > 0 && ed > o.huber_px ? o.huber_px / ed : 1.0;
      cost += wd * rd * rd;
      if (with_jacobian) {
        H.noalias() += wd * Jd.transpose() * Jd;
        H_constraints.noalias() += (wd / (depth.pixel_sigma_px * depth.pixel_sigma_px)) * Jd.transpose() * Jd;
        g.noalias() += wd * Jd.transpose() * rd;
      }
    }
    if (with_attitude) {
      attitude_residual(pose, attitude, ra, with_jacobian ? &Ja : nullptr);
      cost += ra.squaredNorm();
      if (with_jacobian) {
        H.noalias() += Ja.transpose() * Ja;
        H_constraints.noalias() += (1.0 / (attitude.pixel_sigma_px * attitude.pixel_sigma_px)) * Ja.transpose() * Ja;
        g.noalias() += Ja.transpose() * ra;
      }
    }
    return true;
  };
  double cost = 0;
  // Gauss–Newton steps from T; false if the problem is degenerate.
  auto iterate = [&]() {
    out.status = RefineStatus::MaxIterations;
    for (int it = 0; it < o.max_iterations; ++it) {
      if (!accumulate(T, cost, true)) return false;
      const Eigen::LDLT<Matrix6d> ldlt(H);
      if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-12 * H.diagonal().maxCoeff()).all()) {
        return false;
      }
      const Vector6d dx = -ldlt.solve(g);
      T = se3_exp(dx) * T;
      ++out.iterations;
      if (dx.norm() < o.step_tolerance) {
        out.status = RefineStatus::Converged;
        break;
      }
    }
    return true;
  };
  if (!iterate()) {
    out.status = RefineStatus::Degenerate;
    return out;
  }
  // Outlying depths, worst first, each removal refitted from there. Judged
  // at the fit that still holds them by the studentized residual
  // r / (σ √(1 − h)), h = J H⁻¹ Jᵀ its leverage: a depth the fit leans on
  // pulls the fit toward itself, and its plain residual understates how far
  // off it is (Cook & Weisberg 1982, ch. 2).
  bool accumulated = false;  // H, g and cost hold T's (the last outlier check's)
  while (with_depth && o.depth_outlier_sigma > 0 && n_dropped < dropped.size()) {
    if (!accumulate(T, cost, true)) {
      out.status = RefineStatus::Degenerate;
      return out;
    }
    accumulated = true;
    const Eigen::LDLT<Matrix6d> info(H);
    double worst = o.depth_outlier_sigma;
    std::size_t arg = n;
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(depth.z_m[i]) || !(depth.sigma_m[i] > 0) || is_dropped(i)) continue;
      double rd = 0;
      if (!depth_residual(T, p_body[i], depth.z_m[i], depth.pixel_sigma_px / depth.sigma_m[i], rd, &Jd)) continue;
      const double leverage = (Jd * info.solve(Jd.transpose()))(0, 0);
      const double off = std::abs(rd) / (depth.pixel_sigma_px * std::sqrt(std::max(1 - leverage, 1e-3)));
      if (off > worst) {
        worst = off;
        arg = i;
      }
    }
    if (arg == n) break;
    dropped[n_dropped++] = arg;
    accumulated = false;
    if (!iterate()) {
      out.status = RefineStatus::Degenerate;
      return out;
    }
  }
  if (!accumulated && !accumulate(T, cost, true)) {
    out.status = RefineStatus::Degenerate;
    return out;
  }
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();  // shed rounding drift
  const double dof =
      2.0 * static_cast<double>(n) + static_cast<double>(depth_count) + (with_attitude ? 2.0 : 0.0) - 6.0;
  // H, H_pixels and H_constraints as of the last accumulate() (at T, with its Huber weights).
  finish_refinement(cam, p_body, uv, T, H, H_pixels, H_constraints, dof > 0 ? cost / dof : 0.0, bias_variance, out);
  out.degrees_of_freedom = std::max(dof, 0.0);
  return out;
}

}  // namespace touchdown::pose
