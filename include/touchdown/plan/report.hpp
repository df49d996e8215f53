#pragma once
/// \file
/// The landing plan's outputs, in the formats landing_plan writes
/// (docs/cli.md, "landing_plan"): the result and the QP as JSON, the
/// trajectory sampled every millisecond as CSV, a summary for a person and
/// the figure (SVG). For a program of your own that plans and reports the
/// same way.
#include <string>
#include <string_view>

#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"

namespace touchdown::plan {

/// Status, cost, objective, segments (durations and control points), the
/// corridor's polytopes, the time allocation's and final QP's effort, the
/// conflicts when infeasible and the message when not planned. `order` and
/// `max_evaluations` are the options', `seconds` the wall time. One line.
[[nodiscard]] std::string result_json(const PlanResult& r, int order, int max_evaluations, double seconds);

/// The QP at the chosen durations: P, q, A_eq, b_eq, A_in, b_in, constant,
/// the variables' names and each constraint row's group. Ends in a newline.
[[nodiscard]] std::string qp_json(const QpProblem& qp);

/// One row every 1 ms from t = 0 to the last whole millisecond: pad-frame
/// position, velocity, acceleration and world-frame velocity and
/// acceleration (the pad's motion `pad`). About 220 bytes a row.
[[nodiscard]] std::string samples_csv(const PiecewiseBezier& curve, const PadMotion& pad);

/// The summary landing_plan prints: status, cost and durations, the
/// conflicts, the corridor, the time allocation's and final QP's effort and
/// the total time (`seconds`). `path` names the problem.
[[nodiscard]] std::string summary(std::string_view path, const PlanProblem& problem, const PlanResult& r,
                                  double seconds);

/// The figure's title: the problem file's name, the status (with the
/// conflicts) and, when planned, cost and duration.
[[nodiscard]] std::string plot_title(std::string_view problem_path, const PlanResult& r);

/// The figure (SVG): top, side and rear views in the pad frame with the
/// trajectory, the corridor, obstacles, field of view, start and `goal`; the
/// world-frame velocity and acceleration per axis against the limits.
[[nodiscard]] std::string plot_svg(const PlanProblem& problem, const PlanResult& result, const KinematicState& goal,
                                   const std::string& title);

}  // namespace touchdown::plan
