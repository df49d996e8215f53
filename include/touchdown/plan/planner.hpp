#pragma once
/// \file
/// Landing trajectory for a moving pad: a piecewise Bézier curve of the
/// drone's position in the pad's frame that minimises the integral of
/// squared jerk, from the drone's state to the touchdown state, inside the
/// visual safe flight corridor (corridor.hpp), with the drone's velocity
/// and acceleration limited per axis in the world frame although the curve
/// lives in the moving frame; the segment durations are chosen online
/// (NLopt BOBYQA on J(T) + ρ ΣT, each evaluation one warm-started QP).
///
/// Pad frame: x forward, y left, z up, origin at the pad centre on its
/// surface. The pad's motion is predicted from the planning time with a
/// constant body velocity and a constant yaw rate (CTRV): its heading is
/// ψ(t) = yaw + yaw_rate·t and its world velocity R_z(ψ(t)) R_z(yaw)ᵀ
/// velocity. The world axes are the planner's (x, y as the pad's velocity
/// is given, z up). With the drone at pad-frame position p, velocity v and
/// acceleration a, its world velocity is R_z(ψ)(v_b + v + ω e_z × p) and its
/// world acceleration R_z(ψ)(a + 2ω e_z × v + ω e_z × (ω e_z × p) + ω e_z ×
/// v_b), v_b the pad's body velocity. Both are linear in the control points
/// (degree-elevated to one order), so a per-axis limit on the curve's
/// control points bounds the curve (convex hull):
///  - translating pad (yaw_rate = 0): R_z(ψ) is constant and the per-axis
///    world limits are exact linear constraints on the control points;
///  - rotating pad: R_z(ψ(t)) turns with time, so x and y are bounded
///    together by an octagon inscribed in the circle of radius limit, for
///    any heading (conservative by at most 1 − cos(π/8) = 7.6 %); z stays
///    exact.
///
/// The cost matrix of a jerk cost is only semi-definite (quadratics have no
/// jerk); the planner eliminates the equalities in closed form (the start,
/// the goal and continuity fix three control points each), and the QP in
/// the remaining control points is definite.
///
/// Allocation: plan() allocates (a corridor, the QP's matrices); the QP
/// solves inside the time allocation reuse one work space. Thread-safe:
/// plan() is a pure function.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/plan/bezier.hpp"
#include "touchdown/plan/corridor.hpp"

namespace touchdown::plan {

/// Position, velocity, acceleration in the pad frame (relative to the pad).
struct KinematicState {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
};

/// The pad's predicted motion from the planning time (CTRV).
struct PadMotion {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< world frame at t = 0 [m/s]
  double yaw_rate = 0;                                 ///< [rad/s]
  double yaw = 0;                                      ///< pad heading in the world at t = 0 [rad]

  /// Pad heading, position (from its position at t = 0) and world velocity at t.
  [[nodiscard]] double heading(double t) const { return yaw + yaw_rate * t; }
  [[nodiscard]] Eigen::Vector3d position(double t) const;
  [[nodiscard]] Eigen::Vector3d world_velocity(double t) const;
  /// A pad-frame state at t as the drone's world position (from the pad's
  /// position at t = 0), velocity and acceleration.
  [[nodiscard]] KinematicState to_world(double t, const KinematicState& relative) const;
};

/// [s] Range of a segment's duration, fixed or allocated. The jerk cost
/// scales as T⁻⁵: beyond it the QP loses its precision (at 2000 s the
/// solver finds it not convex, at 1e-300 s its entries overflow).
inline constexpr double kMinSegmentDuration = 1e-3;
inline constexpr double kMaxSegmentDuration = 1000;

struct TimeAllocationOptions {
  /// Per-segment duration bounds [s], kMinSegmentDuration <= min < max <=
  /// kMaxSegmentDuration.
  double min = 0.3;
  double max = 8;
  double rho = 1;  ///< weight of the total duration in J(T) + ρ ΣT [cost units per s], ≥ 0
  /// Cap on the time allocation's QP solves, ≥ 1, honoured exactly: every
  /// solve counts (the coarse grid, the first guess, the local search).
  /// The coarse grid (4 points per segment, up to 3 segments) runs only when
  /// the cap leaves room for it and the guess; the local search gets the
  /// rest. The plan then solves the QP once more at the chosen durations
  /// (PlanResult::qp_us), which is not an evaluation.
  int max_evaluations = 300;
};

enum class ConstraintGroup { Boundary, Corridor, Velocity, Acceleration };

}  // namespace touchdown::plan

template <>
struct touchdown::EnumNames<touchdown::plan::ConstraintGroup> {
  static constexpr std::array<std::string_view, 4> names{"boundary", "corridor", "velocity", "acceleration"};
};

namespace touchdown::plan {

inline std::string_view to_string(ConstraintGroup group) { return enum_name(group); }

struct PlannerOptions {
  int order = 7;     ///< Bézier order, ≥ 5
  int segments = 2;  ///< ≥ 1 (≥ 2 with a corridor)
  double v_max = 3;  ///< per-axis world-frame limits [m/s], [m/s²], > 0
  double a_max = 5;
  /// Fixed segment durations [s] (one per segment, each in
  /// [kMinSegmentDuration, kMaxSegmentDuration]); empty: time allocation.
  std::vector<double> durations;
  TimeAllocationOptions time;
  /// No corridor: unconstrained space (obstacles then unused).
  std::optional<CorridorOptions> corridor;
  std::vector<Box> obstacles;  ///< pad frame
  /// Fill PlanResult::qp with the dense QP at the chosen durations (for
  /// --export-qp or another solver). Off by default: a replanning loop does
  /// not need it, and its ~150 KB of matrices per plan cost more than the
  /// plan itself once glibc hands the freed heap back to the system
  /// (docs/benchmarks.md, "Landing trajectory", heap note).
  bool export_qp = false;
  /// Called after each QP solve of the time allocation with the solves done
  /// so far (`done`) of time.max_evaluations (`total`; an app draws a
  /// progress bar from it; the allocation may stop before the cap). Called
  /// on the planning thread; empty: none.
  ProgressCallback progress;
  /// False (with "field: what is wrong" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

enum class PlanStatus {
  Ok,
  Infeasible,  ///< no trajectory meets the constraints; `conflicts` names the groups
  NoCorridor,  ///< the corridor could not be built (see corridor.status)
  /// The time allocation reached time.max_evaluations before it found
  /// durations at which the QP is feasible: the problem may well be
  /// feasible (raise the cap); no trajectory, no diagnosis.
  AllocationCutShort,
};

}  // namespace touchdown::plan

template <>
struct touchdown::EnumNames<touchdown::plan::PlanStatus> {
  static constexpr std::array<std::string_view, 4> names{"ok", "infeasible", "no_corridor", "allocation_cut_short"};
};

namespace touchdown::plan {

inline std::string_view to_string(PlanStatus status) { return enum_name(status); }

/// The QP at the chosen durations, as exported: min ½xᵀPx + qᵀx + constant
/// s.t. A_eq x = b_eq, A_in x ≤ b_in; x holds (segment, control point, axis)
/// in that order, x = ((k (n+1) + i) 3 + axis). P is the jerk cost's (only
/// semi-definite) matrix, so ½x*ᵀPx* + qᵀx* + constant is `cost`.
struct QpProblem {
  int order = 0, segments = 0;
  Eigen::MatrixXd P, A_eq, A_in;
  Eigen::VectorXd q, b_eq, b_in;
  double constant = 0;
  std::vector<ConstraintGroup> eq_groups, in_groups;  ///< the group of each row
  /// "s<segment>.c<control point>.<axis>" per variable, in the order of x.
  [[nodiscard]] std::vector<std::string> variable_names() const;
};

struct PlanResult {
  PlanStatus status = PlanStatus::Infeasible;
  std::string message;
  PiecewiseBezier trajectory;               ///< pad frame; valid when ok()
  double cost = 0;                          ///< ∫‖d³p/dt³‖² dt over the whole trajectory [m²/s⁵]
  double objective = 0;                     ///< cost + ρ ΣT (time allocation's objective)
  std::vector<ConstraintGroup> conflicts;   ///< when infeasible: each group whose relaxation restores feasibility
  Corridor corridor;                        ///< when options.corridor is set
  std::vector<Polytope> segment_polytopes;  ///< one per segment (empty without a corridor)
  QpProblem qp;                             ///< at the chosen durations (only with options.export_qp)
  int evaluations = 0;                      ///< QPs solved by the time allocation (0 with fixed durations)
  /// The time allocation stopped at time.max_evaluations (it wanted more
  /// solves: the coarse grid did not fit or the local search had not
  /// converged): the durations may be far from optimal. With an ok() plan a
  /// warning; with no feasible durations found the status is
  /// AllocationCutShort.
  bool evaluation_cap_reached = false;
  double allocation_ms = 0;  ///< wall time of the time allocation
  int qp_iterations = 0;     ///< of the final QP
  double qp_us = 0;          ///< wall time of the final QP (cold start)
  [[nodiscard]] bool ok() const { return status == PlanStatus::Ok; }
};

/// Plans a landing from `start` to `goal` (default: the pad centre at the
/// corridor's h_touchdown, or 0.5 m without a corridor, at rest relative to
/// the pad). Throws InvalidArgument for invalid options, non-finite states,
/// or a start outside the corridor it builds; an impossible plan is a status.
PlanResult plan(const KinematicState& start, const std::optional<KinematicState>& goal, const PadMotion& pad,
                const PlannerOptions& options);

/// plan() in corridor polytopes already built (one per segment; empty:
/// unconstrained space): for callers that keep a corridor over several
/// plans (a replan cycle, a grid over durations). The goal is explicit.
PlanResult plan_in_corridor(const KinematicState& start, const KinematicState& goal, const PadMotion& pad,
                            const PlannerOptions& options, const std::vector<Polytope>& segment_polytopes);

/// Replanning at given segment durations inside corridor polytopes kept for
/// the whole landing (a guidance loop's replans): the QP's rows, its
/// reduction, the solver and the curve live in work space kept between
/// calls, so a replan of the same size does not allocate (tested). The
/// plan is the one plan_in_corridor() gives at the same durations.
/// Not thread-safe: one per landing.
class Replanner {
 public:
  /// Throws InvalidArgument for invalid options or a polytope count other
  /// than the segments (empty: unconstrained space). The options'
  /// durations, export_qp and progress are not used.
  Replanner(PlannerOptions options, std::vector<Polytope> segment_polytopes);
  ~Replanner();
  Replanner(Replanner&&) noexcept;
  Replanner& operator=(Replanner&&) noexcept;
  Replanner(const Replanner&) = delete;
  Replanner& operator=(const Replanner&) = delete;

  /// Plans from `start` to `goal` at `durations` (one per segment, each in
  /// [kMinSegmentDuration, kMaxSegmentDuration]). Ok: trajectory() holds
  /// it; NoCorridor: the start or goal is outside its polytope; Infeasible:
  /// the QP is (or an input is not finite, or a count is wrong). No
  /// diagnosis: a caller who needs one runs plan_in_corridor().
  PlanStatus plan(const KinematicState& start, const KinematicState& goal, const PadMotion& pad,
                  std::span<const double> durations);
  /// The last Ok plan.
  [[nodiscard]] const PiecewiseBezier& trajectory() const;
  [[nodiscard]] double cost() const;  ///< its jerk cost [m²/s⁵]
  [[nodiscard]] int iterations() const;
  [[nodiscard]] const std::vector<Polytope>& segment_polytopes() const;
  [[nodiscard]] const PlannerOptions& options() const;  ///< what it plans with

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The default goal for these options (see plan()).
KinematicState default_goal(const PlannerOptions& options);

}  // namespace touchdown::plan
