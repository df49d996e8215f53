#include "touchdown/pose/epnp.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "pose/pose_test_util.hpp"
#include "test_util.hpp"
#include "touchdown/core/random.hpp"

using namespace touchdown::pose_test;

namespace {

using touchdown::test::rotation_error;

// OpenCV's solvePnP on the same data (undistorted pixels, no distortion).
Eigen::Isometry3d opencv_pnp(const std::vector<Eigen::Vector3d>& p, const std::vector<Eigen::Vector2d>& uv, int flags) {
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  for (std::size_t i = 0; i < p.size(); ++i) {
    obj.emplace_back(p[i].x(), p[i].y(), p[i].z());
    img.emplace_back(uv[i].x(), uv[i].y());
  }
  const cv::Matx33d K(kCamera.fx, 0, kCamera.cx, 0, kCamera.fy, kCamera.cy, 0, 0, 1);
  cv::Mat rvec, tvec;
  EXPECT_TRUE(cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, false, flags));
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d Re;
  cv::cv2eigen(R, Re);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Re;
  T.translation() << tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2);
  return T;
}

}  // namespace

TEST(Epnp, NoiselessPointsGiveTheExactPoseForEveryShape) {
  touchdown::Rng rng(11);
  for (Shape shape : {Shape::NonPlanar, Shape::Planar, Shape::QuasiPlanar}) {
    for (int n : {4, 5, 6, 10}) {
      for (int k = 0; k < 40; ++k) {
        const auto p = constellation(shape, rng, n);
        const auto T = random_pose(rng);
        const auto uv = observe(T, p, rng, 0.0);
        const auto e = tp::solve_epnp(kCamera, p, uv);
        ASSERT_TRUE(e.ok) << "shape " << int(shape) << " n " << n;
        // EPnP alone: exact up to conditioning (quasi-planar is its weak case).
        const double tol = shape == Shape::QuasiPlanar ? 2e-3 : 1e-6;
        EXPECT_LT((e.T_camera_body.translation() - T.translation()).norm(), tol) << int(shape) << " n " << n;
        EXPECT_LT(rotation_error(e.T_camera_body, T), tol) << int(shape) << " n " << n;
        EXPECT_EQ(e.planar, shape == Shape::Planar || (shape == Shape::QuasiPlanar && e.planar));
        // EPnP + Gauss–Newton on SE(3): exact to 1e-9.
        const auto r = tp::solve_pnp(kCamera, p, uv);
        ASSERT_TRUE(r.ok());
        EXPECT_LT((r.T_camera_body.translation() - T.translation()).norm(), 1e-9) << int(shape) << " n " << n;
        EXPECT_LT(rotation_error(r.T_camera_body, T), 1e-9) << int(shape) << " n " << n;
        EXPECT_LT(r.rms_px, 1e-7);
      }
    }
  }
}

TEST(Epnp, AgreesWithOpenCvSolversOnNoisyWellConditionedCases) {
  touchdown::Rng rng(12);
  for (Shape shape : {Shape::NonPlanar, Shape::Planar}) {
    for (int k = 0; k < 60; ++k) {
      const auto p = constellation(shape, rng, 8);
      const auto T = random_pose(rng);
      const auto uv = observe(T, p, rng, 0.5);
      const auto ours = tp::solve_epnp(kCamera, p, uv);
      ASSERT_TRUE(ours.ok);
      // OpenCV's EPnP solves the same linear problem: close, not identical
      // (it uses different beta approximations).
      const auto cv_epnp = opencv_pnp(p, uv, cv::SOLVEPNP_EPNP);
      const double d = T.translation().z();
      const double ours_err = (ours.T_camera_body.translation() - T.translation()).norm();
      const double cv_err = (cv_epnp.translation() - T.translation()).norm();
      EXPECT_LT(ours_err, 1.5 * cv_err + 0.01 * d)
          << "shape " << int(shape) << " case " << k << " ours " << ours_err << " cv " << cv_err << " rms "
          << ours.rms_px << " planar " << ours.planar;
      // After Gauss–Newton we sit at the least-squares minimum, as
      // OpenCV's ITERATIVE (Levenberg–Marquardt) and SQPnP do.
      const auto refined = tp::solve_pnp(kCamera, p, uv);
      ASSERT_TRUE(refined.ok());
      const auto cv_iter = opencv_pnp(p, uv, cv::SOLVEPNP_ITERATIVE);
      const auto cv_sqpnp = opencv_pnp(p, uv, cv::SOLVEPNP_SQPNP);
      EXPECT_LT((refined.T_camera_body.translation() - cv_iter.translation()).norm(), 1e-6 * (1 + d));
      EXPECT_LT(rotation_error(refined.T_camera_body, cv_iter), 1e-6);
      // SQPnP minimises an object-space error, a slightly different cost.
      EXPECT_LT((refined.T_camera_body.translation() - cv_sqpnp.translation()).norm(), 0.01 * d);
      EXPECT_LT(rotation_error(refined.T_camera_body, cv_sqpnp), 0.03);
      // Our pose's reprojection error is never worse than OpenCV's.
      auto rms = [&](const Eigen::Isometry3d& X) {
        double s = 0;
        for (std::size_t i = 0; i < p.size(); ++i) s += (kCamera.project(X * p[i]) - uv[i]).squaredNorm();
        return std::sqrt(s / p.size());
      };
      EXPECT_LE(refined.rms_px, rms(cv_iter) + 1e-9);
      EXPECT_LE(refined.rms_px, rms(cv_sqpnp) + 1e-9);
      EXPECT_NEAR(ours.rms_px, rms(ours.T_camera_body), 1e-9);
    }
  }
}

TEST(Epnp, QuasiPlanarNoisyReprojectsNoWorseThanOpenCv) {
  // EPnP's weak case: 6 mm relief over 40 cm. Both minima of the planar
  // ambiguity may be close; we must end in the better one at least as
  // often as OpenCV's solvers do.
  touchdown::Rng rng(14);
  int worse = 0;
  for (int k = 0; k < 100; ++k) {
    const auto p = constellation(Shape::QuasiPlanar, rng, 6);
    const auto T = random_pose(rng);
    const auto uv = observe(T, p, rng, 0.5);
    const auto refined = tp::solve_pnp(kCamera, p, uv);
    ASSERT_TRUE(refined.ok());
    double best_cv = 1e300;
    for (int flags : {cv::SOLVEPNP_ITERATIVE, cv::SOLVEPNP_SQPNP, cv::SOLVEPNP_EPNP}) {
      const auto X = opencv_pnp(p, uv, flags);
      double s = 0;
      for (std::size_t i = 0; i < p.size(); ++i) s += (kCamera.project(X * p[i]) - uv[i]).squaredNorm();
      best_cv = std::min(best_cv, std::sqrt(s / p.size()));
    }
    if (refined.rms_px > best_cv + 1e-6) ++worse;
  }
  EXPECT_LE(worse, 2);
}

TEST(Epnp, DegenerateInputIsAStatusNotAPose) {
  std::vector<Eigen::Vector3d> p{{0, 0, 0}, {0.1, 0, 0}, {0.2, 0, 0}, {0.3, 0, 0}};  // collinear
  std::vector<Eigen::Vector2d> uv{{400, 200}, {410, 200}, {420, 200}, {430, 200}};
  EXPECT_FALSE(tp::solve_epnp(kCamera, p, uv).ok);
  EXPECT_EQ(tp::solve_pnp(kCamera, p, uv).status, tp::RefineStatus::Degenerate);
  p = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};  // too few
  uv.resize(3);
  EXPECT_FALSE(tp::solve_epnp(kCamera, p, uv).ok);
  p.push_back({0.1, 0.1, 0.05});
  uv.resize(2);  // sizes differ
  EXPECT_FALSE(tp::solve_epnp(kCamera, p, uv).ok);
}

TEST(Epnp, FourPointsOfEachShape) {
  // The minimal case the correspondence search relies on.
  touchdown::Rng rng(13);
  for (Shape shape : {Shape::NonPlanar, Shape::Planar}) {
    int good = 0;
    for (int k = 0; k < 100; ++k) {
      const auto p = constellation(shape, rng, 4);
      const auto T = random_pose(rng);
      const auto uv = observe(T, p, rng, 0.3);
      const auto r = tp::solve_pnp(kCamera, p, uv);
      if (r.ok() && (r.T_camera_body.translation() - T.translation()).norm() < 0.05 * T.translation().z()) ++good;
    }
    EXPECT_GE(good, 95) << "shape " << int(shape);
  }
}
