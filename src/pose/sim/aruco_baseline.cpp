#include "touchdown/pose/sim/aruco_baseline.hpp"

#include <Eigen/Cholesky>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string_view>
#include <tuple>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::pose {

std::vector<std::string> aruco_dictionary_names() { return aruco_dictionary_name_list(); }

std::string canonical_aruco_dictionary(std::string_view name) {
  const ArucoDictionaryInfo* d = find_aruco_dictionary(name);
  return d ? std::string(d->name) : std::string();
}

bool ArucoOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  const auto* dict = find_aruco_dictionary(dictionary);
  if (!dict) return fail("dictionary: unknown ArUco dictionary " + unknown_aruco_dictionary(dictionary));
  const int n = dict->codes;
  if (marker_id < 0 || marker_id >= n) {
    return fail("marker_id: " + std::to_string(marker_id) + " is not in dictionary " + std::string(dict->name) +
                " (ids 0.." + std::to_string(n - 1) + ")");
  }
  if (!(marker_size > 0 && marker_size <= 10)) {
    return fail("marker_size: must be an edge length in (0, 10] m, got " +
                touchdown::detail::format_general(marker_size));
  }
  if (!(detection_sigma_px > 0) || !std::isfinite(detection_sigma_px))
    return fail("detection_sigma_px: must be positive");
  return true;
}

struct ArucoPoseEstimator::Impl {
  CameraModel camera;
  Eigen::Isometry3d T_body_marker;
  Eigen::Isometry3d T_marker_body;
  ArucoOptions options;

  cv::Ptr<cv::aruco::Dictionary> dictionary;
  cv::Ptr<cv::aruco::DetectorParameters> parameters;
  cv::Matx33d camera_matrix;
  cv::Matx<double, 1, 5> distortion;
  std::array<cv::Point3d, 4> corners_marker;  // aruco's corner order, see the header
  std::array<Eigen::Vector3d, 4> corners_body;

  // Buffers reused from frame to frame.
  cv::Mat gray;
  std::vector<std::vector<cv::Point2f>> detected;
  std::vector<int> ids;
  std::vector<cv::Point2d> image_points;
  std::vector<cv::Point2d> projected;
  std::array<cv::Point3d, 4> points_camera;
};

ArucoPoseEstimator::ArucoPoseEstimator(const CameraModel& camera, const Eigen::Isometry3d& T_body_marker,
                                       const ArucoOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("ArUco options: " + why);
  if (!camera.validate(&why)) throw InvalidArgument("camera: " + why);
  const Eigen::Matrix3d R = T_body_marker.linear();
  if (!T_body_marker.matrix().allFinite() || !(R.transpose() * R).isIdentity(1e-6) || !(R.determinant() > 0)) {
    throw InvalidArgument("T_body_marker: not a finite rigid transform (rotation must be orthonormal, det +1)");
  }
  auto impl = std::make_unique<Impl>();
  impl->camera = camera;
  impl->T_body_marker = T_body_marker;
  impl->T_marker_body = T_body_marker.inverse(Eigen::Isometry);
  impl->options = options;
  impl->dictionary = cv::aruco::getPredefinedDictionary(find_aruco_dictionary(options.dictionary)->opencv_id);
  impl->parameters = cv::aruco::DetectorParameters::create();
  // Otherwise aruco's defaults: the baseline is the pipeline people run.
  if (options.corner_refinement) impl->parameters->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  impl->camera_matrix = cv::Matx33d(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  for (int i = 0; i < 5; ++i) impl->distortion(0, i) = camera.distortion[static_cast<std::size_t>(i)];
  const double h = options.marker_size / 2;
  impl->corners_marker = {cv::Point3d(-h, h, 0), cv::Point3d(h, h, 0), cv::Point3d(h, -h, 0), cv::Point3d(-h, -h, 0)};
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& c = impl->corners_marker[i];
    impl->corners_body[i] = T_body_marker * Eigen::Vector3d(c.x, c.y, c.z);
  }
  impl->image_points.resize(4);
  impl_ = std::move(impl);
}

ArucoPoseEstimator::~ArucoPoseEstimator() = default;
ArucoPoseEstimator::ArucoPoseEstimator(ArucoPoseEstimator&&) noexcept = default;
ArucoPoseEstimator& ArucoPoseEstimator::operator=(ArucoPoseEstimator&&) noexcept = default;

const ArucoOptions& ArucoPoseEstimator::options() const { return impl_->options; }
const CameraModel& ArucoPoseEstimator::camera() const { return impl_->camera; }
const Eigen::Isometry3d& ArucoPoseEstimator::T_body_marker() const { return impl_->T_body_marker; }

PoseEstimate ArucoPoseEstimator::estimate(const BgrImageView& image) {
  Impl& m = *impl_;
  if (!image.data || image.width <= 0 || image.height <= 0) throw InvalidArgument("image: empty view");
  if (image.stride < std::ptrdiff_t{3} * image.width) {
    throw InvalidArgument("image: stride " + std::to_string(image.stride) + " is smaller than 3 × width " +
                          std::to_string(image.width));
  }
  if (image.width != m.camera.width || image.height != m.camera.height) {
    throw InvalidArgument("image: " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                          " does not match the camera's " + std::to_string(m.camera.width) + "x" +
                          std::to_string(m.camera.height));
  }

  PoseEstimate out;
  out.status = PoseStatus::MarkerNotFound;
  // A header over the caller's pixels: no copy. cv::Mat has no const-data
  // constructor; the pixels are only read (cvtColor's source).
  const cv::Mat bgr(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.data),
                    static_cast<std::size_t>(image.stride));
  cv::cvtColor(bgr, m.gray, cv::COLOR_BGR2GRAY);
  cv::aruco::detectMarkers(m.gray, m.dictionary, m.detected, m.ids, m.parameters);
  out.blobs = static_cast<int>(m.ids.size());

  // The requested id; the largest instance if it appears more than once.
  int best = -1;
  double best_perimeter = 0;
  for (std::size_t i = 0; i < m.ids.size(); ++i) {
    if (m.ids[i] != m.options.marker_id || m.detected[i].size() != 4) continue;
    const double perimeter = cv::arcLength(m.detected[i], true);
    if (best < 0 || perimeter > best_perimeter) {
      best = static_cast<int>(i);
      best_perimeter = perimeter;
    }
  }
  if (best < 0) return out;
  const auto& corners = m.detected[static_cast<std::size_t>(best)];
  std::array<Eigen::Vector2d, 4> corners_px;
  for (std::size_t i = 0; i < 4; ++i) corners_px[i] = Eigen::Vector2d(corners[i].x, corners[i].y);
  PoseEstimate solved = estimate_from_corners(corners_px);
  solved.blobs = out.blobs;
  return solved;
}

PoseEstimate ArucoPoseEstimator::estimate_from_corners(const std::array<Eigen::Vector2d, 4>& corners_px) {
  Impl& m = *impl_;
  PoseEstimate out;
  out.status = PoseStatus::Degenerate;
  out.points = 4;
  out.blobs = 1;
  out.reinitialised = true;  // every frame is a fresh detection
  for (const auto& c : corners_px) {
    if (!c.allFinite()) return out;
  }

  // IPPE for squares (Collins & Bartoli 2014) through cv::solvePnP. OpenCV
  // 4.6 turns IPPE's rotation matrix into a vector with its own log map,
  // rvec = θ/(2 sin θ)·vee(R − Rᵀ) (PoseSolver::rot2vec in
  // modules/calib3d/src/ippe.cpp), which loses all precision as θ → π and
  // returns NaN at θ = π. θ ≈ π is exactly our geometry: a camera looking
  // up at a marker that faces down (R_camera_marker ≈ Rx(π)). So the square
  // is solved in each of its 8 symmetric relabellings V (p_marker = S p_V,
  // S a rotation mapping the square onto itself, canonical IPPE corners in
  // V), R_camera_marker = R_camera_V · Sᵀ is recovered with the exact
  // cv::Rodrigues, and the candidate with the lowest reprojection error is
  // kept. At least one relabelling has θ ≤ ~90°, where the log map is
  // accurate; the others either agree with it or reproject worse.
  const std::array<cv::Point3d, 4>& canonical = m.corners_marker;
  Eigen::Isometry3d best_T = Eigen::Isometry3d::Identity();
  double best_sq = std::numeric_limits<double>::infinity();
  for (int flip = 0; flip < 2; ++flip) {
    for (int quarter = 0; quarter < 4; ++quarter) {
      const Eigen::Matrix3d S = (Eigen::AngleAxisd(flip ? std::numbers::pi : 0.0, Eigen::Vector3d::UnitX()) *
                                 Eigen::AngleAxisd(quarter * std::numbers::pi / 2, Eigen::Vector3d::UnitZ()))
                                    .toRotationMatrix();
      // Image point of canonical corner j: the detected corner at S·P_j.
      bool mapped = true;
      for (std::size_t j = 0; j < 4; ++j) {
        const Eigen::Vector3d q = S * Eigen::Vector3d(canonical[j].x, canonical[j].y, canonical[j].z);
        std::size_t match = 4;
        for (std::size_t c = 0; c < 4; ++c) {
          if ((q - Eigen::Vector3d(canonical[c].x, canonical[c].y, canonical[c].z)).norm() <
              1e-6 * m.options.marker_size) {
            match = c;
          }
        }
        if (match == 4) {
          mapped = false;
          break;
        }
        m.image_points[j] = cv::Point2d(corners_px[match].x(), corners_px[match].y());
      }
      if (!mapped) continue;  // cannot happen: S is a symmetry of the square
      cv::Vec3d rvec, tvec;
      try {
        if (!cv::solvePnP(canonical, m.image_points, m.camera_matrix, m.distortion, rvec, tvec, false,
                          cv::SOLVEPNP_IPPE_SQUARE)) {
          continue;
        }
      } catch (const cv::Exception&) {
        continue;  // OpenCV rejects degenerate input by throwing
      }
      if (!std::isfinite(rvec[0] + rvec[1] + rvec[2] + tvec[0] + tvec[1] + tvec[2])) continue;
      cv::Matx33d R_camera_v;
      cv::Rodrigues(rvec, R_camera_v);
      Eigen::Isometry3d T_camera_marker = Eigen::Isometry3d::Identity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) T_camera_marker.linear()(r, c) = R_camera_v(r, c);
        T_camera_marker.translation()(r) = tvec(r);
      }
      T_camera_marker.linear() = T_camera_marker.linear() * S.transpose();
      // Reprojection of the marker's corners, in detector order, through
      // the lens model (points already in the camera frame: zero rvec/tvec).
      bool in_front = true;
      for (std::size_t i = 0; i < 4; ++i) {
        const auto& c = canonical[i];
        const Eigen::Vector3d p = T_camera_marker * Eigen::Vector3d(c.x, c.y, c.z);
        in_front = in_front && p.z() > 0;
        m.points_camera[i] = cv::Point3d(p.x(), p.y(), p.z());
      }
      if (!in_front) continue;
      cv::projectPoints(m.points_camera, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), m.camera_matrix, m.distortion,
                        m.projected);
      double sq = 0;
      for (std::size_t i = 0; i < 4; ++i) {
        const cv::Point2d d = m.projected[i] - cv::Point2d(corners_px[i].x(), corners_px[i].y());
        sq += d.dot(d);
      }
      if (std::isfinite(sq) && sq < best_sq) {
        best_sq = sq;
        best_T = T_camera_marker;
      }
    }
  }
  if (!std::isfinite(best_sq)) return out;  // no relabelling gave a pose in front of the camera
  const Eigen::Isometry3d T_camera_body = best_T * m.T_marker_body;
  out.rms_px = std::sqrt(best_sq / 4.0);

  // Covariance as the LED tracker's Gauss–Newton reports it: σ² (JᵀJ)⁻¹ on
  // the undistorted corners, left perturbation of T_camera_body.
  const PinholeCamera pinhole = m.camera.pinhole();
  Matrix6d H = Matrix6d::Zero();
  double cost = 0;
  Eigen::Vector2d r;
  Eigen::Matrix<double, 2, 6> J;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d uv = m.camera.undistort(corners_px[i]);
    if (!reprojection_residual(pinhole, T_camera_body, m.corners_body[i], uv, r, &J)) return out;
    H.noalias() += J.transpose() * J;
    cost += r.squaredNorm();
  }
  const Eigen::LDLT<Matrix6d> ldlt(H);
  if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 1e-12 * H.diagonal().maxCoeff()).all()) {
    const Matrix6d unit = ldlt.solve(Matrix6d::Identity());
    out.covariance = (cost / 2.0) * unit;
    const double floor = m.options.detection_sigma_px * m.options.detection_sigma_px;
    std::tie(out.sigma_position_m, out.sigma_rotation_rad) =
        pose_sigmas(std::max(cost / 2.0, floor) * unit, T_camera_body);
  }
  out.T_camera_body = T_camera_body;
  out.status = PoseStatus::Ok;
  return out;
}

}  // namespace touchdown::pose
