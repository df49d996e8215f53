// Landing trajectory planner (planner.hpp): the minimum-jerk piecewise
// Bézier QP in the moving pad's frame, its world-frame limits, the online
// time allocation and the diagnosis of infeasible problems.
#include "touchdown/plan/planner.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <nlopt.hpp>

#include "core/format.hpp"
#include "plan/qp_builder.hpp"
#include "touchdown/core/batch.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/plan/qp.hpp"

namespace touchdown::plan {

namespace {

using assembly::OrderTables;
using assembly::QpBuilder;
using assembly::rot2;

bool finite(const KinematicState& s) { return s.p.allFinite() && s.v.allFinite() && s.a.allFinite(); }

using Clock = std::chrono::steady_clock;
double micros_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
}

// Solves the reduced QP of a set of durations (QpBuilder::reduce) and maps
// the answer back to the control points.
class ReducedRunner {
 public:
  explicit ReducedRunner(const QpBuilder& builder) : builder_(builder) {}
  QpStatus solve(const std::vector<double>& T, bool warm, int skip_group = -1) {
    builder_.reduce(T, r_, skip_group);
    const int F = r_.F;
    y_.setZero(3 * F);
    if (F == 0) {  // every control point fixed: feasible or not
      status_ = (r_.b.size() == 0 || r_.b.minCoeff() >= -1e-9) ? QpStatus::Optimal : QpStatus::Infeasible;
      iterations_ = 0;
    } else {
      status_ = solver_.solve(r_.P, r_.q, Eigen::MatrixXd(0, 3 * F), Eigen::VectorXd(0), r_.A, r_.b, warm);
      iterations_ = solver_.iterations();
      y_ = solver_.x();
    }
    return status_;
  }
  int iterations() const { return iterations_; }
  // The control points of the last solution, one per entry (no allocation
  // when `out` has the size already).
  void control_points_into(std::vector<Eigen::Vector3d>& out) const {
    const auto M = r_.C.rows();
    out.resize(static_cast<std::size_t>(M));
    for (Eigen::Index m = 0; m < M; ++m) {
      for (int a = 0; a < 3; ++a) {
        out[static_cast<std::size_t>(m)](a) =
            r_.c0(m, a) + (r_.F > 0 ? r_.C.row(m).dot(y_.segment(a * r_.F, r_.F)) : 0.0);
      }
    }
  }
  // Control points (segment, point, axis) of the last solution.
  Eigen::VectorXd control_points() const {
    const auto M = r_.C.rows();
    Eigen::VectorXd x(3 * M);
    for (Eigen::Index m = 0; m < M; ++m) {
      for (int a = 0; a < 3; ++a) {
        x(3 * m + a) = r_.c0(m, a) + (r_.F > 0 ? r_.C.row(m).dot(y_.segment(a * r_.F, r_.F)) : 0.0);
      }
    }
    return x;
  }

 private:
  const QpBuilder& builder_;
  QpBuilder::Reduced r_;
  QpSolver solver_;
  Eigen::VectorXd y_;
  QpStatus status_ = QpStatus::Infeasible;
  int iterations_ = 0;
};

PiecewiseBezier curve_from(const Eigen::VectorXd& x, int order, const std::vector<double>& T) {
  std::vector<Eigen::Vector3d> cps(static_cast<std::size_t>(x.size() / 3));
  for (std::size_t i = 0; i < cps.size(); ++i) {
    cps[i] = x.segment<3>(static_cast<Eigen::Index>(3 * i));
  }
  return PiecewiseBezier(order, T, std::move(cps));
}

// The heuristic first guess of the durations: distance over a third of the
// speed limit, split by the lengths of the legs through the corridor's
// junction (the Chebyshev centre of the parts' overlap) when there is one.
std::vector<double> initial_durations(const KinematicState& start, const KinematicState& goal, const PlannerOptions& o,
                                      const std::vector<Polytope>& polytopes) {
  std::vector<double> T(static_cast<std::size_t>(o.segments));
  const double total = std::max(2.0 * (goal.p - start.p).norm() / o.v_max + 1.0, o.segments * o.time.min);
  std::vector<double> legs(T.size(), 1.0);
  if (polytopes.size() >= 2) {
    Polytope overlap = polytopes[polytopes.size() - 2];
    overlap.intersect(polytopes.back());
    const ChebyshevBall ball = chebyshev_ball(overlap);
    if (ball.radius > 0) {
      const double a = (ball.centre - start.p).norm(), b = (goal.p - ball.centre).norm();
      std::fill(legs.begin(), legs.end() - 1, std::max(a, 0.1) / static_cast<double>(legs.size() - 1));
      legs.back() = std::max(b, 0.1);
    }
  }
  double sum = 0;
  for (const double l : legs) sum += l;
  for (std::size_t k = 0; k < T.size(); ++k) T[k] = std::clamp(total * legs[k] / sum, o.time.min, o.time.max);
  return T;
}

struct Allocation {
  std::vector<double> T;
  double objective = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  bool cap_reached = false;
};

// J(T) + ρ ΣT for feasible durations; infeasible ones get a penalty above
// every feasible value that falls as the durations grow (slower is more
// often within the limits), so the search walks out of the infeasible set.
struct AllocationContext {
  ReducedRunner* runner;
  const PlannerOptions* o;
  Allocation* best;
  std::vector<double> T;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

constexpr double kPenalty = 1e12;

// One evaluation; at the cap it solves nothing, records that the cap was
// reached and stops the local search (NLopt's own maxeval is not trusted to
// count the same way).
double allocation_objective(unsigned n, const double* x, double* /*grad*/, void* data) {
  auto* c = static_cast<AllocationContext*>(data);
  if (c->best->evaluations >= c->o->time.max_evaluations) {
    c->best->cap_reached = true;
    throw nlopt::forced_stop();
  }
  for (unsigned k = 0; k < n; ++k) c->T[k] = std::clamp(x[k], c->o->time.min, c->o->time.max);
  ++c->best->evaluations;
  const QpStatus status = c->runner->solve(c->T, true);
  double sum = 0;
  for (const double t : c->T) sum += t;
  double value;
  if (status == QpStatus::Optimal) {
    value = curve_from(c->runner->control_points(), c->o->order, c->T).jerk_cost() + c->o->time.rho * sum;
  } else {
    value = kPenalty * (1 + c->o->segments * c->o->time.max - sum);
  }
  if (value < c->best->objective) {
    c->best->objective = value;
    c->best->T = c->T;
  }
  if (c->o->progress) {
    const auto done = static_cast<std::size_t>(c->best->evaluations);
    c->o->progress(progress_since(c->start, done, static_cast<std::size_t>(c->o->time.max_evaluations), done - 1));
  }
  return value;
}

// The coarse grid: 4 log-spaced durations per segment (short durations
// matter most), so that the local search starts in the best basin.
void evaluate_grid(unsigned s, AllocationContext& ctx) {
  const TimeAllocationOptions& t = ctx.o->time;
  const int per = 4;
  int total = 1;
  for (unsigned k = 0; k < s; ++k) total *= per;
  std::vector<double> g(s);
  for (int idx = 0; idx < total; ++idx) {
    int rest = idx;
    for (unsigned k = 0; k < s; ++k) {
      const int m = rest % per;
      rest /= per;
      g[k] = t.min * std::pow(t.max / t.min, (m + 0.5) / per);
    }
    allocation_objective(s, g.data(), nullptr, &ctx);
  }
}

// Every QP solve counts against time.max_evaluations: the grid (4^s points,
// up to 3 segments) runs only when it fits with the guess, then the guess,
// then the local search with what is left.
Allocation allocate_time(const QpBuilder& builder, const PlannerOptions& o, const std::vector<double>& guess) {
  ReducedRunner runner(builder);
  Allocation best;
  AllocationContext ctx{&runner, &o, &best, guess};
  const auto s = static_cast<unsigned>(o.segments);
  if (s <= 3) {
    const int grid = 1 << (2 * s);  // 4^s
    if (o.time.max_evaluations >= grid + 1) {
      evaluate_grid(s, ctx);
    } else {
      best.cap_reached = true;  // the grid did not fit
    }
  }
  allocation_objective(s, guess.data(), nullptr, &ctx);
  if (best.evaluations >= o.time.max_evaluations) {
    best.cap_reached = true;  // no solve left for the local search
    return best;
  }
  std::vector<double> x = best.T;
  nlopt::opt opt(s >= 2 ? nlopt::LN_BOBYQA : nlopt::LN_SBPLX, s);
  opt.set_lower_bounds(std::vector<double>(s, o.time.min));
  opt.set_upper_bounds(std::vector<double>(s, o.time.max));
  opt.set_min_objective(allocation_objective, &ctx);
  opt.set_xtol_rel(1e-4);
  // One more than is left: the objective stops the search at the cap and
  // records it (a search that ends by itself on its last solve did not hit it).
  opt.set_maxeval(o.time.max_evaluations - best.evaluations + 1);
  std::vector<double> step(s);
  for (unsigned k = 0; k < s; ++k) step[k] = std::min(0.25 * (o.time.max - o.time.min), std::max(0.1, 0.2 * x[k]));
  opt.set_initial_step(step);
  double f = 0;
  try {
    if (opt.optimize(x, f) == nlopt::MAXEVAL_REACHED) best.cap_reached = true;
  } catch (const std::exception&) {
    // NLopt's stops (round-off, bounds, the cap) keep the best point, which ctx tracked.
  }
  return best;
}

std::vector<ConstraintGroup> diagnose(const QpBuilder& builder, const std::vector<double>& T, bool corridor) {
  std::vector<ConstraintGroup> groups = {ConstraintGroup::Boundary, ConstraintGroup::Velocity,
                                         ConstraintGroup::Acceleration};
  if (corridor) groups.insert(groups.begin() + 1, ConstraintGroup::Corridor);
  std::vector<ConstraintGroup> conflicts;
  ReducedRunner runner(builder);
  for (const ConstraintGroup g : groups) {
    if (runner.solve(T, false, static_cast<int>(g)) == QpStatus::Optimal) conflicts.push_back(g);
  }
  return conflicts;
}

}  // namespace

Eigen::Vector3d PadMotion::position(double t) const {
  const Eigen::Vector2d vb = rot2(yaw).transpose() * velocity.head<2>();
  Eigen::Vector2d xy;
  if (yaw_rate == 0) {
    xy = velocity.head<2>() * t;
  } else {
    // ∫ R_z(θ) dθ = [[sin θ, cos θ], [−cos θ, sin θ]].
    auto M = [](double th) {
      Eigen::Matrix2d m;
      m << std::sin(th), std::cos(th), -std::cos(th), std::sin(th);
      return m;
    };
    xy = (M(heading(t)) - M(yaw)) * vb / yaw_rate;
  }
  return {xy.x(), xy.y(), velocity.z() * t};
}

Eigen::Vector3d PadMotion::world_velocity(double t) const {
  const Eigen::Vector2d xy = rot2(heading(t)) * rot2(yaw).transpose() * velocity.head<2>();
  return {xy.x(), xy.y(), velocity.z()};
}

KinematicState PadMotion::to_world(double t, const KinematicState& rel) const {
  const Eigen::Vector2d vb2 = rot2(yaw).transpose() * velocity.head<2>();
  const Eigen::Vector3d vb(vb2.x(), vb2.y(), velocity.z());
  const Eigen::Vector3d w(0, 0, yaw_rate);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = rot2(heading(t));
  KinematicState out;
  out.p = position(t) + R * rel.p;
  out.v = R * (vb + rel.v + w.cross(rel.p));
  out.a = R * (rel.a + 2 * w.cross(rel.v) + w.cross(w.cross(rel.p)) + w.cross(vb));
  return out;
}

bool PlannerOptions::validate(std::string* why) const {
  if (order < 5 || order > 20) return invalid(why, "order: must be in [5, 20], got " + std::to_string(order));
  if (segments < 1 || segments > 16)
    return invalid(why, "segments: must be in [1, 16], got " + std::to_string(segments));
  if (corridor && segments < 2) return invalid(why, "segments: a corridor needs at least 2 segments");
  if (!(v_max > 0) || !std::isfinite(v_max)) return invalid(why, "limits.v_max: must be > 0 and finite");
  if (!(a_max > 0) || !std::isfinite(a_max)) return invalid(why, "limits.a_max: must be > 0 and finite");
  if (!durations.empty()) {
    if (static_cast<int>(durations.size()) != segments) {
      return invalid(why, "durations: need one per segment (" + std::to_string(segments) + "), got " +
                              std::to_string(durations.size()));
    }
    for (std::size_t k = 0; k < durations.size(); ++k) {
      if (!(durations[k] >= kMinSegmentDuration && durations[k] <= kMaxSegmentDuration)) {
        return invalid(why, "durations[" + std::to_string(k) + "]: must be in [0.001, 1000] s");
      }
    }
  }
  if (!(time.min >= kMinSegmentDuration) || !(time.max <= kMaxSegmentDuration) || !(time.max > time.min)) {
    return invalid(why, "time: need 0.001 <= min < max <= 1000 s");
  }
  if (!(time.rho >= 0) || !std::isfinite(time.rho)) return invalid(why, "time.rho: must be >= 0 and finite");
  if (time.max_evaluations < 1) return invalid(why, "time.max_evaluations: must be >= 1");
  if (corridor && !corridor->validate(why)) return false;
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    const Box& b = obstacles[i];
    if (!b.min.allFinite() || !b.max.allFinite() || (b.min.array() > b.max.array()).any()) {
      return invalid(why, "obstacles[" + std::to_string(i) + "]: min must not exceed max (finite)");
    }
  }
  return true;
}

std::vector<std::string> QpProblem::variable_names() const {
  std::vector<std::string> names;
  const char* axes = "xyz";
  for (int k = 0; k < segments; ++k) {
    for (int i = 0; i <= order; ++i) {
      for (int a = 0; a < 3; ++a) names.push_back("s" + std::to_string(k) + ".c" + std::to_string(i) + "." + axes[a]);
    }
  }
  return names;
}

KinematicState default_goal(const PlannerOptions& options) {
  KinematicState g;
  g.p = Eigen::Vector3d(0, 0, options.corridor ? options.corridor->h_touchdown : 0.5);
  return g;
}

PlanResult plan(const KinematicState& start, const std::optional<KinematicState>& goal_in, const PadMotion& pad,
                const PlannerOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!finite(start)) throw InvalidArgument("start: every value must be finite");
  if (goal_in && !finite(*goal_in)) throw InvalidArgument("goal: every value must be finite");
  const KinematicState goal = goal_in ? *goal_in : default_goal(options);
  if (!options.corridor) return plan_in_corridor(start, goal, pad, options, {});
  Corridor corridor = build_corridor(start.p, goal.p, options.obstacles, *options.corridor);
  if (corridor.status == CorridorStatus::StartBlocked) {
    throw InvalidArgument("start.p: outside the corridor: " + corridor.message);
  }
  if (corridor.status == CorridorStatus::GoalBlocked) {
    throw InvalidArgument("goal.p: outside the corridor: " + corridor.message);
  }
  if (!corridor.ok()) {
    PlanResult result;
    result.status = PlanStatus::NoCorridor;
    result.message = std::string(to_string(corridor.status)) + ": " + corridor.message;
    result.corridor = std::move(corridor);
    return result;
  }
  PlanResult result = plan_in_corridor(start, goal, pad, options, corridor.per_segment(options.segments));
  result.corridor = std::move(corridor);
  return result;
}

PlanResult plan_in_corridor(const KinematicState& start, const KinematicState& goal, const PadMotion& pad,
                            const PlannerOptions& options, const std::vector<Polytope>& segment_polytopes) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!finite(start)) throw InvalidArgument("start: every value must be finite");
  if (!finite(goal)) throw InvalidArgument("goal: every value must be finite");
  if (!pad.velocity.allFinite() || !std::isfinite(pad.yaw_rate) || !std::isfinite(pad.yaw)) {
    throw InvalidArgument("pad: every value must be finite");
  }
  if (!segment_polytopes.empty()) {
    if (static_cast<int>(segment_polytopes.size()) != options.segments) {
      throw InvalidArgument("corridor: need one polytope per segment (" + std::to_string(options.segments) + "), got " +
                            std::to_string(segment_polytopes.size()));
    }
    if (!segment_polytopes.front().contains(start.p, 1e-9)) throw InvalidArgument("start.p: outside the corridor");
    if (!segment_polytopes.back().contains(goal.p, 1e-9)) throw InvalidArgument("goal.p: outside the corridor");
  }
  PlanResult result;
  result.segment_polytopes = segment_polytopes;
  const QpBuilder builder(start, goal, pad, options, result.segment_polytopes);
  std::vector<double> T = options.durations;
  if (T.empty()) {
    const auto t0 = Clock::now();
    const Allocation a =
        allocate_time(builder, options, initial_durations(start, goal, options, result.segment_polytopes));
    result.allocation_ms = micros_since(t0) / 1000;
    result.evaluations = a.evaluations;
    result.evaluation_cap_reached = a.cap_reached;
    T = a.T;
    if (a.cap_reached && !(a.objective < kPenalty)) {
      // No feasible durations seen before the cap: the problem is not shown
      // infeasible, so neither a diagnosis nor more solves.
      result.status = PlanStatus::AllocationCutShort;
      result.message = "the time allocation reached time.max_evaluations (" +
                       detail::count_noun(options.time.max_evaluations, "QP") +
                       ") before it found feasible durations; raise time.max_evaluations";
      return result;
    }
  }
  if (options.export_qp) builder.build(T, result.qp);
  ReducedRunner runner(builder);
  const auto t1 = Clock::now();
  const QpStatus status = runner.solve(T, false);
  result.qp_us = micros_since(t1);
  result.qp_iterations = runner.iterations();
  if (status != QpStatus::Optimal) {
    result.status = PlanStatus::Infeasible;
    result.conflicts = diagnose(builder, T, options.corridor.has_value());
    result.message = "QP " + std::string(to_string(status)) + " at durations";
    for (const double t : T) result.message += " " + std::to_string(t);
    if (!result.conflicts.empty()) {
      result.message += "; feasible without:";
      for (const ConstraintGroup g : result.conflicts) result.message += " " + std::string(to_string(g));
    } else {
      result.message += "; no single constraint group restores feasibility";
    }
    result.trajectory = curve_from(runner.control_points(), options.order, T);
    return result;
  }
  result.status = PlanStatus::Ok;
  result.trajectory = curve_from(runner.control_points(), options.order, T);
  result.cost = result.trajectory.jerk_cost();
  double sum = 0;
  for (const double t : T) sum += t;
  result.objective = result.cost + options.time.rho * sum;
  return result;
}

struct Replanner::Impl {
  Impl(PlannerOptions o, std::vector<Polytope> p)
      : options(std::move(o)), polytopes(std::move(p)), builder({}, {}, {}, options, polytopes), runner(builder) {}
  PlannerOptions options;
  std::vector<Polytope> polytopes;
  QpBuilder builder;
  ReducedRunner runner;
  std::vector<double> T;
  std::vector<Eigen::Vector3d> control_points;
  PiecewiseBezier trajectory;
  double cost = 0;
};

Replanner::Replanner(PlannerOptions options, std::vector<Polytope> segment_polytopes) {
  options.durations.clear();
  options.export_qp = false;
  options.progress = nullptr;
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument(why);
  if (!segment_polytopes.empty() && static_cast<int>(segment_polytopes.size()) != options.segments) {
    throw InvalidArgument("corridor: need one polytope per segment (" + std::to_string(options.segments) + "), got " +
                          std::to_string(segment_polytopes.size()));
  }
  impl_ = std::make_unique<Impl>(std::move(options), std::move(segment_polytopes));
  impl_->T.resize(static_cast<std::size_t>(impl_->options.segments));
}

Replanner::~Replanner() = default;
Replanner::Replanner(Replanner&&) noexcept = default;
Replanner& Replanner::operator=(Replanner&&) noexcept = default;

PlanStatus Replanner::plan(const KinematicState& start, const KinematicState& goal, const PadMotion& pad,
                           std::span<const double> durations) {
  Impl& m = *impl_;
  if (durations.size() != m.T.size() || !finite(start) || !finite(goal) || !pad.velocity.allFinite() ||
      !std::isfinite(pad.yaw_rate) || !std::isfinite(pad.yaw)) {
    return PlanStatus::Infeasible;
  }
  for (std::size_t k = 0; k < durations.size(); ++k) {
    if (!(durations[k] >= kMinSegmentDuration && durations[k] <= kMaxSegmentDuration)) return PlanStatus::Infeasible;
    m.T[k] = durations[k];
  }
  if (!m.polytopes.empty() &&
      (!m.polytopes.front().contains(start.p, 1e-9) || !m.polytopes.back().contains(goal.p, 1e-9))) {
    return PlanStatus::NoCorridor;
  }
  m.builder.set(start, goal, pad);
  if (m.runner.solve(m.T, false) != QpStatus::Optimal) return PlanStatus::Infeasible;
  m.runner.control_points_into(m.control_points);
  m.trajectory.assign(m.options.order, m.T, m.control_points);
  // The jerk cost, Σ_k cᵀ Q(1) c / T_k⁵ (PiecewiseBezier::jerk_cost()
  // builds Q per segment, which allocates).
  const int n = m.options.order;
  const Eigen::MatrixXd& Q = m.builder.jerk();
  m.cost = 0;
  for (std::size_t k = 0; k < m.T.size(); ++k) {
    const Eigen::Vector3d* c = m.control_points.data() + k * static_cast<std::size_t>(n + 1);
    double segment = 0;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) segment += Q(i, j) * c[i].dot(c[j]);
    }
    m.cost += segment / std::pow(m.T[k], 5);
  }
  return PlanStatus::Ok;
}

const PiecewiseBezier& Replanner::trajectory() const { return impl_->trajectory; }
double Replanner::cost() const { return impl_->cost; }
int Replanner::iterations() const { return impl_->runner.iterations(); }
const std::vector<Polytope>& Replanner::segment_polytopes() const { return impl_->polytopes; }
const PlannerOptions& Replanner::options() const { return impl_->options; }

}  // namespace touchdown::plan
