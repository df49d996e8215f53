// landing_plan: the minimum-jerk landing trajectory onto a moving pad inside
// the visual safe flight corridor, from a problem file (docs/formats.md,
// "Landing problem"); a summary or one JSON object, and optionally the QP,
// an SVG of the plan and the sampled trajectory.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "app_common.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/problem_io.hpp"
#include "touchdown/plan/report.hpp"

namespace {

namespace td = touchdown;
namespace tp = touchdown::plan;
namespace fs = std::filesystem;
using td::app::format_fixed;

// --samples: one ~220-byte row per millisecond, built in memory before it is
// written; a trajectory of 16 segments of up to 1000 s would take ~3.5 GB.
constexpr double kMaxSampledSeconds = 1000;
constexpr double kCsvBytesPerRow = 220;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Plan a minimum-jerk landing onto a moving pad inside the visual safe flight corridor, from a problem YAML "
      "(docs/formats.md). Exit 0: planned; 1: infeasible, no corridor or allocation cut short (the report still "
      "prints); 2: bad input.",
      "landing_plan"};
  std::string problem_path, qp_path, plot_path, samples_path;
  bool json = false;
  app.add_option("PROBLEM", problem_path, "landing problem YAML (data/plans/landing.yaml is an example)")->required();
  app.add_flag("--json", json, "print one JSON object on stdout instead of the summary");
  app.add_option("--export-qp", qp_path,
                 "write the QP at the chosen durations as JSON (P, q, A_eq, b_eq, A_in, b_in, constant, variables)")
      ->check(td::app::output_extension(".json"));
  app.add_option("--plot", plot_path,
                 "write an SVG: top/side/rear views with the corridor, obstacles and field of view, and the "
                 "world-frame velocity and acceleration against the limits")
      ->check(td::app::output_extension(".svg"));
  app.add_option("--samples", samples_path,
                 "write the trajectory every 1 ms as CSV (pad-frame position, velocity, acceleration; world-frame "
                 "velocity and acceleration); only when planned, for a trajectory of at most 1000 s")
      ->check(td::app::output_extension(".csv"));
  // PROBLEM's counts and sizes have their ranges in the file format
  // (docs/formats.md): order 5..20, segments 1..16, durations and time.min,
  // time.max in [0.001, 1000] s, time.max_evaluations 1..100000,
  // corridor.max_dilations 1..100.

  return td::app::run(app, argc, argv, [&]() -> int {
    tp::PlanProblem problem = tp::load_plan_problem(problem_path);
    td::app::print_warnings(app.get_name(), problem.warnings);
    // Every output path is checked before the planning, and written through
    // a temporary: a failed run leaves no file behind.
    td::StagedOutputs staged;
    const fs::path qp_tmp = td::app::stage(staged, qp_path, "--export-qp");
    const fs::path plot_tmp = td::app::stage(staged, plot_path, "--plot");
    const fs::path samples_tmp = td::app::stage(staged, samples_path, "--samples");
    problem.options.export_qp = !qp_path.empty();
    const auto t0 = std::chrono::steady_clock::now();
    // A long time allocation (16 segments of order 20 take a minute) shows
    // a progress bar on a terminal once it has run for a second (off one,
    // lines when it takes over a minute).
    td::app::ProgressBar bar("landing_plan", "QP solves");
    const bool terminal = td::app::ProgressBar::on_terminal();
    problem.options.progress = [&bar, terminal](const td::Progress& p) {
      if (terminal && p.elapsed_s < 1) return;
      bar.draw(p.done, p.total);
    };
    tp::PlanResult r;
    try {
      r = tp::plan(problem.start, problem.goal, problem.pad, problem.options);
    } catch (const td::InvalidArgument& e) {
      bar.close();
      // A start or goal outside the corridor: the file's values are at fault.
      throw td::InvalidArgument(problem_path + ": " + e.what());
    }
    bar.close();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // Every output is rendered first, then written.
    std::vector<std::tuple<fs::path, std::string, std::string>> outputs;  // temporary, text, path
    // No QP without a corridor, nor without durations (allocation cut short).
    if (!qp_path.empty() && r.status != tp::PlanStatus::NoCorridor && r.status != tp::PlanStatus::AllocationCutShort)
      outputs.emplace_back(qp_tmp, tp::qp_json(r.qp), qp_path);
    if (!plot_path.empty()) {
      const tp::KinematicState goal = problem.goal ? *problem.goal : tp::default_goal(problem.options);
      outputs.emplace_back(plot_tmp, tp::plot_svg(problem, r, goal, tp::plot_title(problem_path, r)), plot_path);
    }
    if (!samples_path.empty() && r.ok()) {
      // Refused before the rows are built, with what they would take.
      if (const double T = r.trajectory.total_duration(); T > kMaxSampledSeconds) {
        const double rows = std::floor(T * 1000) + 1;
        throw td::InvalidArgument("--samples: the trajectory lasts " + format_fixed(T, 1) +
                                  " s: " + std::to_string(static_cast<long long>(rows)) + " rows of 1 ms, ~" +
                                  td::app::gigabytes(rows * kCsvBytesPerRow) + " of CSV; the limit is " +
                                  format_fixed(kMaxSampledSeconds, 0) + " s (~" +
                                  td::app::gigabytes(kMaxSampledSeconds * 1000 * kCsvBytesPerRow) + ")");
      }
      outputs.emplace_back(samples_tmp, tp::samples_csv(r.trajectory, problem.pad), samples_path);
    }
    for (const auto& [tmp, text, path] : outputs) td::app::write_text(tmp, text, path);
    staged.commit();

    if (json) {
      std::cout << tp::result_json(r, problem.options.order, problem.options.time.max_evaluations, seconds) << "\n";
    } else {
      std::cout << tp::summary(problem_path, problem, r, seconds);
    }
    // Infeasible, no corridor or the allocation cut short at its cap is a
    // result (the status says which): exit 0, as every app's answer is
    // (docs/cli.md, "Exit codes").
    return td::app::kExitOk;
  });
}
