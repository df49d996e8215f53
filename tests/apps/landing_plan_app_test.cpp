// landing_plan end to end: the bundled problem, JSON schema, the exported QP
// against the JSON's control points, the samples CSV, the SVG, bad input and
// an infeasible problem.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.hpp"

namespace td = touchdown;
using td::test::AppRun;
using td::test::TempDir;

namespace {

AppRun run(const std::string& args, const TempDir& dir) { return td::test::run_app(LANDING_PLAN_EXE, args, dir); }

std::string bundled() { return (std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/plans/landing.yaml").string(); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

Eigen::MatrixXd matrix_of(const nlohmann::json& j) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(j.size()), j.empty() ? 0 : static_cast<Eigen::Index>(j[0].size()));
  for (std::size_t r = 0; r < j.size(); ++r) {
    for (std::size_t c = 0; c < j[r].size(); ++c) {
      m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = j[r][c].get<double>();
    }
  }
  return m;
}

Eigen::VectorXd vector_of(const nlohmann::json& j) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (std::size_t i = 0; i < j.size(); ++i) v(static_cast<Eigen::Index>(i)) = j[i].get<double>();
  return v;
}

// The JSON's control points flattened in (segment, control point, axis) order.
Eigen::VectorXd control_points_of(const nlohmann::json& j) {
  std::vector<double> x;
  for (const auto& s : j["segments"]) {
    for (const auto& c : s["control_points"]) {
      for (const auto& v : c) x.push_back(v.get<double>());
    }
  }
  return Eigen::Map<Eigen::VectorXd>(x.data(), static_cast<Eigen::Index>(x.size()));
}

std::vector<std::vector<double>> csv_rows(const std::string& text, std::string& header) {
  std::istringstream in(text);
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

// Runs the bundled problem once with every output (shared by the tests below).
struct BundledRun {
  TempDir dir;
  AppRun result;
  nlohmann::json json;
  BundledRun() {
    result = run(bundled() + " --json --export-qp " + (dir / "qp.json").string() + " --plot " +
                     (dir / "plan.svg").string() + " --samples " + (dir / "samples.csv").string(),
                 dir);
    if (result.code == 0) json = nlohmann::json::parse(result.out);
  }
};

}  // namespace

TEST(LandingPlanApp, BundledProblemJson) {
  BundledRun b;
  ASSERT_EQ(b.result.code, 0) << b.result.err;
  const auto& j = b.json;
  for (const char* key : {"status", "cost", "order", "segments", "corridor", "time_allocation", "qp", "seconds"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_FALSE(j.contains("conflicts"));
  EXPECT_FALSE(j.contains("message"));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_GT(j["cost"].get<double>(), 0);
  EXPECT_EQ(j["order"], 7);
  EXPECT_GT(j["time_allocation"]["evaluations"].get<int>(), 0);
  EXPECT_GE(j["time_allocation"]["ms"].get<double>(), 0);
  EXPECT_GE(j["qp"]["iterations"].get<int>(), 0);
  EXPECT_GE(j["qp"]["us"].get<double>(), 0);
  EXPECT_GT(j["seconds"].get<double>(), 0);
  ASSERT_EQ(j["segments"].size(), 2u);
  ASSERT_EQ(j["corridor"].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& s = j["segments"][k];
    EXPECT_GT(s["duration"].get<double>(), 0);
    ASSERT_EQ(s["control_points"].size(), 8u);
    const Eigen::MatrixXd A = matrix_of(j["corridor"][k]["A"]);
    const Eigen::VectorXd bvec = vector_of(j["corridor"][k]["b"]);
    ASSERT_EQ(A.cols(), 3);
    ASSERT_EQ(A.rows(), bvec.size());
    for (const auto& c : s["control_points"]) {
      ASSERT_EQ(c.size(), 3u);
      const Eigen::Vector3d p(c[0].get<double>(), c[1].get<double>(), c[2].get<double>());
      EXPECT_LE((A * p - bvec).maxCoeff(), 1e-9) << "segment " << k << " control point " << p.transpose();
    }
  }
  // From the start to the default goal: the pad centre at h_touchdown.
  const auto& first = j["segments"][0]["control_points"][0];
  const auto& last = j["segments"][1]["control_points"][7];
  EXPECT_NEAR(first[0].get<double>(), -3, 1e-9);
  EXPECT_NEAR(first[2].get<double>(), 2, 1e-9);
  EXPECT_NEAR(last[0].get<double>(), 0, 1e-9);
  EXPECT_NEAR(last[1].get<double>(), 0, 1e-9);
  EXPECT_NEAR(last[2].get<double>(), 0.5, 1e-9);
}

TEST(LandingPlanApp, ExportedQpAgreesWithTheJson) {
  BundledRun b;
  ASSERT_EQ(b.result.code, 0) << b.result.err;
  const auto qp = nlohmann::json::parse(td::test::read_text(b.dir / "qp.json"));
  for (const char* key : {"P", "q", "A_eq", "b_eq", "A_in", "b_in", "constant", "variables"}) {
    EXPECT_TRUE(qp.contains(key)) << key;
  }
  const Eigen::VectorXd x = control_points_of(b.json);
  ASSERT_EQ(x.size(), 2 * 8 * 3);
  ASSERT_EQ(qp["variables"].size(), static_cast<std::size_t>(x.size()));
  EXPECT_EQ(qp["variables"][0], "s0.c0.x");
  EXPECT_EQ(qp["variables"][47], "s1.c7.z");
  const Eigen::MatrixXd P = matrix_of(qp["P"]);
  const Eigen::VectorXd q = vector_of(qp["q"]);
  ASSERT_EQ(P.rows(), x.size());
  ASSERT_EQ(P.cols(), x.size());
  ASSERT_EQ(q.size(), x.size());
  // cost = ½ xᵀPx + qᵀx + constant at the JSON's control points.
  const double cost = b.json["cost"].get<double>();
  const double value = 0.5 * x.dot(P * x) + q.dot(x) + qp["constant"].get<double>();
  EXPECT_NEAR(value, cost, 1e-6 * std::abs(cost));
  // The control points meet the exported constraints.
  const Eigen::MatrixXd A_eq = matrix_of(qp["A_eq"]), A_in = matrix_of(qp["A_in"]);
  const Eigen::VectorXd b_eq = vector_of(qp["b_eq"]), b_in = vector_of(qp["b_in"]);
  ASSERT_GT(A_eq.rows(), 0);
  ASSERT_GT(A_in.rows(), 0);
  ASSERT_EQ(A_eq.cols(), x.size());
  ASSERT_EQ(A_in.cols(), x.size());
  for (Eigen::Index r = 0; r < A_eq.rows(); ++r) {
    EXPECT_NEAR(A_eq.row(r).dot(x), b_eq(r),
                1e-7 * std::max(1.0, A_eq.row(r).cwiseAbs().sum() * x.cwiseAbs().maxCoeff()))
        << "equality row " << r;
  }
  for (Eigen::Index r = 0; r < A_in.rows(); ++r) {
    EXPECT_LE(A_in.row(r).dot(x), b_in(r) + 1e-7 * std::max(1.0, A_in.row(r).cwiseAbs().sum()))
        << "inequality row " << r << " (" << qp["in_groups"][static_cast<std::size_t>(r)] << ")";
  }
}

TEST(LandingPlanApp, SamplesEveryMillisecondWithinTheLimits) {
  BundledRun b;
  ASSERT_EQ(b.result.code, 0) << b.result.err;
  std::string header;
  const auto rows = csv_rows(td::test::read_text(b.dir / "samples.csv"), header);
  EXPECT_EQ(header, "t,px,py,pz,vx,vy,vz,ax,ay,az,world_vx,world_vy,world_vz,world_ax,world_ay,world_az");
  const double total =
      b.json["segments"][0]["duration"].get<double>() + b.json["segments"][1]["duration"].get<double>();
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(std::floor(total * 1000 + 1e-6)) + 1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    ASSERT_EQ(r.size(), 16u) << "row " << i;
    EXPECT_NEAR(r[0], static_cast<double>(i) * 1e-3, 1e-9);
    // A pad driving straight at 2 m/s along world x: world velocity = pad
    // velocity + relative velocity, world acceleration = relative acceleration.
    EXPECT_NEAR(r[10], r[4] + 2.0, 1e-6);
    EXPECT_NEAR(r[11], r[5], 1e-6);
    EXPECT_NEAR(r[12], r[6], 1e-6);
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(r[static_cast<std::size_t>(13 + a)], r[static_cast<std::size_t>(7 + a)], 1e-6);
    // The limits (4 m/s, 4 m/s² per world axis) hold on the sampled curve.
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(std::abs(r[static_cast<std::size_t>(10 + a)]), 4 + 1e-6) << "t = " << r[0];
      EXPECT_LE(std::abs(r[static_cast<std::size_t>(13 + a)]), 4 + 1e-6) << "t = " << r[0];
    }
  }
  // The drone (radius 0.25 m) keeps clear of the antenna mast all the way
  // (the corridor's guarantee, checked on the curve itself).
  const Eigen::Vector3d mast_min(-1.6, -0.15, 0), mast_max(-1.45, 0.15, 0.7);
  for (const auto& r : rows) {
    const Eigen::Vector3d p(r[1], r[2], r[3]);
    const Eigen::Vector3d outside = (mast_min - p).cwiseMax(p - mast_max).cwiseMax(0.0);
    EXPECT_GE(outside.norm(), 0.25) << "t = " << r[0];
  }
  // Starts at the start state, ends near the goal at rest relative to the pad.
  EXPECT_NEAR(rows.front()[1], -3, 1e-9);
  EXPECT_NEAR(rows.front()[3], 2, 1e-9);
  EXPECT_NEAR(rows.front()[4], 0.3, 1e-9);
  EXPECT_NEAR(rows.back()[3], 0.5, 1e-3);
  EXPECT_NEAR(rows.back()[4], 0, 1e-2);
}

TEST(LandingPlanApp, SvgAndSummary) {
  BundledRun b;
  ASSERT_EQ(b.result.code, 0) << b.result.err;
  const std::string svg = td::test::read_text(b.dir / "plan.svg");
  EXPECT_TRUE(svg.rfind("<svg", 0) == 0 || svg.rfind("<?xml", 0) == 0) << svg.substr(0, 80);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find("landing.yaml: ok"), std::string::npos);
  for (const char* part : {"top view", "side view", "rear view", "world-frame velocity", "world-frame acceleration",
                           "touchdown corridor", "obstacle", "field of view"}) {
    EXPECT_NE(svg.find(part), std::string::npos) << part;
  }
  // The human summary.
  const AppRun s = run(bundled(), b.dir);
  EXPECT_EQ(s.code, 0) << s.err;
  EXPECT_NE(s.out.find("landing.yaml: ok"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("cost"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("time alloc"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("final QP"), std::string::npos) << s.out;
}

// Issue 31, item 9: the summary said "1 segments of order 7".
TEST(LandingPlanApp, SummaryCountsSegmentsInTheSingular) {
  TempDir dir;
  std::string text = td::test::read_text(bundled());
  text = replaced(text.substr(0, text.find("\ncorridor:") + 1), "segments: 2", "segments: 1");
  td::test::write_text(dir / "one.yaml", text);
  const AppRun one = run((dir / "one.yaml").string(), dir);
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_NE(one.out.find("(1 segment of order 7)"), std::string::npos) << one.out;
  const AppRun two = run(bundled(), dir);
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_NE(two.out.find("(2 segments of order 7)"), std::string::npos) << two.out;
}

// Issue 31 item 6: time.max_evaluations below 18 had no effect (every cap
// printed "18 QPs") and reaching the cap was never reported.
TEST(LandingPlanApp, EvaluationCapIsHonouredAndReported) {
  TempDir dir;
  const std::string y = td::test::read_text(bundled());
  for (const int cap : {5, 16, 17}) {
    SCOPED_TRACE(cap);
    td::test::write_text(
        dir / "p.yaml",
        td::test::replace_key_line(
            y, "time", "time: {min: 0.3, max: 8.0, rho: 1.0, max_evaluations: " + std::to_string(cap) + "}"));
    const AppRun r = run((dir / "p.yaml").string() + " --json", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["status"], "ok");
    EXPECT_EQ(j["time_allocation"]["evaluations"].get<int>(), cap);
    EXPECT_EQ(j["time_allocation"]["max_evaluations"].get<int>(), cap);
    EXPECT_EQ(j["time_allocation"]["cap_reached"], true);
    const AppRun s = run((dir / "p.yaml").string(), dir);
    ASSERT_EQ(s.code, 0) << s.err;
    EXPECT_NE(s.out.find("  time alloc    " + std::to_string(cap) + " QPs"), std::string::npos) << s.out;
    EXPECT_NE(s.out.find("warning       the time allocation stopped at time.max_evaluations (" + std::to_string(cap)),
              std::string::npos)
        << s.out;
  }
  // The bundled problem converges well within its cap: no warning.
  const AppRun b = run(bundled() + " --json", dir);
  ASSERT_EQ(b.code, 0) << b.err;
  const auto j = nlohmann::json::parse(b.out);
  EXPECT_EQ(j["time_allocation"]["cap_reached"], false);
  EXPECT_EQ(j["time_allocation"]["max_evaluations"].get<int>(), 300);
  const AppRun s = run(bundled(), dir);
  EXPECT_EQ(s.out.find("warning"), std::string::npos) << s.out;
}

// A cap reached before any feasible durations: status allocation_cut_short,
// exit 0 (a result), no trajectory and no conflicts (not a verdict of infeasibility).
TEST(LandingPlanApp, CapBeforeAnyFeasibleDurationsIsCutShort) {
  TempDir dir;
  std::string text = td::test::read_text(bundled());
  text = text.substr(0, text.find("\ncorridor:") + 1);  // no corridor, 2 segments
  text = replaced(text, "p: [-3.0, 0.0, 2.0]", "p: [-10.0, 0.0, 2.0]");
  text = td::test::replace_key_line(text, "limits", "limits: {v_max: 100.0, a_max: 0.5}");
  text = td::test::replace_key_line(text, "time", "time: {min: 0.3, max: 8.0, rho: 1.0, max_evaluations: 1}");
  td::test::write_text(dir / "p.yaml", text);
  const AppRun r = run((dir / "p.yaml").string() + " --json --export-qp " + (dir / "qp.json").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "allocation_cut_short");
  EXPECT_EQ(j["time_allocation"]["cap_reached"], true);
  EXPECT_EQ(j["time_allocation"]["evaluations"].get<int>(), 1);
  EXPECT_FALSE(j.contains("conflicts"));
  EXPECT_TRUE(j["segments"].empty());
  EXPECT_NE(j["message"].get<std::string>().find("raise time.max_evaluations"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir / "qp.json"));
  const AppRun s = run((dir / "p.yaml").string(), dir);
  EXPECT_EQ(s.code, 0);
  EXPECT_NE(s.out.find("allocation_cut_short"), std::string::npos) << s.out;
  EXPECT_EQ(s.out.find("final QP"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("time alloc    1 QP in"), std::string::npos) << s.out;
}

TEST(LandingPlanApp, InfeasibleIsAResultWithConflicts) {
  TempDir dir;
  // A tiny acceleration limit and fixed durations: only the acceleration
  // limit stands between the problem and a plan.
  td::test::write_text(dir / "p.yaml", td::test::replace_key_line(td::test::read_text(bundled()), "limits",
                                                                  "limits: {v_max: 4.0, a_max: 0.05}\n"
                                                                  "durations: [2.5, 2.0]"));
  const AppRun r = run((dir / "p.yaml").string() + " --json --samples " + (dir / "s.csv").string() + " --export-qp " +
                           (dir / "qp.json").string() + " --plot " + (dir / "p.svg").string(),
                       dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "infeasible");
  ASSERT_TRUE(j.contains("conflicts"));
  bool acceleration = false;
  for (const auto& c : j["conflicts"]) acceleration = acceleration || c == "acceleration";
  EXPECT_TRUE(acceleration) << j["conflicts"];
  EXPECT_FALSE(j["message"].get<std::string>().empty());
  EXPECT_TRUE(j["segments"].empty());
  EXPECT_EQ(j["corridor"].size(), 2u);
  // No trajectory, no samples; the QP and the plot still tell why.
  EXPECT_FALSE(std::filesystem::exists(dir / "s.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "qp.json"));
  EXPECT_NE(td::test::read_text(dir / "p.svg").find("infeasible"), std::string::npos);
  // The summary says so too, with the same exit code.
  const AppRun s = run((dir / "p.yaml").string(), dir);
  EXPECT_EQ(s.code, 0);
  EXPECT_NE(s.out.find("infeasible"), std::string::npos) << s.out;
  EXPECT_NE(s.out.find("acceleration"), std::string::npos) << s.out;
}

// Issue 31 item 9: radians in camera.rpy_deg or pad.yaw_deg give a warning
// on stderr naming the file, line and key, and the run goes on; the plot's
// subtitle gives the pad's turn rate in deg/s, as the file does.
TEST(LandingPlanApp, RadiansInDegreeKeysWarnAndTheRunContinues) {
  TempDir dir;
  td::test::write_text(dir / "p.yaml", replaced(td::test::read_text(bundled()), "yaw_deg: 0.0", "yaw_deg: 0.35"));
  const AppRun r = run((dir / "p.yaml").string() + " --json", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "landing_plan: warning: " + (dir / "p.yaml").string() +
                       ":27: pad.yaw_deg: 0.35 looks like radians (within +-2 pi, not a whole degree) but is read as "
                       "degrees; if radians were meant, write 20.05\n");
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
  // A camera turned by radians read as degrees looks the wrong way: the
  // warning comes first and explains the error that follows.
  td::test::write_text(dir / "c.yaml", replaced(td::test::read_text(bundled()), "rpy_deg: [-45.0, 0.0, 90.0]",
                                                "rpy_deg: [-0.785, 0, 1.571]"));
  const AppRun c = run((dir / "c.yaml").string(), dir);
  EXPECT_EQ(c.err.rfind("landing_plan: warning: " + (dir / "c.yaml").string() +
                            ":40: corridor.camera.rpy_deg: [-0.785, 0, 1.571] look like radians",
                        0),
            0u)
      << c.err;
  const AppRun ok = run(bundled(), dir);
  EXPECT_TRUE(ok.err.empty()) << ok.err;

  td::test::write_text(dir / "turning.yaml",
                       replaced(td::test::read_text(bundled()), "yaw_rate_deg: 0.0", "yaw_rate_deg: 10.0"));
  const AppRun t = run((dir / "turning.yaml").string() + " --plot " + (dir / "t.svg").string(), dir);
  ASSERT_TRUE(t.code == 0 || t.code == 1) << t.err;
  const std::string svg = td::test::read_text(dir / "t.svg");
  EXPECT_NE(svg.find("yaw rate 10.00 deg/s"), std::string::npos);
  EXPECT_EQ(svg.find("rad/s"), std::string::npos);
}

// ---- bad input: exit 2, one line naming the file and the key, no output ----

namespace {

struct BadProblem {
  const char* name;
  std::string yaml;
  std::string expected;  // in the one stderr line, after "p.yaml"
};

std::vector<BadProblem> bad_problems() {
  const std::string y = td::test::read_text(bundled());
  using td::test::replace_key_line;
  return {
      {"missing limits", replace_key_line(y, "limits", ""), "limits: missing"},
      {"NaN", replace_key_line(y, "limits", "limits: {v_max: .nan, a_max: 4.0}"), "limits.v_max: expected a number"},
      {"negative v_max", replace_key_line(y, "limits", "limits: {v_max: -1, a_max: 4.0}"),
       "limits.v_max: must be > 0, got -1"},
      {"zero duration", replace_key_line(y, "segments", "segments: 2\ndurations: [1, 0]"),
       "durations[1]: must be in [0.001, 1000] s, got 0"},
      {"duration of 1e5 s", replace_key_line(y, "segments", "segments: 2\ndurations: [1, 1e5]"),
       "durations[1]: must be in [0.001, 1000] s, got 100000"},
      {"order 4", replace_key_line(y, "order", "order: 4"), "order: must be in 5..20, got 4"},
      {"start inside the obstacle", replaced(y, "p: [-3.0, 0.0, 2.0]", "p: [-1.5, 0.0, 0.4]"),
       "start.p: outside the corridor"},
      {"start behind the camera", replaced(y, "p: [-3.0, 0.0, 2.0]", "p: [1.5, 0.0, 1.0]"),
       "start.p: outside the corridor"},
      {"unknown key", replace_key_line(y, "order", "order: 7\ncolour: red"), "colour: unknown key"},
      {"unknown nested key", replaced(y, "  radius: 0.25", "  radius: 0.25\n  radious: 0.3"),
       "corridor.radious: unknown key"},
      {"old pad.yaw_rate (rad/s)", replaced(y, "yaw_rate_deg: 0.0", "yaw_rate: 0.2"),
       "p.yaml:26: pad.yaw_rate: renamed to pad.yaw_rate_deg (deg/s)"},
  };
}

}  // namespace

TEST(LandingPlanAppBadInput, ExitTwoOneLineNoOutputs) {
  for (const auto& c : bad_problems()) {
    SCOPED_TRACE(c.name);
    TempDir dir;
    td::test::write_text(dir / "p.yaml", c.yaml);
    const AppRun r = run((dir / "p.yaml").string() + " --json --export-qp " + (dir / "qp.json").string() + " --plot " +
                             (dir / "p.svg").string() + " --samples " + (dir / "s.csv").string(),
                         dir);
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("p.yaml"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    EXPECT_EQ(dir.files(), std::vector<std::string>{"p.yaml"});
  }
}

// Issue 31: a second `limits` appended to the bundled problem was ignored
// (the first won) and the unchanged plan was written.
TEST(LandingPlanAppBadInput, RepeatedKeyIsExitTwoNamingBothLines) {
  TempDir dir;
  const auto f = td::test::with_repeated_key(bundled(), dir / "landing.yaml", "limits", "{v_max: 0.1, a_max: 0.1}");
  const AppRun r = run(f.path.string() + " --json --plot " + (dir / "p.svg").string() + " --samples " +
                           (dir / "s.csv").string() + " --export-qp " + (dir / "qp.json").string(),
                       dir);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(f.expected + "\n"), std::string::npos) << r.err;
  EXPECT_EQ(dir.files(), std::vector<std::string>{"landing.yaml"});
}

TEST(LandingPlanAppBadInput, MissingFileAndMissingOutputDirectory) {
  TempDir dir;
  AppRun r = run((dir / "nope.yaml").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("nope.yaml: cannot open"), std::string::npos) << r.err;
  // One output into a missing directory: nothing is written, not even the others.
  r = run(bundled() + " --plot " + (dir / "p.svg").string() + " --samples " + (dir / "missing/s.csv").string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing"), std::string::npos) << r.err;
  EXPECT_TRUE(dir.files().empty());
  // Each output's name must match what is written into it.
  for (const std::string& bad : {" --plot " + (dir / "p.png").string(), " --samples " + (dir / "s.txt").string(),
                                 " --export-qp " + (dir / "qp.yaml").string()}) {
    r = run(bundled() + bad, dir);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("its name must end in"), std::string::npos) << r.err;
    EXPECT_TRUE(dir.files().empty());
  }
}

// Issue 11: the samples CSV is built in memory, one ~220-byte row per
// millisecond: a trajectory of 1200 s wrote 264 MB and exit 0 (16 segments of
// 1000 s would take ~3.5 GB). Refused before the rows are built, with the
// estimate, and no output file is written.
TEST(LandingPlanAppBadInput, SamplesOfAVeryLongTrajectoryAreRefused) {
  TempDir dir;
  td::test::write_text(dir / "p.yaml",
                       "start: {p: [-3, 0, 2]}\nlimits: {v_max: 4, a_max: 4}\nsegments: 2\n"
                       "durations: [600, 600]\n");
  AppRun r =
      run((dir / "p.yaml").string() + " --samples " + (dir / "s.csv").string() + " --plot " + (dir / "p.svg").string(),
          dir);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("--samples: the trajectory lasts 1200.0 s: 1200001 rows of 1 ms, ~0.26 GB of CSV; the limit "
                       "is 1000 s"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(dir.files(), std::vector<std::string>{"p.yaml"});
  // Without --samples the plan itself is fine.
  r = run((dir / "p.yaml").string(), dir);
  EXPECT_EQ(r.code, 0) << r.err;
}
