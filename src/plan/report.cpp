// landing_plan's outputs (docs/cli.md, "landing_plan"): the result and the
// QP as JSON, the sampled trajectory as CSV, the summary and the plot's title.
#include "touchdown/plan/report.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/format.hpp"
#include "core/json_number.hpp"

namespace touchdown::plan {

namespace {

// Keys in the order documented (docs/cli.md), not sorted.
using Json = nlohmann::ordered_json;
using detail::format_fixed;
using detail::round3;

Json matrix_json(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(std::move(row));
  }
  return rows;
}

Json vector_json(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

Json groups_json(const std::vector<ConstraintGroup>& groups) {
  Json out = Json::array();
  for (const auto g : groups) out.push_back(to_string(g));
  return out;
}

}  // namespace

std::string result_json(const PlanResult& r, int order, int max_evaluations, double seconds) {
  Json j;
  j["status"] = to_string(r.status);
  j["cost"] = r.cost;
  j["objective"] = r.objective;
  j["order"] = order;
  Json segments = Json::array();
  if (r.ok()) {
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      Json cps = Json::array();
      for (const auto& c : r.trajectory.control_points(k)) cps.push_back({c.x(), c.y(), c.z()});
      segments.push_back({{"duration", r.trajectory.duration(k)}, {"control_points", std::move(cps)}});
    }
  }
  j["segments"] = std::move(segments);
  Json corridor = Json::array();
  for (const auto& p : r.segment_polytopes) corridor.push_back({{"A", matrix_json(p.A)}, {"b", vector_json(p.b)}});
  j["corridor"] = std::move(corridor);
  j["time_allocation"] = {{"evaluations", r.evaluations},
                          {"max_evaluations", max_evaluations},
                          {"cap_reached", r.evaluation_cap_reached},
                          {"ms", round3(r.allocation_ms)}};
  j["qp"] = {{"iterations", r.qp_iterations}, {"us", round3(r.qp_us)}};
  j["seconds"] = std::round(seconds * 1e6) / 1e6;
  if (r.status == PlanStatus::Infeasible) j["conflicts"] = groups_json(r.conflicts);
  if (!r.ok()) j["message"] = r.message;
  return j.dump();
}

std::string qp_json(const QpProblem& qp) {
  Json j;
  j["P"] = matrix_json(qp.P);
  j["q"] = vector_json(qp.q);
  j["A_eq"] = matrix_json(qp.A_eq);
  j["b_eq"] = vector_json(qp.b_eq);
  j["A_in"] = matrix_json(qp.A_in);
  j["b_in"] = vector_json(qp.b_in);
  j["constant"] = qp.constant;
  j["variables"] = qp.variable_names();
  j["eq_groups"] = groups_json(qp.eq_groups);
  j["in_groups"] = groups_json(qp.in_groups);
  return j.dump() + "\n";
}

// Rows every 1 ms from t = 0 to the last whole millisecond of the trajectory.
std::string samples_csv(const PiecewiseBezier& curve, const PadMotion& pad) {
  std::string out = "t,px,py,pz,vx,vy,vz,ax,ay,az,world_vx,world_vy,world_vz,world_ax,world_ay,world_az\n";
  const auto n = static_cast<long>(std::floor(curve.total_duration() * 1000 + 1e-6));
  char buf[512];
  for (long i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / 1000;
    KinematicState s;
    s.p = curve.evaluate(t, 0);
    s.v = curve.evaluate(t, 1);
    s.a = curve.evaluate(t, 2);
    const KinematicState w = pad.to_world(t, s);
    std::snprintf(buf, sizeof(buf), "%.3f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
                  t, s.p.x(), s.p.y(), s.p.z(), s.v.x(), s.v.y(), s.v.z(), s.a.x(), s.a.y(), s.a.z(), w.v.x(), w.v.y(),
                  w.v.z(), w.a.x(), w.a.y(), w.a.z());
    out += buf;
  }
  return out;
}

// The plot's title: the problem file, the status and, when planned, cost and duration.
std::string plot_title(std::string_view problem_path, const PlanResult& r) {
  std::string title = "landing_plan: " + std::filesystem::path(problem_path).filename().string() + ": " +
                      std::string(to_string(r.status));
  if (r.status == PlanStatus::Infeasible && !r.conflicts.empty()) {
    title += " (feasible without:";
    for (const auto g : r.conflicts) title += " " + std::string(to_string(g));
    title += ")";
  }
  if (r.ok()) {
    title += ", cost " + format_fixed(r.cost, 3) +
             " m\u00b2/s\u2075, T = " + format_fixed(r.trajectory.total_duration(), 2) + " s";
  }
  return title;
}

std::string summary(std::string_view path, const PlanProblem& pb, const PlanResult& r, double seconds) {
  std::ostringstream os;
  os << "landing_plan: " << path << ": " << to_string(r.status) << "\n";
  if (r.ok()) {
    double sum = 0;
    std::string parts;
    for (int k = 0; k < r.trajectory.segments(); ++k) {
      sum += r.trajectory.duration(k);
      parts += (k ? " + " : "") + format_fixed(r.trajectory.duration(k), 3);
    }
    os << "  cost          " << format_fixed(r.cost, 4) << " m^2/s^5 (integral of squared jerk); objective "
       << format_fixed(r.objective, 4) << " = cost + rho * sum T\n"
       << "  durations     " << parts << " = " << format_fixed(sum, 3) << " s ("
       << detail::count_noun(r.trajectory.segments(), "segment") << " of order " << r.trajectory.order() << ")\n";
  } else if (!r.message.empty()) {
    os << "  message       " << r.message << "\n";
  }
  if (r.status == PlanStatus::Infeasible) {
    std::string names;
    for (const auto g : r.conflicts) names += (names.empty() ? "" : ", ") + std::string(to_string(g));
    os << "  conflicts     " << (names.empty() ? "none alone (no single group restores feasibility)" : names)
       << (names.empty() ? "" : " (feasible without it)") << "\n";
  }
  if (pb.options.corridor) {
    if (r.corridor.ok()) {
      os << "  corridor      rear " << r.corridor.rear.faces() << " faces, touchdown " << r.corridor.touchdown.faces()
         << " faces, " << r.corridor.dilations << " dilation" << (r.corridor.dilations == 1 ? "" : "s") << "\n";
    } else {
      os << "  corridor      " << to_string(r.corridor.status) << "\n";
    }
  }
  if (r.status != PlanStatus::NoCorridor) {  // else nothing was solved
    if (pb.options.durations.empty()) {
      os << "  time alloc    " << detail::count_noun(r.evaluations, "QP") << " in " << format_fixed(r.allocation_ms, 2)
         << " ms\n";
      if (r.evaluation_cap_reached && r.ok()) {
        os << "  warning       the time allocation stopped at time.max_evaluations ("
           << detail::count_noun(pb.options.time.max_evaluations, "QP")
           << ") before it converged: the durations may be far from optimal (raise time.max_evaluations)\n";
      }
    } else {
      os << "  time alloc    off (fixed durations)\n";
    }
    if (r.status != PlanStatus::AllocationCutShort) {  // else no final QP was solved
      os << "  final QP      " << r.qp_iterations << " iterations in " << format_fixed(r.qp_us, 1)
         << " us (cold start)\n";
    }
  }
  os << "  total         " << format_fixed(seconds * 1000, 2) << " ms\n";
  return os.str();
}

}  // namespace touchdown::plan
