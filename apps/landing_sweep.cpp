// landing_sweep: land the drone's digital twin on a terrain at n headings ×
// m noisy runs and pick the safest heading (issue 3).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "app_common.hpp"
#include "frames.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/twin/sweep.hpp"
#include "touchdown/twin/sweep_plot.hpp"
#include "touchdown/twin/sweep_report.hpp"

namespace {

namespace td = touchdown;
namespace tw = touchdown::twin;

// The command line: what the user asked for.
struct Args {
  std::string terrain_path, airframe_path, extrinsics_path, runs_csv_path, plot_path;
  tw::SweepOptions o;
  std::vector<double> landing_point, friction;
  double sigma_speed = o.perturbation.sigma_land_speed;
  bool json = false;
  bool full = false;  // --full: every landing (default: the decision mode)
  bool assume_world = false;
  double search_radius = 0, search_spacing = 0;
  tw::SearchPreference search_prefer = tw::SearchPreference::LowestScore;
  td::terrain::TerrainOptions cloud_options;
};

void add_options(CLI::App& app, Args& a) {
  tw::SweepOptions& o = a.o;
  app.add_option("TERRAIN", a.terrain_path,
                 "terrain mesh (.stl .obj .ply) or point cloud (.pcd .ply .xyz .csv), world frame z up")
      ->required();
  app.add_option("--airframe", a.airframe_path,
                 "airframe YAML (default: the built-in DJI F450, data/airframes/f450.yaml)");
  auto* extrinsics = app.add_option("--extrinsics", a.extrinsics_path,
                                    "camera pose YAML when TERRAIN is a camera-frame point cloud (not for a mesh)")
                         ->default_str("none");
  app.add_flag("--assume-world-frame", a.assume_world,
               "TERRAIN is a world-frame cloud (z up) although it looks like a camera frame (docs/formats.md)")
      ->excludes(extrinsics);
  app.add_option("--headings", o.headings, "number of headings n (headings x runs <= 1,000,000)")
      ->check(CLI::Range(1, tw::SweepOptions::kMaxHeadings))
      ->capture_default_str();
  app.add_option("--runs", o.runs, "runs per heading m")
      ->check(CLI::Range(1, tw::SweepOptions::kMaxRuns))
      ->capture_default_str();
  app.add_option(
         "--yaw-max", o.yaw_max_deg,
         "psi_max [deg]; 0 = 360 / the airframe's symmetry order (the turn after which its feet, motors and body "
         "repeat: 180 for the F450)")
      ->check(td::app::degrees_not_radians("--yaw-max"))
      ->capture_default_str();
  app.add_option("--landing-point", a.landing_point, "x,y of the landing point [m]")
      ->delimiter(',')
      ->expected(2)
      ->default_str("0,0");
  app.add_option("--hover-offset", o.hover_offset,
                 "start this high above the terrain under the footprint [m] (a descent at --land-speed shorter "
                 "than --timeout)")
      ->check(td::app::number_in(0, tw::SweepOptions::kMaxHoverOffset, true, false))
      ->capture_default_str();
  app.add_option("--land-speed", o.land_speed, "descent speed, PX4 MPC_LAND_SPEED [m/s]")
      ->check(td::app::number_in(0, 5, true, true))
      ->capture_default_str();
  app.add_option("--sigma-xy", o.perturbation.sigma_xy, "start position sigma [m]")->capture_default_str();
  app.add_option("--sigma-yaw-deg", o.perturbation.sigma_yaw_deg, "heading sigma [deg]")->capture_default_str();
  app.add_option("--sigma-tilt-deg", o.perturbation.sigma_tilt_deg, "initial roll/pitch sigma [deg]")
      ->capture_default_str();
  app.add_option("--sigma-speed", a.sigma_speed, "land speed sigma [m/s]")->capture_default_str();
  app.add_option("--friction", a.friction, "ground friction range min,max (drawn uniformly per run)")
      ->delimiter(',')
      ->expected(2)
      ->default_str("0.6,1");
  td::app::add_enum_option(app, "--metric", o.metric,
                           "full: strikes and tip-overs are unsafe; seed: the paper's final-nutation rule");
  td::app::add_seed_option(app, "--seed", o.seed, "random seed (same seed -> same result for any thread count)");
  app.add_option("--threads", o.threads, "worker threads (0 = every core)")->capture_default_str();
  app.add_flag("--full", a.full,
               "fly every heading x run and print the full table (default: the decision mode, which flies only the "
               "landings that can change the decision: the same decision, heading and S)");
  app.add_option("--deadline", o.deadline,
                 "decision mode: start no landing after this many seconds; say which headings are settled, \"do not "
                 "land\" when none is settled safe; 0 = none")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--time-budget", o.time_budget,
                 "with --full, anytime: stop after the round that passes this many seconds, 0 = off")
      ->capture_default_str();
  app.add_option("--search-radius", a.search_radius,
                 "also try landing points on a grid within this radius [m] and report the best (x, y, psi)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  td::app::add_enum_option(app, "--search-prefer", a.search_prefer,
                           "which safe point the search returns: lowest (lowest S) or nearest (nearest the landing "
                           "point; farther points are not flown)");
  app.add_option("--search-spacing", a.search_spacing, "grid spacing of the search [m], 0 = radius/2")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  td::app::add_enum_option(app, "--unknown-fill", a.cloud_options.height_map.unknown_fill,
                           "point clouds: fill regions the camera never observed as a block up to their highest rim "
                           "or as a pit (either way a heading over them is unsafe: unobserved terrain)");
  app.add_option("--step", o.simulation.step, "physics step [s]")->capture_default_str();
  td::app::add_enum_option(app, "--contact", o.simulation.contact,
                           "height-field (the default): on a terrain that is one (a depth cloud, or a mesh made from "
                           "one) contact candidates by grid index and one contact per patch of surface, else as "
                           "trimesh; trimesh: contacts from every triangle (the twin before issue 57)");
  app.add_option("--timeout", o.simulation.timeout,
                 "simulated seconds a landing may take; a run still moving then is invalid (timeout), not scored")
      ->check(CLI::Range(0.1, 600.0))
      ->capture_default_str();
  app.add_option("--runs-csv", a.runs_csv_path, "write one CSV row per run")->check(td::app::output_extension(".csv"));
  app.add_option("--plot", a.plot_path, "write an SVG of S(psi) per heading with the threshold")
      ->check(td::app::output_extension(".svg"));
  app.add_flag("--json", a.json, "print one JSON object on stdout");
}

// The options the vector flags set, validated.
void finish_sweep_options(Args& a) {
  tw::SweepOptions& o = a.o;
  if (a.landing_point.size() == 2) o.landing_point = {a.landing_point[0], a.landing_point[1]};
  if (a.friction.size() == 2) {
    o.perturbation.friction_min = a.friction[0];
    o.perturbation.friction_max = a.friction[1];
  }
  o.perturbation.sigma_land_speed = a.sigma_speed;
  if (o.time_budget > 0 && !a.full) {
    throw td::InvalidArgument("--time-budget: the full sweep's anytime mode: add --full, or use --deadline");
  }
  if (o.deadline > 0 && a.full) throw td::InvalidArgument("--deadline: the decision mode's; not with --full");
  o.decide = !a.full;
  std::string why;
  if (!o.validate(&why)) throw td::InvalidArgument(why);
}

// TERRAIN as a terrain model: a mesh as it is, a cloud in the world frame
// (through --extrinsics, or as it is when it looks like one).
std::shared_ptr<const tw::TerrainModel> load_terrain(const std::string& app_name, Args& a) {
  if (!a.extrinsics_path.empty()) {
    const auto e = td::app::load_extrinsics_with_warnings(app_name, a.extrinsics_path);
    a.cloud_options.T_world_camera = e.T_world_camera;
    a.cloud_options.T_body_camera = e.T_body_camera;
  }
  tw::TerrainFile terrain_file = tw::read_terrain_file(a.terrain_path);
  if (terrain_file.is_mesh() && (!a.extrinsics_path.empty() || a.assume_world)) {
    throw td::InvalidArgument(a.terrain_path + ": is a mesh, always in the world frame: " +
                              (a.assume_world ? "--assume-world-frame" : "--extrinsics") +
                              " applies to point clouds only");
  }
  if (!terrain_file.is_mesh() && a.extrinsics_path.empty() && !a.assume_world) {
    td::app::require_world_frame(a.terrain_path, terrain_file.cloud);
  }
  return tw::make_terrain_model(std::move(terrain_file), a.cloud_options);
}

// The sweep at the landing point, or with --search-radius the search (the
// landing point then becomes the best one found).
tw::SearchResult sweep_or_search(const tw::Airframe& airframe, const std::shared_ptr<const tw::TerrainModel>& terrain,
                                 Args& a) {
  tw::SearchResult search;
  if (a.search_radius > 0) {
    search = tw::search_landing_point(airframe, terrain, a.o, a.search_radius, a.search_spacing, a.search_prefer);
    if (!search.ok()) throw td::InvalidArgument(search.message);
    a.o.landing_point = search.candidates[static_cast<std::size_t>(search.best)].xy;
  } else {
    search.sweep = tw::run_sweep(airframe, terrain, a.o);
    // The user's landing point is off the terrain: bad input for the app.
    if (!search.sweep.ok()) throw td::InvalidArgument(search.sweep.message);
  }
  return search;
}

// --runs-csv and --plot, to the temporaries `outputs` staged for them.
struct OutputFiles {
  td::StagedOutputs staged;
  std::filesystem::path runs_csv, plot;
};

void write_files(const Args& a, OutputFiles& out, const tw::SearchResult& search, const Eigen::Vector2d& requested,
                 const tw::Airframe& airframe, const tw::TerrainModel& terrain) {
  const tw::SweepResult& r = search.sweep;
  if (!out.runs_csv.empty()) td::app::write_text(out.runs_csv, tw::runs_csv(r), a.runs_csv_path);
  if (!out.plot.empty()) {
    const tw::SweepPlotLabels labels{std::filesystem::path(a.terrain_path).filename().string(),
                                     a.airframe_path.empty() ? "F450 (built in)" : airframe.name};
    td::app::write_text(out.plot,
                        search.candidates.empty()
                            ? tw::sweep_plot_svg(r, labels)
                            : tw::search_plot_svg(search, requested, a.search_radius, airframe, terrain, labels),
                        a.plot_path);
  }
  out.staged.commit();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Land the drone's digital twin on a terrain at n headings x m noisy runs and pick the safest heading.",
               "landing_sweep"};
  Args a;
  add_options(app, a);

  return td::app::run(app, argc, argv, [&]() -> int {
    finish_sweep_options(a);
    OutputFiles out;  // checked before any work; nothing is left if the run fails
    out.runs_csv = td::app::stage(out.staged, a.runs_csv_path, "--runs-csv");
    out.plot = td::app::stage(out.staged, a.plot_path, "--plot");
    const tw::Airframe airframe = a.airframe_path.empty() ? tw::Airframe::f450() : tw::load_airframe(a.airframe_path);
    const auto terrain = load_terrain(app.get_name(), a);
    td::app::ProgressBar bar("landing_sweep", "landings");
    a.o.progress = [&bar](const td::Progress& p) { bar.draw(p.done, p.total); };
    const Eigen::Vector2d requested = a.o.landing_point;
    const tw::SearchResult search = sweep_or_search(airframe, terrain, a);
    bar.close();  // e.g. a --time-budget stop: the summary gets its own line
    write_files(a, out, search, requested, airframe, *terrain);
    tw::SweepReportInfo info{a.terrain_path, a.airframe_path.empty() ? "built-in f450" : a.airframe_path, a.o};
    if (a.o.simulation.contact == tw::TerrainContact::HeightField && terrain->height_field() != nullptr) {
      info.contact = std::string(tw::to_string(tw::TerrainContact::HeightField));
    }
    std::cout << (a.json ? tw::sweep_json(search, info) + "\n" : tw::sweep_summary(search, info));
    return td::app::kExitOk;
  });
}
