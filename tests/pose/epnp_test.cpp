#include "touchdown/pose/epnp.hpp"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <vector>

#include "pose/p3p.hpp"
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
        ASSERT_TRUE(e.ok()) << "shape " << int(shape) << " n " << n;
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
      ASSERT_TRUE(ours.ok());
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
  tp::EpnpResult e = tp::solve_epnp(kCamera, p, uv);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.status, tp::EpnpStatus::Degenerate);
  EXPECT_EQ(e.message(), "degenerate");
  EXPECT_EQ(tp::solve_pnp(kCamera, p, uv).status, tp::RefineStatus::Degenerate);
  p = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};  // too few
  uv.resize(3);
  e = tp::solve_epnp(kCamera, p, uv);
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.status, tp::EpnpStatus::TooFewPoints);
  EXPECT_EQ(e.message(), "too_few_points");
  p.push_back({0.1, 0.1, 0.05});
  uv.resize(2);  // sizes differ
  EXPECT_EQ(tp::solve_epnp(kCamera, p, uv).status, tp::EpnpStatus::TooFewPoints);
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

// Grunert's P3P (src/pose/p3p.hpp): the true distances are among the
// solutions, and so is every solution OpenCV's P3P finds on the same rays.
TEST(P3p, FindsTheTrueDistancesAndEveryOpenCvSolution) {
  touchdown::Rng rng(13);
  const cv::Matx33d K(kCamera.fx, 0, kCamera.cx, 0, kCamera.fy, kCamera.cy, 0, 0, 1);
  int opencv_solutions = 0, opencv_matched = 0, exact = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto p = constellation(Shape::NonPlanar, rng, 3);
    const auto T = random_pose(rng);
    std::array<Eigen::Vector3d, 3> j;
    Eigen::Vector3d truth;
    std::vector<cv::Point3d> obj;
    std::vector<cv::Point2d> img;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d q = T * p[static_cast<std::size_t>(i)];
      truth(i) = q.norm();
      j[static_cast<std::size_t>(i)] = q.normalized();
      const Eigen::Vector2d uv = kCamera.project(q);
      obj.emplace_back(p[static_cast<std::size_t>(i)].x(), p[static_cast<std::size_t>(i)].y(),
                       p[static_cast<std::size_t>(i)].z());
      img.emplace_back(uv.x(), uv.y());
    }
    const double a = (p[1] - p[2]).norm(), b = (p[0] - p[2]).norm(), c = (p[0] - p[1]).norm();
    const auto sol = tp::detail::solve_p3p(j[0], j[1], j[2], a, b, c);
    ASSERT_GE(sol.count, 1) << trial;
    int best = 0;
    for (int s = 1; s < sol.count; ++s) {
      if ((sol.s[static_cast<std::size_t>(s)] - truth).norm() < (sol.s[static_cast<std::size_t>(best)] - truth).norm())
        best = s;
    }
    const Eigen::Vector3d& d = sol.s[static_cast<std::size_t>(best)];
    // Exact for a simple root; a double root (the camera on the "danger
    // cylinder") is found to about 1e-3 (Newton converges slowly there).
    EXPECT_LT((d - truth).norm(), 1e-3 * truth.norm()) << trial;
    if ((d - truth).norm() < 1e-6 * truth.norm()) ++exact;
    std::vector<cv::Mat> rvecs, tvecs;
    cv::solveP3P(obj, img, K, cv::noArray(), rvecs, tvecs, cv::SOLVEPNP_P3P);
    for (std::size_t s = 0; s < rvecs.size(); ++s) {
      cv::Mat R;
      cv::Rodrigues(rvecs[s], R);
      Eigen::Matrix3d Re;
      cv::cv2eigen(R, Re);
      const Eigen::Vector3d t(tvecs[s].at<double>(0), tvecs[s].at<double>(1), tvecs[s].at<double>(2));
      Eigen::Vector3d dist;
      bool solves = true;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d q = Re * p[static_cast<std::size_t>(i)] + t;
        dist(i) = q.norm();
        // A solution puts each point on its ray (in front, and reprojected
        // within 0.5 px): OpenCV's P3P also returns a few poses 2-30 % off
        // near degenerate triangles, more of them on arm64 (635 of 643
        // matched there against 637 of 642 here), which are not solutions.
        const Eigen::Vector2d uv = kCamera.project(q);
        const cv::Point2d& seen = img[static_cast<std::size_t>(i)];
        solves = solves && q.dot(j[static_cast<std::size_t>(i)]) > 0.999 * dist(i) &&
                 std::hypot(uv.x() - seen.x, uv.y() - seen.y) < 0.5;
      }
      if (!solves) continue;
      ++opencv_solutions;
      // OpenCV's P3P is itself accurate to ~1e-3 only (against the truth).
      for (int k = 0; k < sol.count; ++k) {
        if ((sol.s[static_cast<std::size_t>(k)] - dist).norm() < 2e-2 * dist.norm()) {
          ++opencv_matched;
          break;
        }
      }
    }
  }
  EXPECT_GE(exact, 290);
  EXPECT_GT(opencv_solutions, 300);
  EXPECT_GE(opencv_matched, opencv_solutions * 99 / 100);
}

TEST(P3p, DegenerateInputGivesNoSolution) {
  const Eigen::Vector3d j = Eigen::Vector3d::UnitZ();
  EXPECT_EQ(tp::detail::solve_p3p(j, j, j, 0.1, 0.1, 0.1).count, 0);  // one ray: no triangle fits
  EXPECT_EQ(tp::detail::solve_p3p(j, Eigen::Vector3d(0.1, 0, 1).normalized(), Eigen::Vector3d(0, 0.1, 1).normalized(),
                                  0, 0.1, 0.1)
                .count,
            0);
}
