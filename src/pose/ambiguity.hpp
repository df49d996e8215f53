#pragma once
// Pose ambiguities (issue 9, item 3; internal to touchdown::pose): a pose
// estimator that lands a drone must say "I don't know" rather than report a
// wrong pose.
//
// - Mirror branch: a (quasi-)planar constellation seen from afar has a
//   two-fold ambiguity — the plane tilted the other way about the line of
//   sight reprojects almost as well (the two IPPE solutions of a plane;
//   Collins & Bartoli 2014, weak-perspective flip). mirrored_branch() seeds
//   the other branch, Gauss–Newton refines it, resolve_branches() decides:
//   by reprojection when the difference is significant for the detection
//   noise (a χ² test; with an attitude prior its χ² joins the
//   reprojection's), else by the depth image at the blobs (the same test
//   on the depth pattern), else by temporal consistency with the tracked
//   motion, else Ambiguous.
// - Uncertainty: within one branch, a small or distant constellation can
//   leave the pose poorly determined (a near-frontal board's tilt); a fit
//   whose 1-σ position or rotation exceeds the options' limits is
//   Uncertain, not Ok.
// - Rigid symmetry: a constellation that a rotation maps onto itself
//   (colours and emission cones included; e.g. a square of four white LEDs)
//   has poses no single frame can tell apart.
#include <Eigen/Geometry>
#include <array>
#include <span>
#include <utility>

#include "pose/assignment.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/correspondence.hpp"
#include "touchdown/pose/gauss_newton.hpp"
#include "touchdown/pose/led_detector.hpp"

namespace touchdown::pose::detail {

// The angle of the rotation between a and b [rad].
double rotation_angle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// What does not change between frames: the constellation's best-fit plane
// and whether it has a rigid symmetry.
struct ConstellationShape {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitZ();  // body frame, unit
  bool symmetric = false;                                   // a rotation other than the identity maps it onto itself
  static ConstellationShape of(const Constellation& constellation);
};

// True if a proper rotation other than the identity maps every LED onto an
// LED of the same colour (within max(3 mm, 3 % of the radius)) and its
// emission axis onto that LED's (within 10°).
bool has_rigid_symmetry(const Constellation& constellation);

// The seed of the other branch of `T_camera_body`: the constellation's
// plane rotated about its centroid so that its normal is mirrored about the
// line of sight.
Eigen::Isometry3d mirrored_branch(const Eigen::Isometry3d& T_camera_body, const ConstellationShape& shape);

// χ² of the depths measured at the matched blobs that carry a 3-D point
// against the pose's LED depths, after removing their median offset, with
// σ = depth_sigma_k·z² + 2 mm; negative when fewer than 3 blobs have depth.
double depth_misfit(const Constellation& constellation, std::span<const Blob> blobs,
                    const std::array<int, kMaxLeds>& blob_of_led, const Eigen::Isometry3d& T_camera_body,
                    const CorrespondenceOptions& options);

// A fit's twist covariance for its pixel noise variance floored,
// max(σ², floor_variance) [px²]; the depths and the attitude prior count
// with their own σ (PoseRefinement::covariance_for).
Matrix6d fit_covariance(const PoseRefinement& fit, double floor_variance);
// The p-quantile of the χ² distribution with `dof` degrees of freedom
// (dof > 0, 0 < p < 1): bisection on the regularised lower incomplete gamma
// function P(dof/2, x/2) by its power series (Abramowitz & Stegun 6.5.29).
// A fit's σ̂² = cost / dof is σ² χ²_dof / dof, so σ̂² · dof / chi2_quantile(dof,
// α) bounds σ² from above at confidence 1 − α.
double chi2_quantile(double dof, double p);
// The 1-σ position [m] and rotation [rad] of a fit (pose_sigmas of
// fit_covariance floored at detection_sigma_px²), and whether
// they exceed the options' sigma_limits (with or without an attitude prior).
std::pair<double, double> fit_sigmas(const PoseRefinement& fit, const CorrespondenceOptions& options);
bool too_uncertain(const PoseRefinement& fit, const CorrespondenceOptions& options, bool with_attitude);

enum class BranchVerdict { Keep, Switch, Ambiguous };

struct BranchDecision {
  BranchVerdict verdict = BranchVerdict::Keep;
  PoseRefinement alternative;  // the other branch, when it was distinct
  // The reprojection and the depths each ruled out a different branch: the
  // verdict is then their sum's (Ambiguous when it is not decisive).
  bool contradicted = false;
};

// Compares `fit` (refined on the matched set) with its mirrored branch.
// `predicted` (may be null) is the tracker's prediction for this frame;
// unless `prediction_vouched` (made from Ok poses), it settles the branch
// only where the image and the depths do not lean the other way.
BranchDecision resolve_branches(const PinholeCamera& camera, const Constellation& constellation,
                                const ConstellationShape& shape, std::span<const Blob> blobs,
                                const std::array<int, kMaxLeds>& blob_of_led, const MatchedSet& set,
                                const PoseRefinement& fit, const Eigen::Isometry3d* predicted,
                                const CorrespondenceOptions& options, const AttitudeConstraint& attitude = {},
                                bool prediction_vouched = true);

// The full search with the constellation's shape precomputed (the tracker
// keeps it; find_correspondences computes it per call).
// `attitude` (when active) gates every hypothesis (attitude_gate_chi2) and
// joins every refinement.
Correspondence find_correspondences(const PinholeCamera& camera, const Constellation& constellation,
                                    const ConstellationShape& shape, std::span<const Blob> blobs,
                                    const CorrespondenceOptions& options, const AttitudeConstraint& attitude = {});

// The checks a fit that reprojects well must pass to be reported Ok, one
// rule for the search and the tracker: a symmetric constellation is
// Ambiguous; the mirrored branch replaces `fit` when the evidence says so,
// or makes it Ambiguous when nothing settles it; a (switched) fit over
// `max_rms_px` is ReprojectionTooLarge; one over the sigma limits
// Uncertain. `predicted` (may be null) is the tracker's prediction
// (`prediction_vouched`: resolve_branches).
PoseStatus vet_fit(const PinholeCamera& camera, const Constellation& constellation, const ConstellationShape& shape,
                   std::span<const Blob> blobs, const std::array<int, kMaxLeds>& blob_of_led, PoseRefinement& fit,
                   const Eigen::Isometry3d* predicted, double max_rms_px, const CorrespondenceOptions& options,
                   const AttitudeConstraint& attitude = {}, bool prediction_vouched = true);

// True if two poses differ by more than the options' distinctness
// thresholds (branch_distinct_m, branch_distinct_deg).
bool distinct_poses(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, const CorrespondenceOptions& options);

}  // namespace touchdown::pose::detail
