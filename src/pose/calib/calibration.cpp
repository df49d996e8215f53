#include "touchdown/pose/calib/calibration.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/epnp.hpp"
#include "touchdown/pose/se3.hpp"

namespace touchdown::pose {

bool CalibrationOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (max_iterations < 1) return fail("max_iterations: must be at least 1, got " + std::to_string(max_iterations));
  if (!std::isfinite(huber_px) || huber_px < 0) {
    return fail("huber_px: must be finite and >= 0 (0 = squared loss), got " + std::to_string(huber_px));
  }
  if (!std::isfinite(function_tolerance) || function_tolerance <= 0 || function_tolerance >= 1) {
    return fail("function_tolerance: must be in (0, 1), got " + std::to_string(function_tolerance));
  }
  return true;
}

namespace {

// Pose parameter block: Eigen quaternion coefficients (x, y, z, w) then the
// translation — one block per view so the Schur solver can eliminate the
// poses (each residual touches exactly one pose block).
using PoseBlock = std::array<double, 7>;
using PointBlock = std::array<double, 3>;
using PoseManifold = ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>>;

PoseBlock to_block(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  return {q.x(), q.y(), q.z(), q.w(), T.translation().x(), T.translation().y(), T.translation().z()};
}

Eigen::Isometry3d from_block(const PoseBlock& b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(b[3], b[0], b[1], b[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(b[4], b[5], b[6]);
  return T;
}

// Reprojection error [px] of one LED in one view: π(q p + t) − uv, the
// residual of Triggs et al. (2000) eq. (1) with the pinhole model.
struct ReprojectionError {
  double fx, fy, cx, cy, u, v;
  template <typename T>
  bool operator()(const T* pose, const T* led, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(pose);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(pose + 4);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(led);
    const Eigen::Matrix<T, 3, 1> pc = q * p + t;
    // Behind (or on) the camera plane: an invalid step, which Ceres rejects
    // and retries with a smaller trust region.
    if (!(pc.z() > T(1e-9))) return false;
    residual[0] = T(fx) * pc.x() / pc.z() + T(cx) - T(u);
    residual[1] = T(fy) * pc.y() / pc.z() + T(cy) - T(v);
    return true;
  }
};

// Scale gauge prior: weight · (RMS distance of the LEDs from their centroid /
// that of the initial constellation − 1). The data term is exactly invariant
// along the scale gauge orbit and this function varies monotonically along
// it, so the minimum of data + prior lies on the data term's minimum set
// where the prior is exactly zero: it picks the gauge, it does not bias the
// shape (Triggs et al. 2000, sec. 9.2.2 on gauge fixing by constraints).
struct ScaleGaugePrior {
  int num_leds;
  double rms_radius_initial;
  double weight;
  template <typename T>
  bool operator()(T const* const* leds, T* residual) const {
    Eigen::Matrix<T, 3, 1> c = Eigen::Matrix<T, 3, 1>::Zero();
    for (int i = 0; i < num_leds; ++i) c += Eigen::Map<const Eigen::Matrix<T, 3, 1>>(leds[i]);
    c /= T(num_leds);
    T s = T(0);
    for (int i = 0; i < num_leds; ++i) s += (Eigen::Map<const Eigen::Matrix<T, 3, 1>>(leds[i]) - c).squaredNorm();
    using std::sqrt;
    residual[0] = T(weight) * (sqrt(s / T(num_leds)) / T(rms_radius_initial) - T(1));
    return true;
  }
};

double rms_radius(const std::vector<PointBlock>& p) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& q : p) c += Eigen::Vector3d(q[0], q[1], q[2]);
  c /= static_cast<double>(p.size());
  double s = 0;
  for (const auto& q : p) s += (Eigen::Vector3d(q[0], q[1], q[2]) - c).squaredNorm();
  return std::sqrt(s / static_cast<double>(p.size()));
}

std::string view_key(std::size_t i) { return "views[" + std::to_string(i) + "]"; }

enum class Gauge {
  None,              // ≥ 2 known poses with distinct camera centres: metric, fixed
  ScaleAboutCentre,  // known poses share one camera centre: scale about it is free
  Similarity,        // no known pose: rotation, translation and scale are free
};

// Misuse (invalid options, camera or initial constellation, a bad
// observation, a known pose that is not rigid or puts an LED behind the
// camera): throws InvalidArgument naming the view and observation.
void check_calibration_input(const PinholeCamera& camera, const Constellation& initial,
                             std::span<const CalibrationView> views, const CalibrationOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("calibration options: " + why);
  if (!initial.validate(&why)) throw InvalidArgument("calibration: initial constellation: " + why);
  if (!(std::isfinite(camera.fx) && std::isfinite(camera.fy) && camera.fx > 0 && camera.fy > 0 &&
        std::isfinite(camera.cx) && std::isfinite(camera.cy))) {
    throw InvalidArgument("calibration: camera: fx, fy must be finite and > 0, cx, cy finite");
  }
  const std::size_t num_leds = initial.leds.size();
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& view = views[i];
    std::vector<bool> seen(num_leds, false);
    for (std::size_t j = 0; j < view.observations.size(); ++j) {
      const auto& o = view.observations[j];
      const std::string key = view_key(i) + ".observations[" + std::to_string(j) + "]";
      if (o.led < 0 || static_cast<std::size_t>(o.led) >= num_leds) {
        throw InvalidArgument("calibration: " + key + ".led: " + std::to_string(o.led) + " is out of range [0, " +
                              std::to_string(num_leds) + ")");
      }
      if (seen[static_cast<std::size_t>(o.led)]) {
        throw InvalidArgument("calibration: " + key + ".led: LED " + std::to_string(o.led) +
                              " is observed twice in one view");
      }
      seen[static_cast<std::size_t>(o.led)] = true;
      if (!o.uv_px.allFinite()) throw InvalidArgument("calibration: " + key + ".uv_px: not finite");
    }
    if (view.T_camera_body) {
      const auto& T = *view.T_camera_body;
      if (!T.matrix().allFinite() ||
          (T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
        throw InvalidArgument("calibration: " + view_key(i) + ".T_camera_body: not a finite rigid transform");
      }
      for (const auto& o : view.observations) {
        const double z = (T * initial.leds[static_cast<std::size_t>(o.led)].p_body).z();
        if (!(z > 0)) {
          throw InvalidArgument("calibration: " + view_key(i) + ": LED " + std::to_string(o.led) +
                                " of the initial constellation is behind the camera under the known pose (z = " +
                                std::to_string(z) + " m)");
        }
      }
    }
  }
}

// Why the views cannot determine every LED (an expected outcome, status
// InsufficientData); empty if they can.
std::string insufficient_views(const Constellation& initial, std::span<const CalibrationView> views) {
  const std::size_t num_leds = initial.leds.size();
  std::vector<int> views_per_led(num_leds, 0);
  int rich_views = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (const auto& o : views[i].observations) ++views_per_led[static_cast<std::size_t>(o.led)];
    if (views[i].observations.size() >= 4) ++rich_views;
    if (!views[i].T_camera_body && views[i].observations.size() < 4) {
      return view_key(i) + ": a view without a known pose needs at least 4 LEDs, has " +
             std::to_string(views[i].observations.size()) + " (give its pose or drop it)";
    }
  }
  for (std::size_t k = 0; k < num_leds; ++k) {
    if (views_per_led[k] < 2) {
      return "LED " + std::to_string(k) + " is seen in " + std::to_string(views_per_led[k]) +
             " view(s); every LED needs at least 2";
    }
  }
  if (rich_views < 2) {
    return "need at least 2 views with 4 or more LEDs, have " + std::to_string(rich_views);
  }
  return {};
}

// Initial poses: known ones as given, the others by EPnP + Gauss–Newton on
// the initial constellation. Returns why a view has no PnP solution (status
// InsufficientData); empty if every view has a pose.
std::string initial_poses(const PinholeCamera& camera, const Constellation& initial,
                          std::span<const CalibrationView> views, const CalibrationOptions& options,
                          std::vector<PoseBlock>& poses) {
  GaussNewtonOptions gn;
  gn.huber_px = options.huber_px;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].T_camera_body) {
      poses[i] = to_block(*views[i].T_camera_body);
      continue;
    }
    std::vector<Eigen::Vector3d> p;
    std::vector<Eigen::Vector2d> uv;
    for (const auto& o : views[i].observations) {
      p.push_back(initial.leds[static_cast<std::size_t>(o.led)].p_body);
      uv.push_back(o.uv_px);
    }
    const PoseRefinement pnp = solve_pnp(camera, p, uv, gn);
    if (!pnp.ok()) return view_key(i) + ": no PnP solution from the initial constellation";
    poses[i] = to_block(pnp.T_camera_body);
  }
  return {};
}

// Reprojection RMS [px] over every observation; `num_obs` gets their number.
double reprojection_rms(const PinholeCamera& camera, std::span<const CalibrationView> views,
                        const std::vector<PoseBlock>& poses, const std::vector<PointBlock>& leds,
                        std::size_t& num_obs) {
  double sq = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Eigen::Isometry3d T = from_block(poses[i]);
    for (const auto& o : views[i].observations) {
      const auto& q = leds[static_cast<std::size_t>(o.led)];
      sq += (camera.project(T * Eigen::Vector3d(q[0], q[1], q[2])) - o.uv_px).squaredNorm();
      ++n;
    }
  }
  num_obs = n;
  return n ? std::sqrt(sq / static_cast<double>(n)) : 0.0;
}

struct GaugeChoice {
  Gauge gauge = Gauge::Similarity;
  Eigen::Vector3d scale_centre = Eigen::Vector3d::Zero();  // centre of the free scale (ScaleAboutCentre)
};

// Gauge (see the header). Camera centres in the body frame: c = −Rᵀ t.
GaugeChoice choose_gauge(const Constellation& initial, std::span<const CalibrationView> views) {
  std::vector<Eigen::Vector3d> known_centres;
  for (const auto& v : views) {
    if (v.T_camera_body)
      known_centres.push_back(-(v.T_camera_body->linear().transpose() * v.T_camera_body->translation()));
  }
  Gauge gauge = Gauge::Similarity;
  Eigen::Vector3d scale_centre = Eigen::Vector3d::Zero();
  if (!known_centres.empty()) {
    double spread = 0, distance = 0;
    for (const auto& c : known_centres) {
      scale_centre += c;
      distance += (c - initial.centroid()).norm();
      for (const auto& d : known_centres) spread = std::max(spread, (c - d).norm());
    }
    scale_centre /= static_cast<double>(known_centres.size());
    distance /= static_cast<double>(known_centres.size());
    // A baseline under 1e-3 of the viewing distance fixes the scale too
    // weakly to rely on: treat the centres as one.
    gauge = spread > 1e-3 * distance ? Gauge::None : Gauge::ScaleAboutCentre;
  }
  return {gauge, scale_centre};
}

// The bundle adjustment's parameter blocks (known poses held constant) and
// one reprojection residual per observation.
void add_reprojection_residuals(ceres::Problem& problem, const PinholeCamera& camera,
                                std::span<const CalibrationView> views, const CalibrationOptions& options,
                                std::vector<PoseBlock>& poses, std::vector<PointBlock>& leds) {
  // Every observation has a residual block (the checks above guarantee at
  // least one), so the problem takes ownership of the loss; the manifold is
  // made only if some pose is free.
  ceres::LossFunction* loss = options.huber_px > 0 ? new ceres::HuberLoss(options.huber_px) : nullptr;
  ceres::Manifold* pose_manifold = nullptr;
  for (auto& q : leds) problem.AddParameterBlock(q.data(), 3);
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].T_camera_body) {
      problem.AddParameterBlock(poses[i].data(), 7);
      problem.SetParameterBlockConstant(poses[i].data());
    } else {
      if (!pose_manifold) pose_manifold = new PoseManifold();
      problem.AddParameterBlock(poses[i].data(), 7, pose_manifold);
    }
  }
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (const auto& o : views[i].observations) {
      auto* cost = new ceres::AutoDiffCostFunction<ReprojectionError, 2, 7, 3>(
          new ReprojectionError{camera.fx, camera.fy, camera.cx, camera.cy, o.uv_px.x(), o.uv_px.y()});
      problem.AddResidualBlock(cost, loss, poses[i].data(), leds[static_cast<std::size_t>(o.led)].data());
    }
  }
}

// Gauge fixing for conditioning (Triggs et al. 2000, sec. 9): without it
// the normal equations are singular along the gauge orbit and LM only
// converges thanks to its damping, slowly and with a meaningless
// covariance. Rotation and translation: hold the pose of the unknown view
// with the most LEDs at its PnP value — any pose is reachable along the
// orbit, so this costs nothing. Scale: the prior above. Returns the number
// of poses left free.
int fix_gauge(ceres::Problem& problem, const PinholeCamera& camera, std::span<const CalibrationView> views, Gauge gauge,
              std::vector<PoseBlock>& poses, std::vector<PointBlock>& leds) {
  const std::size_t num_leds = leds.size();
  int free_poses = 0;
  for (const auto& v : views) free_poses += v.T_camera_body ? 0 : 1;
  if (gauge == Gauge::Similarity) {
    std::size_t reference = 0;
    for (std::size_t i = 1; i < views.size(); ++i) {
      if (views[i].observations.size() > views[reference].observations.size()) reference = i;
    }
    problem.SetParameterBlockConstant(poses[reference].data());
    --free_poses;
  }
  const bool scale_prior = gauge != Gauge::None;
  if (scale_prior) {
    // Weight fx [px]: a 1 % scale change costs about what a 1 % change of a
    // 1 m depth does in one view; the weight only affects conditioning.
    auto* prior = new ceres::DynamicAutoDiffCostFunction<ScaleGaugePrior, 4>(
        new ScaleGaugePrior{static_cast<int>(num_leds), rms_radius(leds), camera.fx});
    std::vector<double*> blocks;
    for (auto& q : leds) {
      prior->AddParameterBlock(3);
      blocks.push_back(q.data());
    }
    prior->SetNumResiduals(1);
    problem.AddResidualBlock(prior, nullptr, blocks);
  }
  return free_poses;
}

ceres::Solver::Options solver_options(const CalibrationOptions& options, int free_poses, std::vector<PoseBlock>& poses,
                                      std::vector<PointBlock>& leds) {
  ceres::Solver::Options so;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = options.function_tolerance;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-14;
  so.num_threads = 1;  // deterministic
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  if (free_poses > 0) {
    // Eliminate the poses (each residual touches one) and solve the reduced
    // system over the ≤ 3·kMaxLeds LED coordinates (Triggs et al. sec. 6.1).
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (auto& b : poses) ordering->AddElementToGroup(b.data(), 0);
    for (auto& q : leds) ordering->AddElementToGroup(q.data(), 1);
    so.linear_solver_ordering = ordering;
    so.linear_solver_type = ceres::DENSE_SCHUR;
  } else {
    so.linear_solver_type = ceres::DENSE_QR;
  }
  return so;
}

using LedCovariance = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Where the gauge is free, the covariance of the solve depends on the
// gauge held during it (the reference pose's own error shows up in every
// LED). The result is returned aligned (least squares) to the initial LEDs,
// which to first order removes its components along the gauge directions
// G: its covariance is P C P with P the orthogonal projector off span(G)
// (Triggs et al. 2000, sec. 9).
void project_off_gauge(LedCovariance& C, const std::vector<PointBlock>& leds, Gauge gauge,
                       const Eigen::Vector3d& scale_centre) {
  const std::size_t num_leds = leds.size();
  const auto n3 = static_cast<Eigen::Index>(3 * num_leds);
  const Eigen::Index cols = gauge == Gauge::Similarity ? 7 : 1;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n3, cols);
  for (std::size_t k = 0; k < num_leds; ++k) {
    const auto row = static_cast<Eigen::Index>(3 * k);
    const Eigen::Vector3d p(leds[k][0], leds[k][1], leds[k][2]);
    if (gauge == Gauge::Similarity) {
      G.block<3, 3>(row, 0).setIdentity();  // translation
      G.block<3, 3>(row, 3) = -hat(p);      // rotation: ω × p
      G.block<3, 1>(row, 6) = p;            // scale about the origin
    } else {
      G.block<3, 1>(row, 0) = p - scale_centre;  // scale about the camera centre
    }
  }
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(n3, n3) - G * (G.transpose() * G).ldlt().solve(G.transpose());
  C = P * C * P.transpose();
}

// Per-LED standard deviation from the covariance of the gauge-fixed
// problem, scaled by the a-posteriori variance factor 2·cost / dof; empty
// if the solution is unusable, there is no redundancy or Ceres cannot
// compute the covariance.
std::vector<double> led_sigmas(ceres::Problem& problem, const ceres::Solver::Summary& summary,
                               const std::vector<PointBlock>& leds, std::size_t num_obs, int free_poses,
                               bool scale_prior, Gauge gauge, const Eigen::Vector3d& scale_centre) {
  const std::size_t num_leds = leds.size();
  const int num_params = 3 * static_cast<int>(num_leds) + 6 * free_poses;
  const int dof = 2 * static_cast<int>(num_obs) - num_params + (scale_prior ? 1 : 0);
  std::vector<double> sigma;
  if (summary.IsSolutionUsable() && dof > 0) {
    ceres::Covariance::Options co;
    co.num_threads = 1;
    ceres::Covariance covariance(co);
    std::vector<const double*> blocks;
    for (const auto& q : leds) blocks.push_back(q.data());
    std::vector<std::pair<const double*, const double*>> pairs;
    for (std::size_t i = 0; i < num_leds; ++i) {
      for (std::size_t j = i; j < num_leds; ++j) pairs.emplace_back(blocks[i], blocks[j]);
    }
    const auto n3 = static_cast<Eigen::Index>(3 * num_leds);
    LedCovariance C(n3, n3);
    if (covariance.Compute(pairs, &problem) && covariance.GetCovarianceMatrix(blocks, C.data())) {
      C *= 2.0 * summary.final_cost / dof;
      if (gauge != Gauge::None) project_off_gauge(C, leds, gauge, scale_centre);
      for (std::size_t k = 0; k < num_leds; ++k) {
        const auto row = static_cast<Eigen::Index>(3 * k);
        sigma.push_back(std::sqrt(std::max(0.0, C.block<3, 3>(row, row).trace())));
      }
    }
  }
  return sigma;
}

// Back to the gauge of the initial constellation: the member of the
// solution family closest to the initial LEDs. A body-frame similarity
// p' = s R p + t keeps every image if each pose becomes
// R_c' = R_c Rᵀ, t_c' = s t_c − R_c Rᵀ t (the camera frame scales by s).
void align_to_initial_gauge(const Constellation& initial, std::span<const CalibrationView> views, Gauge gauge,
                            const Eigen::Vector3d& scale_centre, std::vector<PointBlock>& leds,
                            std::vector<PoseBlock>& poses, std::vector<double>& sigma) {
  const std::size_t num_leds = leds.size();
  double s = 1;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  if (gauge == Gauge::Similarity) {
    Eigen::Matrix3Xd src(3, num_leds), dst(3, num_leds);
    for (std::size_t k = 0; k < num_leds; ++k) {
      const auto col = static_cast<Eigen::Index>(k);
      src.col(col) = Eigen::Vector3d(leds[k][0], leds[k][1], leds[k][2]);
      dst.col(col) = initial.leds[k].p_body;
    }
    // Umeyama (1991): least-squares similarity, with scale.
    const Eigen::Matrix4d S = Eigen::umeyama(src, dst, true);
    s = S.block<3, 1>(0, 0).norm();
    R = S.block<3, 3>(0, 0) / s;
    t = S.block<3, 1>(0, 3);
  } else if (gauge == Gauge::ScaleAboutCentre) {
    // p' = s (p − c) + c with the least-squares s.
    double num = 0, den = 0;
    for (std::size_t k = 0; k < num_leds; ++k) {
      const Eigen::Vector3d d = Eigen::Vector3d(leds[k][0], leds[k][1], leds[k][2]) - scale_centre;
      num += d.dot(initial.leds[k].p_body - scale_centre);
      den += d.squaredNorm();
    }
    if (den > 0 && num > 0) s = num / den;
    t = (1 - s) * scale_centre;
  }
  for (auto& q : leds) {
    const Eigen::Vector3d p = s * R * Eigen::Vector3d(q[0], q[1], q[2]) + t;
    q = {p.x(), p.y(), p.z()};
  }
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].T_camera_body) continue;  // known: unchanged (the gauge keeps it)
    Eigen::Isometry3d T = from_block(poses[i]);
    const Eigen::Matrix3d Rc = T.linear() * R.transpose();
    T.translation() = s * T.translation() - Rc * t;
    T.linear() = Rc;
    poses[i] = to_block(T);
  }
  for (auto& x : sigma) x *= s;
}

// Status and message from the solver's termination, the usability of its
// solution and the validity of the calibrated constellation.
void set_status(CalibrationResult& out, const ceres::Solver::Summary& summary, const CalibrationOptions& options,
                Gauge gauge, const Constellation& initial) {
  std::string why;
  switch (summary.termination_type) {
    case ceres::CONVERGENCE:
      out.status = CalibrationStatus::Converged;
      out.message = "converged after " + std::to_string(out.iterations) + " iterations: reprojection RMS " +
                    std::to_string(out.initial_rms_px) + " px -> " + std::to_string(out.final_rms_px) + " px";
      break;
    case ceres::NO_CONVERGENCE:
      out.status = CalibrationStatus::NoConvergence;
      out.message =
          "no convergence within max_iterations = " + std::to_string(options.max_iterations) + ": " + summary.message;
      break;
    default:
      out.status = CalibrationStatus::NoConvergence;
      out.message = "solver failed: " + summary.message;
      break;
  }
  if (!summary.IsSolutionUsable()) {
    out.constellation = initial;
  } else if (!out.constellation.validate(&why)) {
    out.status = CalibrationStatus::NoConvergence;
    out.message = "the calibrated constellation is degenerate: " + why;
  }
  if (gauge != Gauge::None) {
    out.message += gauge == Gauge::Similarity
                       ? " (no known pose: scale, orientation and origin taken from the initial constellation)"
                       : " (known poses share one camera centre: scale taken from the initial constellation)";
  }
}

}  // namespace

CalibrationResult calibrate_constellation(const PinholeCamera& camera, const Constellation& initial,
                                          std::span<const CalibrationView> views, const CalibrationOptions& options) {
  // --- misuse: throw ---
  check_calibration_input(camera, initial, views, options);
  const std::size_t num_leds = initial.leds.size();

  CalibrationResult out;
  out.constellation = initial;
  auto insufficient = [&](const std::string& m) {
    out.status = CalibrationStatus::InsufficientData;
    out.message = m;
    return out;
  };

  // --- expected outcomes: status InsufficientData ---
  if (const std::string m = insufficient_views(initial, views); !m.empty()) return insufficient(m);
  std::vector<PoseBlock> poses(views.size());
  if (const std::string m = initial_poses(camera, initial, views, options, poses); !m.empty()) return insufficient(m);
  std::vector<PointBlock> leds(num_leds);
  for (std::size_t k = 0; k < num_leds; ++k) {
    const auto& p = initial.leds[k].p_body;
    leds[k] = {p.x(), p.y(), p.z()};
  }

  std::size_t num_obs = 0;
  out.initial_rms_px = reprojection_rms(camera, views, poses, leds, num_obs);
  const auto [gauge, scale_centre] = choose_gauge(initial, views);

  // --- the bundle adjustment problem ---
  ceres::Problem::Options po;  // the problem owns cost, loss and manifold objects
  ceres::Problem problem(po);
  add_reprojection_residuals(problem, camera, views, options, poses, leds);
  const int free_poses = fix_gauge(problem, camera, views, gauge, poses, leds);
  const bool scale_prior = gauge != Gauge::None;

  ceres::Solver::Summary summary;
  ceres::Solve(solver_options(options, free_poses, poses, leds), &problem, &summary);
  out.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;

  std::vector<double> sigma = led_sigmas(problem, summary, leds, num_obs, free_poses, scale_prior, gauge, scale_centre);
  align_to_initial_gauge(initial, views, gauge, scale_centre, leds, poses, sigma);

  out.final_rms_px = reprojection_rms(camera, views, poses, leds, num_obs);
  for (std::size_t k = 0; k < num_leds; ++k) out.constellation.leds[k].p_body = {leds[k][0], leds[k][1], leds[k][2]};
  out.T_camera_body.reserve(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    out.T_camera_body.push_back(views[i].T_camera_body ? *views[i].T_camera_body : from_block(poses[i]));
  }
  out.led_sigma_m = std::move(sigma);
  set_status(out, summary, options, gauge, initial);
  return out;
}

}  // namespace touchdown::pose
