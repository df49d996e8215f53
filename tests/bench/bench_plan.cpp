// Landing trajectory benchmarks (issue 10; docs/benchmarks.md): one QP of
// the bundled problem (order 7, 2 segments, corridor + limits) by our
// Goldfarb–Idnani solver and by NLopt's SLSQP, the planner's QP per set of
// durations, the time allocation against the published 31 × 31 grid, the
// corridor, and a whole plan.
//
//   build/tests/bench/bench_plan --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <Eigen/QR>
#include <nlopt.hpp>

#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"
#include "touchdown/plan/qp.hpp"

namespace tp = touchdown::plan;

namespace {

const tp::PlanProblem& problem() {
  static const tp::PlanProblem kProblem = tp::load_plan_problem(TOUCHDOWN_SOURCE_DIR "/data/plans/landing.yaml");
  return kProblem;
}

const tp::PlanResult& reference() {
  static const tp::PlanResult kResult = [] {
    tp::PlannerOptions o = problem().options;
    o.export_qp = true;
    return tp::plan(problem().start, problem().goal, problem().pad, o);
  }();
  return kResult;
}

// The bundled problem with tight limits (v_max 2.5 m/s over ground while the
// pad drives at 2 m/s, a_max 1 m/s², ρ = 5 for shorter durations): its QP at
// the allocated durations has active acceleration and velocity rows.
const tp::PlanResult& tight() {
  static const tp::PlanResult kResult = [] {
    tp::PlannerOptions o = problem().options;
    o.v_max = 2.5;
    o.a_max = 1.0;
    o.time.rho = 5.0;
    o.export_qp = true;
    return tp::plan(problem().start, problem().goal, problem().pad, o);
  }();
  return kResult;
}

const tp::QpProblem& bench_qp(int variant) { return variant == 0 ? reference().qp : tight().qp; }

tp::KinematicState goal() { return problem().goal ? *problem().goal : tp::default_goal(problem().options); }

// The full 48-variable QP at the chosen durations, as exported by
// --export-qp (P is only semidefinite: the solver eliminates the 27
// equalities, then solves the 21-variable rest). Arguments: problem
// (0 bundled, 1 tight limits), warm start.
void BM_QpGoldfarbIdnani(benchmark::State& state) {
  const tp::QpProblem& qp = bench_qp(static_cast<int>(state.range(0)));
  tp::QpSolver solver;
  const bool warm = state.range(1) != 0;
  (void)solver.solve(qp.P, qp.q, qp.A_eq, qp.b_eq, qp.A_in, qp.b_in);
  for (auto _ : state) {
    benchmark::DoNotOptimize(solver.solve(qp.P, qp.q, qp.A_eq, qp.b_eq, qp.A_in, qp.b_in, warm));
  }
  state.counters["iterations"] = solver.iterations();
  state.counters["active"] = static_cast<double>(solver.active_set().size());
  state.counters["variables"] = static_cast<double>(qp.P.rows());
  state.counters["inequalities"] = static_cast<double>(qp.A_in.rows());
  state.counters["cost"] = solver.objective() + qp.constant;
}
BENCHMARK(BM_QpGoldfarbIdnani)->Args({0, 0})->Args({0, 1})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMicrosecond);

// The same QP with its equalities eliminated (x = x₀ + Z y, Z a basis of
// A_eq's null space from a QR, set up outside the timing): 21 variables,
// the inequalities only — the size of the QP the planner solves per set
// of durations (it eliminates the equalities in closed form instead).
void BM_QpReduced(benchmark::State& state) {
  const tp::QpProblem& qp = bench_qp(static_cast<int>(state.range(0)));
  const Eigen::Index n = qp.P.rows(), me = qp.A_eq.rows();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(qp.A_eq.transpose());
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd Z = Q.rightCols(n - me);
  const Eigen::VectorXd x0 = qp.A_eq.colPivHouseholderQr().solve(qp.b_eq);
  const Eigen::MatrixXd P = Z.transpose() * qp.P * Z;
  const Eigen::VectorXd q = Z.transpose() * (qp.P * x0 + qp.q);
  const Eigen::MatrixXd A = qp.A_in * Z;
  const Eigen::VectorXd b = qp.b_in - qp.A_in * x0;
  tp::QpSolver solver;
  const bool warm = state.range(1) != 0;
  (void)solver.solve(P, q, Eigen::MatrixXd(0, n - me), Eigen::VectorXd(0), A, b);
  for (auto _ : state) {
    benchmark::DoNotOptimize(solver.solve(P, q, Eigen::MatrixXd(0, n - me), Eigen::VectorXd(0), A, b, warm));
  }
  const Eigen::VectorXd x = x0 + Z * solver.x();
  state.counters["cost"] = 0.5 * x.dot(qp.P * x) + qp.q.dot(x);
  state.counters["iterations"] = solver.iterations();
  state.counters["variables"] = static_cast<double>(n - me);
}
BENCHMARK(BM_QpReduced)->Args({0, 0})->Args({0, 1})->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMicrosecond);

struct SlsqpRow {
  const tp::QpProblem* qp;
  Eigen::Index row;
};
double slsqp_f(unsigned n, const double* x, double* grad, void* data) {
  const auto* qp = static_cast<const tp::QpProblem*>(data);
  const Eigen::Map<const Eigen::VectorXd> xv(x, n);
  const Eigen::VectorXd g = qp->P * xv + qp->q;
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = g;
  return 0.5 * xv.dot(qp->P * xv) + qp->q.dot(xv);
}
double slsqp_eq(unsigned n, const double* x, double* grad, void* data) {
  const auto* r = static_cast<const SlsqpRow*>(data);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = r->qp->A_eq.row(r->row).transpose();
  return r->qp->A_eq.row(r->row).dot(Eigen::Map<const Eigen::VectorXd>(x, n)) - r->qp->b_eq(r->row);
}
double slsqp_in(unsigned n, const double* x, double* grad, void* data) {
  const auto* r = static_cast<const SlsqpRow*>(data);
  if (grad) Eigen::Map<Eigen::VectorXd>(grad, n) = r->qp->A_in.row(r->row).transpose();
  return r->qp->A_in.row(r->row).dot(Eigen::Map<const Eigen::VectorXd>(x, n)) - r->qp->b_in(r->row);
}

// NLopt's SLSQP on the same QP, from the same cold start (x = 0).
// Argument: problem (0 bundled, 1 tight limits).
void BM_QpSlsqp(benchmark::State& state) {
  const tp::QpProblem& qp = bench_qp(static_cast<int>(state.range(0)));
  const auto n = static_cast<unsigned>(qp.P.rows());
  std::vector<SlsqpRow> eq, in;
  for (Eigen::Index r = 0; r < qp.A_eq.rows(); ++r) eq.push_back({&qp, r});
  for (Eigen::Index r = 0; r < qp.A_in.rows(); ++r) in.push_back({&qp, r});
  double f = 0;
  for (auto _ : state) {
    nlopt::opt opt(nlopt::LD_SLSQP, n);
    opt.set_min_objective(slsqp_f, const_cast<tp::QpProblem*>(&qp));
    for (auto& r : eq) opt.add_equality_constraint(slsqp_eq, &r, 1e-9);
    for (auto& r : in) opt.add_inequality_constraint(slsqp_in, &r, 1e-9);
    opt.set_xtol_rel(1e-10);
    opt.set_maxeval(5000);
    std::vector<double> x(n, 0.0);
    try {
      opt.optimize(x, f);
    } catch (const std::exception&) {
    }
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["cost"] = f + qp.constant;
  state.counters["our_cost"] = (state.range(0) == 0 ? reference() : tight()).cost;
}
BENCHMARK(BM_QpSlsqp)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// What one time-allocation evaluation costs: the planner's QP at fixed
// durations (rows, elimination of the equalities, the reduced QP).
void BM_PlanFixedDurations(benchmark::State& state) {
  tp::PlannerOptions o = problem().options;
  for (int k = 0; k < reference().trajectory.segments(); ++k) o.durations.push_back(reference().trajectory.duration(k));
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        tp::plan_in_corridor(problem().start, goal(), problem().pad, o, reference().segment_polytopes));
  }
}
BENCHMARK(BM_PlanFixedDurations)->Unit(benchmark::kMicrosecond);

void BM_TimeAllocation(benchmark::State& state) {
  double objective = 0;
  int evaluations = 0;
  for (auto _ : state) {
    const tp::PlanResult r =
        tp::plan_in_corridor(problem().start, goal(), problem().pad, problem().options, reference().segment_polytopes);
    objective = r.objective;
    evaluations = r.evaluations;
  }
  state.counters["objective"] = objective;
  state.counters["evaluations"] = evaluations;
}
BENCHMARK(BM_TimeAllocation)->Unit(benchmark::kMillisecond);

// The published method's offline grid: 31 × 31 durations over the same bounds.
void BM_Grid961(benchmark::State& state) {
  const tp::PlannerOptions& base = problem().options;
  double best = INFINITY;
  for (auto _ : state) {
    best = INFINITY;
    for (int i = 0; i < 31; ++i) {
      for (int j = 0; j < 31; ++j) {
        tp::PlannerOptions o = base;
        o.durations = {base.time.min + (base.time.max - base.time.min) * i / 30.0,
                       base.time.min + (base.time.max - base.time.min) * j / 30.0};
        const tp::PlanResult r =
            tp::plan_in_corridor(problem().start, goal(), problem().pad, o, reference().segment_polytopes);
        if (r.ok()) best = std::min(best, r.objective);
      }
    }
  }
  state.counters["objective"] = best;
}
BENCHMARK(BM_Grid961)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Corridor(benchmark::State& state) {
  const tp::PlannerOptions& o = problem().options;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tp::build_corridor(problem().start.p, goal().p, o.obstacles, *o.corridor));
  }
}
BENCHMARK(BM_Corridor)->Unit(benchmark::kMillisecond);

void BM_PlanWhole(benchmark::State& state) {
  for (auto _ : state) {
    benchmark::DoNotOptimize(tp::plan(problem().start, problem().goal, problem().pad, problem().options));
  }
}
BENCHMARK(BM_PlanWhole)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
