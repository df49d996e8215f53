#pragma once
/// \file
/// Visual safe flight corridor (VSFC) for landing on a moving pad, built in
/// the pad's frame (x forward, y left, z up, origin at the pad centre on its
/// surface): free space around start and goal minus box obstacles, split at
/// the touchdown height into a rear part (z ≥ h_T, where the approach
/// starts) and a touchdown part (z ≤ h_T, the column above the pad), the
/// touchdown part deflated horizontally toward the pad centre, both dilated
/// vertically by ε_d so that they overlap, intersected with the pad camera's
/// field-of-view pyramid, and every face shrunk inward by the drone radius.
/// The result is one H-polytope {x | A x ≤ b} per trajectory segment, for
/// the control points of that segment (a Bézier segment lies in the convex
/// hull of its control points, so the whole curve stays in the corridor).
///
/// Follows the guidance paper's Algorithm 1 (canLand, free box, split,
/// deflate, dilate, FoV, radius), completed with the steps its published
/// code leaves out: obstacle subtraction by exact box algebra, deflation,
/// dilation and the radius shrink.
///
/// Allocation: building a corridor allocates (it runs once per replan);
/// Polytope::contains does not. Thread-safe: pure functions.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"

namespace touchdown::plan {

/// An axis-aligned box [min, max] (pad frame, m).
struct Box {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  [[nodiscard]] bool contains(const Eigen::Vector3d& p, double tolerance = 0) const;
  [[nodiscard]] double volume() const;  ///< 0 for an empty box
};

/// An H-polytope {x | A x ≤ b} in 3-D. Rows of A are unit normals (every
/// constructor in this file normalises them), so b − A x is the distance to
/// each face.
struct Polytope {
  Eigen::Matrix<double, Eigen::Dynamic, 3> A;
  Eigen::VectorXd b;
  [[nodiscard]] int faces() const { return static_cast<int>(b.size()); }
  [[nodiscard]] bool contains(const Eigen::Vector3d& p, double tolerance = 1e-9) const;
  /// Appends the half-space n·x ≤ d (n need not be unit; it is normalised).
  void add(const Eigen::Vector3d& n, double d);
  /// Appends every face of `other` (the intersection of the two).
  void intersect(const Polytope& other);
  /// Moves every face inward by `distance` (b_i −= distance for unit rows).
  void shrink(double distance);
  [[nodiscard]] static Polytope from_box(const Box& box);
};

/// The largest ball inside a polytope (Chebyshev ball): the exact solution
/// of the linear program max r s.t. a_iᵀc + r ≤ b_i (unit a_i). radius < 0
/// when the polytope is empty; an unbounded polytope is cut by a cube of
/// half-width 1e6 m.
struct ChebyshevBall {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = -1;
};
ChebyshevBall chebyshev_ball(const Polytope& polytope);

/// Removes faces implied by the others (kept faces in their order). A face
/// is redundant when maximising its normal over the polytope without it
/// does not exceed its offset.
Polytope remove_redundant_faces(const Polytope& polytope, double tolerance = 1e-9);

/// The pad camera's field of view, a pyramid with its apex at the camera:
/// camera frame x right, y down, z along the optical axis (the pose
/// module's convention), placed in the pad frame by T_pad_camera; with the
/// identity rotation the camera looks straight up (pad +z).
struct CameraFov {
  Eigen::Isometry3d T_pad_camera = Eigen::Isometry3d::Identity();
  double horizontal_fov_rad = 1.2;  ///< full angle, (0, π)
  double vertical_fov_rad = 0.9;    ///< full angle, (0, π)
  double near_m = 0.1;              ///< along the optical axis, ≥ 0
  double far_m = 10;                ///< along the optical axis, > near_m
  /// Four side planes, the near plane and the far plane (unit normals).
  [[nodiscard]] Polytope pyramid() const;
};

struct CorridorOptions {
  double h_touchdown = 0.5;  ///< height of the rear/touchdown split above the pad [m], > 0
  double deflate = 0.3;      ///< horizontal shrink of the touchdown part toward the pad centre [m], ≥ 0
  double dilate = 0.2;       ///< ε_d: vertical growth of each part across h_T per dilation step [m], > 0
  int max_dilations = 20;    ///< dilation steps tried before `no_overlap`
  double radius = 0.25;      ///< r_q: drone radius, every face moves inward by it [m], ≥ 0
  double margin = 1.0;  ///< free box: bounding box of start and goal grown by this (not below the pad) [m], ≥ radius
  std::optional<CameraFov> camera;  ///< no camera: no FoV constraint
  /// False (with "field: what is wrong" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class CorridorStatus {
  Ok,
  StartBlocked,  ///< start inside an obstacle (grown by the radius), below the pad plane, or outside the FoV
  GoalBlocked,   ///< goal inside an obstacle (grown by the radius) or outside the FoV
  NoConnection,  ///< no pair of free pieces joins start and goal (canLand false)
  NoOverlap,     ///< the parts still do not overlap after max_dilations
};

}  // namespace touchdown::plan

template <>
struct touchdown::EnumNames<touchdown::plan::CorridorStatus> {
  static constexpr std::array<std::string_view, 5> names{"ok", "start_blocked", "goal_blocked", "no_connection",
                                                         "no_overlap"};
};

namespace touchdown::plan {

inline std::string_view to_string(CorridorStatus status) { return enum_name(status); }

struct Corridor {
  CorridorStatus status = CorridorStatus::NoConnection;
  std::string message;  ///< why, when not ok
  Polytope rear;        ///< contains the start (after the radius shrink)
  Polytope touchdown;   ///< contains the goal (after the radius shrink)
  Box free_box;         ///< the free box before obstacle subtraction
  Box rear_piece;       ///< the obstacle-free box the rear part was cut from
  Box touchdown_piece;  ///< the obstacle-free box the touchdown part was cut from
  int dilations = 0;    ///< dilation steps used
  [[nodiscard]] bool ok() const { return status == CorridorStatus::Ok; }
  /// One polytope per segment: the first segments − 1 get the rear part,
  /// the last the touchdown part. Throws InvalidArgument for segments < 2
  /// (one segment cannot pass from one part to the other).
  [[nodiscard]] std::vector<Polytope> per_segment(int segments) const;
};

/// Builds the corridor for a landing from `start` to `goal` (pad frame)
/// around `obstacles` (pad-frame boxes). Throws InvalidArgument for invalid
/// options or non-finite input; an impossible corridor is a status.
Corridor build_corridor(const Eigen::Vector3d& start, const Eigen::Vector3d& goal, std::span<const Box> obstacles,
                        const CorridorOptions& options);

/// Every maximal obstacle-free axis-aligned box inside `free_box` (exact box
/// algebra: a box that meets an obstacle is replaced by its up-to-six slabs
/// beside the obstacle; boxes inside others are dropped). At most
/// `max_boxes`; throws InvalidArgument beyond it.
std::vector<Box> free_pieces(const Box& free_box, std::span<const Box> obstacles, int max_boxes = 4096);

}  // namespace touchdown::plan
