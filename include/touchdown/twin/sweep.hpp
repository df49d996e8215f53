#pragma once
/// \file
/// The landing sweep (digital-twin landing method): land the twin at n
/// headings × m noisy runs, score each heading by its worst final nutation
/// (eq. 6), pick the lowest (eq. 7) if it is below the safety threshold.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/terrain_model.hpp"
#include "touchdown/twin/threshold.hpp"

namespace touchdown::twin {

/// Per-run perturbations (each run draws its own, seeded from (seed, heading, run)).
struct Perturbation {
  double sigma_xy = 0.015;         ///< horizontal start position σ [m]
  double sigma_yaw_deg = 1.0;      ///< heading σ
  double sigma_tilt_deg = 0.5;     ///< initial roll and pitch σ
  double sigma_land_speed = 0.05;  ///< [m/s]
  double friction_min = 0.6;       ///< ground friction drawn uniformly from [min, max]
  double friction_max = 1.0;
};

enum class SafetyMetric {
  Full,  ///< unsafe if any run strikes a propeller/arm/body, tips over or is invalid
  Seed,  ///< the paper's rule: final nutation only (invalid runs still unsafe)
};

struct SweepOptions {
  int headings = 20;       ///< n
  int runs = 10;           ///< m per heading
  double yaw_max_deg = 0;  ///< ψ_max; 0 = 180 if the airframe is half-turn symmetric, else 360
  Eigen::Vector2d landing_point = Eigen::Vector2d::Zero();
  double hover_offset = 0.8;  ///< Δz [m]
  double land_speed = 0.7;    ///< MPC_LAND_SPEED [m/s]
  Perturbation perturbation{};
  SafetyMetric metric = SafetyMetric::Full;
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0 = all cores
  /// Anytime use: stop after the round (one run per heading) that exceeds
  /// this many wall seconds; 0 = no limit. The result says how complete it is.
  double time_budget = 0;
  SimulationOptions simulation{};  ///< tip_nutation is set from the threshold
  /// Called after each finished landing (from worker threads, serialised).
  std::function<void(std::size_t done, std::size_t total)> progress;

  [[nodiscard]] bool validate(std::string* why) const;
};

struct HeadingScore {
  double yaw = 0;            ///< ψ_j [rad]
  double score = 0;          ///< S(ψ) = max over runs of the final nutation (eq. 6) [rad]
  double mean = 0;           ///< mean final nutation [rad]
  double max_touchdown = 0;  ///< max nutation during touchdown over runs [rad]
  int runs = 0;
  int prop_strike_runs = 0, arm_strike_runs = 0, body_strike_runs = 0;
  int tipped_runs = 0, invalid_runs = 0, feet_not_all_down_runs = 0;
  double max_offset = 0;  ///< [m]
  bool safe = false;      ///< under the threshold and clean by the chosen metric
};

struct RunRecord {
  int heading = 0, run = 0;
  LandingConditions conditions;
  RunResult result;
  double wall_seconds = 0;  ///< wall time of this run on its thread (not deterministic)
};

/// Expected outcomes of a sweep (not errors: the terrain is what it is).
enum class SweepStatus {
  Ok,                   ///< headings scored; `safe` says whether to land
  FootprintNotCovered,  ///< the terrain does not cover the twin's footprint at the landing point
};
std::string_view to_string(SweepStatus status);

struct SweepResult {
  SweepStatus status = SweepStatus::Ok;
  std::string message;  ///< why, when status is not Ok
  [[nodiscard]] bool ok() const { return status == SweepStatus::Ok; }
  SafetyThreshold threshold;
  double ground_z = 0;  ///< z_lp used
  std::vector<HeadingScore> headings;
  int best = -1;                 ///< index of ψ* (lowest score among safe headings, else lowest score)
  bool safe = false;             ///< ψ* is safe: land there; false: do not land
  std::vector<RunRecord> runs;   ///< heading-major
  int rounds_completed = 0;      ///< runs per heading actually flown (anytime)
  double completeness = 0;       ///< rounds_completed / runs
  double seconds = 0;            ///< wall time
  double simulated_seconds = 0;  ///< sum over runs
  double run_sim_to_wall = 0;    ///< median over runs of simulated / wall time of one run
  [[nodiscard]] std::size_t landings() const { return runs.size(); }
};

/// Runs the sweep. Deterministic: same options and seed → identical result
/// for any thread count. Throws InvalidArgument for invalid options or an
/// invalid airframe; a terrain that does not cover the footprint around the
/// landing point is status FootprintNotCovered (no headings, no runs).
SweepResult run_sweep(const Airframe& airframe, std::shared_ptr<const TerrainModel> terrain,
                      const SweepOptions& options);

/// One candidate landing point of a search.
struct SearchCandidate {
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  bool covered = false;  ///< the terrain covers the footprint there
  int best = -1;         ///< best heading index at this point
  double yaw = 0;        ///< its heading [rad]
  double score = 0;      ///< its S(ψ) [rad]
  bool safe = false;
};

struct SearchResult {
  /// FootprintNotCovered when no candidate is covered (then best is -1).
  SweepStatus status = SweepStatus::Ok;
  std::string message;
  [[nodiscard]] bool ok() const { return status == SweepStatus::Ok; }
  std::vector<SearchCandidate> candidates;
  int best = -1;      ///< index into candidates
  SweepResult sweep;  ///< the full sweep at the best candidate
};

/// Beyond the paper: also explores landing points on a square grid of
/// `spacing` (0: radius / 2) within `radius` of options.landing_point, runs
/// the sweep at each, and returns the best (x, y, ψ): the lowest score among
/// safe points, ties going to the point nearer the requested one. Points
/// where the terrain does not cover the footprint are skipped.
SearchResult search_landing_point(const Airframe& airframe, std::shared_ptr<const TerrainModel> terrain,
                                  const SweepOptions& options, double radius, double spacing = 0);

/// The conditions of run `run` at heading `heading` (what run_sweep flies).
LandingConditions sweep_conditions(const SweepOptions& options, double ground_z, double yaw, int heading, int run);

}  // namespace touchdown::twin
