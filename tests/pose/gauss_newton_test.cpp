#include "touchdown/pose/gauss_newton.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"

using namespace touchdown::pose_test;

TEST(GaussNewton, JacobianMatchesFiniteDifferences) {
  touchdown::Rng rng(1);
  for (int k = 0; k < 50; ++k) {
    const auto T = random_pose(rng);
    const double pz = rng.uniform(-0.1, 0.1), py = rng.uniform(-0.2, 0.2);  // drawn z first, as recorded
    const Eigen::Vector3d p(rng.uniform(-0.2, 0.2), py, pz);
    const double v = rng.uniform(0, 480);
    const Eigen::Vector2d uv(rng.uniform(0, 848), v);
    Eigen::Vector2d r;
    Eigen::Matrix<double, 2, 6> J;
    ASSERT_TRUE(tp::reprojection_residual(kCamera, T, p, uv, r, &J));
    for (int i = 0; i < 6; ++i) {
      tp::Vector6d d = tp::Vector6d::Zero();
      d[i] = 1e-6;
      Eigen::Vector2d rp, rm;
      tp::reprojection_residual(kCamera, tp::se3_exp(d) * T, p, uv, rp, nullptr);
      tp::reprojection_residual(kCamera, tp::se3_exp(-d) * T, p, uv, rm, nullptr);
      const Eigen::Vector2d fd = (rp - rm) / 2e-6;
      EXPECT_LT((fd - J.col(i)).norm(), 1e-5 * (1 + fd.norm())) << "column " << i;
    }
  }
}

TEST(GaussNewton, NoiselessPointsRecoverThePoseForEveryConstellationShape) {
  touchdown::Rng rng(2);
  for (Shape shape : {Shape::NonPlanar, Shape::Planar, Shape::QuasiPlanar}) {
    for (int k = 0; k < 20; ++k) {
      const auto p = constellation(shape, rng);
      const auto T = random_pose(rng);
      const auto uv = observe(T, p, rng, 0.0);
      const auto r = tp::refine_pose_gauss_newton(kCamera, p, uv, perturb(T, rng));
      ASSERT_EQ(r.status, tp::RefineStatus::Converged) << static_cast<int>(shape) << " " << k;
      EXPECT_LT(r.rms_px, 1e-8);
      EXPECT_LT((r.T_camera_body.translation() - T.translation()).norm(), 1e-9);
      EXPECT_LT(tp::se3_log(r.T_camera_body * T.inverse()).tail<3>().norm(), 1e-9);
    }
  }
}

TEST(GaussNewton, AgreesWithOpenCvIterativeOnNoisyData) {
  touchdown::Rng rng(4);
  const cv::Matx33d K(kCamera.fx, 0, kCamera.cx, 0, kCamera.fy, kCamera.cy, 0, 0, 1);
  for (int k = 0; k < 30; ++k) {
    const auto p = constellation(Shape::NonPlanar, rng, 8);
    const auto T = random_pose(rng);
    const auto uv = observe(T, p, rng, 0.5);
    const auto init = perturb(T, rng);
    const auto ours = tp::refine_pose_gauss_newton(kCamera, p, uv, init);
    ASSERT_TRUE(ours.ok());
    // OpenCV's Levenberg–Marquardt (SOLVEPNP_ITERATIVE) from the same start.
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (std::size_t i = 0; i < p.size(); ++i) {
      obj.emplace_back(p[i].x(), p[i].y(), p[i].z());
      img.emplace_back(uv[i].x(), uv[i].y());
    }
    cv::Mat R0, rvec, tvec;
    cv::eigen2cv(Eigen::Matrix3d(init.linear()), R0);
    cv::Rodrigues(R0, rvec);
    tvec = (cv::Mat_<double>(3, 1) << init.translation().x(), init.translation().y(), init.translation().z());
    ASSERT_TRUE(cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE));
    cv::Mat Rcv;
    cv::Rodrigues(rvec, Rcv);
    Eigen::Matrix3d R;
    cv::cv2eigen(Rcv, R);
    Eigen::Isometry3d Tcv = Eigen::Isometry3d::Identity();
    Tcv.linear() = R;
    Tcv.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    EXPECT_LT((ours.T_camera_body.translation() - Tcv.translation()).norm(), 1e-6) << k;
    EXPECT_LT(tp::se3_log(ours.T_camera_body * Tcv.inverse()).tail<3>().norm(), 1e-6) << k;
    // The reported covariance is that of a real estimate: positive definite.
    EXPECT_GT(ours.covariance.ldlt().vectorD().minCoeff(), 0);
  }
}

TEST(GaussNewton, HuberLossResistsAnOutlier) {
  touchdown::Rng rng(5);
  const auto p = constellation(Shape::NonPlanar, rng, 8);
  const auto T = random_pose(rng);
  auto uv = observe(T, p, rng, 0.3);
  uv[3] += Eigen::Vector2d(40, -25);  // a wrong correspondence
  tp::GaussNewtonOptions robust;
  robust.huber_px = 2.0;
  robust.max_iterations = 50;
  const auto plain = tp::refine_pose_gauss_newton(kCamera, p, uv, perturb(T, rng));
  const auto huber = tp::refine_pose_gauss_newton(kCamera, p, uv, perturb(T, rng), robust);
  ASSERT_TRUE(plain.ok());
  ASSERT_TRUE(huber.ok());
  EXPECT_LT((huber.T_camera_body.translation() - T.translation()).norm(),
            0.5 * (plain.T_camera_body.translation() - T.translation()).norm());
}

TEST(GaussNewton, DegenerateInputIsAStatus) {
  const std::vector<Eigen::Vector3d> two{{0, 0, 0}, {0.1, 0, 0}};
  const std::vector<Eigen::Vector2d> uv{{424, 240}, {480, 240}};
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().z() = 1;
  EXPECT_EQ(tp::refine_pose_gauss_newton(kCamera, two, uv, T).status, tp::RefineStatus::Degenerate);
  // Behind the camera.
  const std::vector<Eigen::Vector3d> p{{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0.1, 0.1, 0.05}};
  const std::vector<Eigen::Vector2d> uv4{{424, 240}, {480, 240}, {424, 300}, {470, 290}};
  T.translation().z() = -1;
  EXPECT_EQ(tp::refine_pose_gauss_newton(kCamera, p, uv4, T).status, tp::RefineStatus::Degenerate);
}

TEST(GaussNewtonOptions, ValidateNamesTheFieldAndRefineRefusesBadOptions) {
  using O = tp::GaussNewtonOptions;
  touchdown::test::expect_validate_names_fields<O>({
      {"max_iterations:", [](O& o) { o.max_iterations = 0; }},
      {"huber_px:", [](O& o) { o.huber_px = -1; }},
      {"depth_outlier_sigma:", [](O& o) { o.depth_outlier_sigma = -1; }},
  });
  O o;
  o.huber_px = -1;
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0.1, 0.1, 0.02}};
  const std::vector<Eigen::Vector2d> uv(4, Eigen::Vector2d(320, 240));
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, Eigen::Isometry3d::Identity(), o),
               touchdown::InvalidArgument);
}

// ---- measured depths (DepthConstraints) ------------------------------------------------

TEST(GaussNewton, DepthJacobianMatchesFiniteDifferences) {
  touchdown::Rng rng(11);
  for (int k = 0; k < 50; ++k) {
    const auto T = random_pose(rng);
    const double pz = rng.uniform(-0.1, 0.1), py = rng.uniform(-0.2, 0.2);  // drawn z first, as recorded
    const Eigen::Vector3d p(rng.uniform(-0.2, 0.2), py, pz);
    const double z = rng.uniform(0.5, 3), scale = rng.uniform(1, 100);
    double r = 0;
    Eigen::Matrix<double, 1, 6> J;
    ASSERT_TRUE(tp::depth_residual(T, p, z, scale, r, &J));
    EXPECT_NEAR(r, ((T * p).z() - z) * scale, 1e-12);
    for (int i = 0; i < 6; ++i) {
      tp::Vector6d d = tp::Vector6d::Zero();
      d[i] = 1e-6;
      double rp = 0, rm = 0;
      tp::depth_residual(tp::se3_exp(d) * T, p, z, scale, rp, nullptr);
      tp::depth_residual(tp::se3_exp(-d) * T, p, z, scale, rm, nullptr);
      EXPECT_NEAR((rp - rm) / 2e-6, J(0, i), 1e-5 * (1 + std::abs(J(0, i)))) << "column " << i;
    }
  }
}

// Oracle: exact depths pin a quasi-planar board's pose that noisy pixels
// alone leave loose: the fused fit is closer to the truth and its
// covariance smaller, on average over many draws.
TEST(GaussNewton, MeasuredDepthsTightenAQuasiPlanarFit) {
  touchdown::Rng rng(12);
  double err_pixels = 0, err_fused = 0, sigma_pixels = 0, sigma_fused = 0;
  for (int k = 0; k < 100; ++k) {
    const auto p = constellation(Shape::QuasiPlanar, rng);
    const auto T = random_pose(rng);
    const auto uv = observe(T, p, rng, 0.5);
    std::vector<double> z, sigma;
    for (const auto& q : p) z.push_back((T * q).z() + 0.001 * rng.normal()), sigma.push_back(0.001);
    const auto init = perturb(T, rng);
    const auto plain = tp::refine_pose_gauss_newton(kCamera, p, uv, init);
    const auto fused = tp::refine_pose_gauss_newton(kCamera, p, uv, init, {}, {z, sigma, 0.5});
    ASSERT_TRUE(plain.ok() && fused.ok());
    auto angle = [&](const Eigen::Isometry3d& A) {
      return Eigen::AngleAxisd(A.linear().transpose() * T.linear()).angle();
    };
    err_pixels += angle(plain.T_camera_body) + (plain.T_camera_body.translation() - T.translation()).norm();
    err_fused += angle(fused.T_camera_body) + (fused.T_camera_body.translation() - T.translation()).norm();
    sigma_pixels += plain.unit_covariance.trace();
    sigma_fused += fused.unit_covariance.trace();
    // The reported RMS is the reprojection's only.
    double sq = 0;
    for (std::size_t i = 0; i < p.size(); ++i)
      sq += (kCamera.project(fused.T_camera_body * p[i]) - uv[i]).squaredNorm();
    EXPECT_NEAR(fused.rms_px, std::sqrt(sq / static_cast<double>(p.size())), 1e-9);
  }
  EXPECT_LT(err_fused, 0.5 * err_pixels);
  EXPECT_LT(sigma_fused, 0.5 * sigma_pixels);
}

// A depth far off the pose (the camera saw a housing in front of the LED)
// is left out: the fit equals the one without that depth, and its noise
// estimate stays the pixels'; with the truncation off (0) the depth pulls
// the fit and inflates the noise estimate.
TEST(GaussNewton, DepthFarOffThePoseIsLeftOut) {
  touchdown::Rng rng(14);
  for (int k = 0; k < 20; ++k) {
    const auto p = constellation(Shape::QuasiPlanar, rng);
    const auto T = random_pose(rng);
    const auto uv = observe(T, p, rng, 0.2);
    std::vector<double> z, sigma;
    for (const auto& q : p) z.push_back((T * q).z() + 0.001 * rng.normal()), sigma.push_back(0.001);
    std::vector<double> without = z;
    z[0] -= 0.03;  // 30 sigma nearer
    without[0] = std::nan("");
    const auto init = perturb(T, rng);
    const auto robust = tp::refine_pose_gauss_newton(kCamera, p, uv, init, {}, {z, sigma, 0.2});
    const auto reference = tp::refine_pose_gauss_newton(kCamera, p, uv, init, {}, {without, sigma, 0.2});
    tp::GaussNewtonOptions all;
    all.depth_outlier_sigma = 0;
    const auto pulled = tp::refine_pose_gauss_newton(kCamera, p, uv, init, all, {z, sigma, 0.2});
    ASSERT_TRUE(robust.ok() && reference.ok() && pulled.ok()) << k;
    EXPECT_LT((robust.T_camera_body.translation() - reference.T_camera_body.translation()).norm(), 1e-9) << k;
    EXPECT_LT(Eigen::AngleAxisd(robust.T_camera_body.linear().transpose() * reference.T_camera_body.linear()).angle(),
              1e-9)
        << k;
    EXPECT_NEAR(robust.noise_variance, reference.noise_variance, 1e-9) << k;
    EXPECT_GT(pulled.noise_variance, 10 * robust.noise_variance) << k;
  }
}

TEST(GaussNewton, DepthsNotOnePerPointThrow) {
  touchdown::Rng rng(13);
  const auto p = constellation(Shape::NonPlanar, rng);
  const auto T = random_pose(rng);
  const auto uv = observe(T, p, rng, 0.0);
  const std::vector<double> z(p.size() - 1, 1.0), sigma(p.size() - 1, 0.01);
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {z, sigma, 0.2}), touchdown::InvalidArgument);
  // NaN depths are "none": the same as no depths at all.
  const std::vector<double> none(p.size(), std::nan("")), ones(p.size(), 0.01);
  const auto a = tp::refine_pose_gauss_newton(kCamera, p, uv, perturb(T, rng));
  const auto b = tp::refine_pose_gauss_newton(kCamera, p, uv, a.T_camera_body, {}, {none, ones, 0.2});
  EXPECT_LT((b.T_camera_body.translation() - a.T_camera_body.translation()).norm(), 1e-9);
  EXPECT_NEAR(b.noise_variance, a.noise_variance, 1e-12);
}

// ---- the attitude prior (issue 33, item 3) ----------------------------------

namespace {

// A unit vector turned by a random rotation of `sigma` [rad] per axis: how
// an IMU's gravity direction is off.
Eigen::Vector3d noisy_direction(const Eigen::Vector3d& v, double sigma, touchdown::Rng& rng) {
  const Eigen::Vector3d a = normal_vector3(rng) * sigma;
  return (a.norm() > 0 ? Eigen::AngleAxisd(a.norm(), a.normalized()) * v : v).normalized();
}

}  // namespace

TEST(GaussNewton, AttitudeJacobianMatchesFiniteDifferences) {
  touchdown::Rng rng(31);
  for (int k = 0; k < 50; ++k) {
    const auto T = random_pose(rng);
    tp::AttitudeConstraint a;
    a.g_camera = normal_vector3(rng).normalized();
    a.g_body = normal_vector3(rng).normalized();
    a.sigma_rad = rng.uniform(0.005, 0.1);
    a.pixel_sigma_px = rng.uniform(0.05, 1.0);
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, 6> J;
    tp::attitude_residual(T, a, r, &J);
    for (int i = 0; i < 6; ++i) {
      tp::Vector6d d = tp::Vector6d::Zero();
      d[i] = 1e-6;
      Eigen::Vector3d rp, rm;
      tp::attitude_residual(tp::se3_exp(d) * T, a, rp, nullptr);
      tp::attitude_residual(tp::se3_exp(-d) * T, a, rm, nullptr);
      const Eigen::Vector3d fd = (rp - rm) / 2e-6;
      EXPECT_LT((fd - J.col(i)).norm(), 1e-5 * (1 + fd.norm())) << "column " << i;
    }
    // χ² is the residual in units of its σ.
    EXPECT_NEAR(a.chi2(T.linear()), (r / a.pixel_sigma_px).squaredNorm(), 1e-9 * (1 + r.squaredNorm()));
  }
}

// The covariance a fit with the attitude prior reports is the truth: over
// many draws of pixel noise and of both IMUs' noise, the normalised
// estimation error squared of the 6-D twist averages its 6 degrees of
// freedom (Bar-Shalom et al. 2001, §5.4: NEES), and the prior shrinks the
// rotation's error where the image leaves it loose. Oracle: the simulated
// noise, not the code's own figures.
TEST(GaussNewton, AttitudePriorCovarianceIsTrueByNees) {
  touchdown::Rng rng(32);
  const double sigma_px = 0.5, sigma_imu = 0.0175;  // 1° per IMU
  const int trials = 400;
  double nees_prior = 0, nees_plain = 0, tilt_prior = 0, tilt_plain = 0;
  const auto p = constellation(Shape::QuasiPlanar, rng, 6);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  T.translation() << 0.1, -0.05, 2.5;
  const Eigen::Vector3d g_camera = Eigen::Vector3d(0, 0.94, -0.34).normalized();
  const Eigen::Vector3d g_body = T.linear().transpose() * g_camera;
  for (int k = 0; k < trials; ++k) {
    const auto uv = observe(T, p, rng, sigma_px);
    tp::AttitudeConstraint a;
    a.g_camera = noisy_direction(g_camera, sigma_imu, rng);
    a.g_body = noisy_direction(g_body, sigma_imu, rng);
    a.sigma_rad = std::sqrt(2.0) * sigma_imu;
    a.pixel_sigma_px = sigma_px;  // the residuals weighed by their true noise: the fit is the MLE
    const auto with = tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, a);
    const auto without = tp::refine_pose_gauss_newton(kCamera, p, uv, T);
    ASSERT_TRUE(with.ok() && without.ok()) << k;
    const tp::Vector6d e_with = tp::se3_log(T * with.T_camera_body.inverse());
    const tp::Vector6d e_without = tp::se3_log(T * without.T_camera_body.inverse());
    nees_prior += e_with.dot(with.covariance_for(sigma_px * sigma_px).ldlt().solve(e_with));
    nees_plain += e_without.dot(without.covariance_for(sigma_px * sigma_px).ldlt().solve(e_without));
    // The error of the rotation about a horizontal axis (what gravity fixes).
    const Eigen::Vector3d phi = e_with.tail<3>(), phi0 = e_without.tail<3>();
    tilt_prior += (phi - phi.dot(g_camera) * g_camera).squaredNorm();
    tilt_plain += (phi0 - phi0.dot(g_camera) * g_camera).squaredNorm();
  }
  nees_prior /= trials;
  nees_plain /= trials;
  // The mean of 400 χ²(6) has σ = √(12/400) ≈ 0.17: [5, 7] is ±6σ.
  EXPECT_GT(nees_prior, 5.0);
  EXPECT_LT(nees_prior, 7.0);
  EXPECT_GT(nees_plain, 5.0);
  EXPECT_LT(nees_plain, 7.0);
  EXPECT_LT(tilt_prior, 0.5 * tilt_plain);  // the prior pins the tilt
  // Without prior and at the assumed noise, covariance_for is the old σ²(JᵀJ)⁻¹.
  const auto uv = observe(T, p, rng, sigma_px);
  const auto plain = tp::refine_pose_gauss_newton(kCamera, p, uv, T);
  EXPECT_LT((plain.covariance_for(0.3) - 0.3 * plain.unit_covariance).norm(), 1e-9 * plain.unit_covariance.norm());
}

// One blob with an error of its own (a neighbour's glow pulling its
// centre; CorrespondenceOptions::crowded_bias_px): bias_variance leaves the
// fit as it is and carries that error into the covariance. Oracle: the
// NEES of 400 fits with the point's extra noise drawn as stated is a
// χ²(6) mean; without it the covariance is far too small.
TEST(GaussNewton, BiasVarianceMakesTheCovarianceTrueForOneNoisyPoint) {
  touchdown::Rng rng(34);
  const double sigma_px = 0.2, sigma_bias = 1.0;
  const int trials = 400;
  const auto p = constellation(Shape::NonPlanar, rng, 6);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -1, 0.5).normalized()).toRotationMatrix();
  T.translation() << -0.05, 0.1, 1.8;
  std::vector<double> bias(p.size(), 0.0);
  bias[2] = sigma_bias * sigma_bias;
  double nees_bias = 0, nees_plain = 0;
  for (int k = 0; k < trials; ++k) {
    auto uv = observe(T, p, rng, sigma_px);
    uv[2] += normal_vector2(rng) * sigma_bias;
    const auto with = tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, {}, bias);
    const auto without = tp::refine_pose_gauss_newton(kCamera, p, uv, T);
    ASSERT_TRUE(with.ok() && without.ok()) << k;
    // The estimate is the plain least-squares one: only the covariance changes.
    ASSERT_LT((with.T_camera_body.matrix() - without.T_camera_body.matrix()).norm(), 1e-12) << k;
    const tp::Vector6d e = tp::se3_log(T * with.T_camera_body.inverse());
    nees_bias += e.dot(with.covariance_for(sigma_px * sigma_px).ldlt().solve(e));
    nees_plain += e.dot(without.covariance_for(sigma_px * sigma_px).ldlt().solve(e));
    if (k == 0) {  // .covariance (at the fit's own noise estimate) carries the bias term too
      const tp::Matrix6d expected = with.noise_variance * with.unit_covariance +
                                    with.unit_covariance * with.pixel_bias_moment * with.unit_covariance;
      EXPECT_LT((with.covariance - expected).norm(), 1e-9 * expected.norm());
    }
  }
  nees_bias /= trials;
  nees_plain /= trials;
  EXPECT_GT(nees_bias, 5.0);  // 400 χ²(6): σ of the mean ≈ 0.17
  EXPECT_LT(nees_bias, 7.0);
  EXPECT_GT(nees_plain, 12.0) << nees_bias;  // the plain covariance hides the noisy point
}

TEST(GaussNewton, BadBiasVarianceIsRejected) {
  touchdown::Rng rng(35);
  const auto p = constellation(Shape::NonPlanar, rng, 6);
  const auto T = random_pose(rng);
  const auto uv = observe(T, p, rng, 0.1);
  const std::vector<double> short_list(p.size() - 1, 0.0);
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, {}, short_list), touchdown::InvalidArgument);
  std::vector<double> negative(p.size(), 0.0);
  negative[1] = -0.1;
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, {}, negative), touchdown::InvalidArgument);
  negative[1] = std::nan("");
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, {}, negative), touchdown::InvalidArgument);
}

TEST(GaussNewton, BadAttitudeConstraintIsRejected) {
  touchdown::Rng rng(33);
  const auto p = constellation(Shape::NonPlanar, rng, 6);
  const auto T = random_pose(rng);
  const auto uv = observe(T, p, rng, 0.1);
  tp::AttitudeConstraint a;
  a.g_camera = Eigen::Vector3d(0, 2, 0);  // not a unit vector
  a.g_body = Eigen::Vector3d::UnitZ();
  a.sigma_rad = 0.02;
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, a), touchdown::InvalidArgument);
  a.g_camera = Eigen::Vector3d(std::nan(""), 0, 0);
  EXPECT_THROW(tp::refine_pose_gauss_newton(kCamera, p, uv, T, {}, {}, a), touchdown::InvalidArgument);
}
