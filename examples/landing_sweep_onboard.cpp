// Embedding the landing sweep onboard: a companion computer has meshed the
// terrain under the drone (here: from a simulated depth frame) and asks the
// twin for the safest heading within a time budget (the anytime entry point:
// fewer runs per heading when time is short, and it says how complete the
// answer is).
//
//   example_landing_sweep_onboard [budget_seconds]
#include <cstdlib>
#include <iostream>
#include <touchdown/core/units.hpp>
#include <touchdown/terrain/synthetic.hpp>
#include <touchdown/terrain/terrain_mesher.hpp>
#include <touchdown/twin/airframe.hpp>
#include <touchdown/twin/sweep.hpp>
#include <touchdown/twin/terrain_model.hpp>

int main(int argc, char** argv) {
  namespace td = touchdown;
  namespace syn = td::terrain::synthetic;
  const double budget = argc > 1 ? std::atof(argv[1]) : 1.0;

  // 1. Terrain: a depth frame over a 10 cm step, meshed by the terrain stage.
  syn::Shape step;
  step.kind = syn::ShapeKind::Step;
  step.step_height = 0.10;
  step.prepare();
  td::terrain::TerrainOptions terrain_options;
  terrain_options.T_world_camera = syn::nadir_camera_pose(0.0, 0.0, 1.2);
  auto meshed = td::terrain::mesh_terrain(
      syn::render_depth_scan(step, syn::DepthCamera{}, terrain_options.T_world_camera, 1), terrain_options);
  if (!meshed.ok()) {
    std::cerr << "no terrain: " << meshed.message << "\n";
    return 1;
  }
  auto terrain = std::make_shared<const td::twin::TerrainModel>(std::move(meshed.mesh));

  // 2. The sweep: 20 headings x up to 10 runs, stopping after the round that
  //    passes the budget.
  td::twin::SweepOptions options;
  options.landing_point = {0.12, 0.0};  // 12 cm from the step's edge
  options.time_budget = budget;
  const auto result = td::twin::run_sweep(td::twin::Airframe::f450(), terrain, options);
  if (!result.ok()) {
    std::cout << "do not land here: " << result.message << "\n";
    return 0;
  }

  std::cout << result.landings() << " landings in " << result.seconds << " s, " << 100 * result.completeness
            << " % of the full sweep\n";
  if (result.safe) {
    const auto& best = result.headings[static_cast<std::size_t>(result.best)];
    std::cout << "land at heading " << td::rad_to_deg(best.yaw) << " deg (worst nutation " << best.score
              << " rad, threshold " << result.threshold.value() << " rad)\n";
  } else {
    // Why: e.g. "20 headings: unobserved terrain" or "4 headings: tips over".
    std::cout << "do not land here: " << td::twin::unsafe_summary(result) << "\n";
  }
  return 0;
}
