#pragma once
/// \file
/// The landing sweep (digital-twin landing method): land the twin at n
/// headings × m noisy runs, score each heading by its worst final nutation
/// (eq. 6), pick the lowest (eq. 7) if it is below the safety threshold.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/enum_names.hpp"
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

}  // namespace touchdown::twin

template <>
struct touchdown::EnumNames<touchdown::twin::SafetyMetric> {
  static constexpr std::array<std::string_view, 2> names{"full", "seed"};
};

namespace touchdown::twin {

inline std::string_view to_string(SafetyMetric metric) { return enum_name(metric); }

struct SweepOptions {
  static constexpr int kMaxHeadings = 3600;           ///< one every 0.1°
  static constexpr int kMaxRuns = 10000;              ///< per heading
  static constexpr long long kMaxLandings = 1000000;  ///< headings × runs
  int headings = 20;                                  ///< n, 1..kMaxHeadings
  int runs = 10;                                      ///< m per heading, 1..kMaxRuns
  /// ψ_max; 0 = automatic: 360° / Airframe::symmetry_order() (the
  /// airframe's contact geometry repeats after that turn).
  double yaw_max_deg = 0;
  Eigen::Vector2d landing_point = Eigen::Vector2d::Zero();
  double hover_offset = 0.8;  ///< Δz [m], in (0, kMaxHoverOffset]
  /// validate() also refuses a descent (hover_offset / land_speed) not
  /// shorter than simulation.timeout: every run would time out in the air.
  static constexpr double kMaxHoverOffset = 10;
  double land_speed = 0.7;  ///< MPC_LAND_SPEED [m/s]
  Perturbation perturbation{};
  SafetyMetric metric = SafetyMetric::Full;
  std::uint64_t seed = 1;
  int threads = 0;  ///< 0 = every core (core/batch.hpp's rule)
  /// Anytime use: stop after the round (one run per heading) that exceeds
  /// this many wall seconds; 0 = no limit. The result says how complete it is.
  double time_budget = 0;
  /// Decision mode: fly only the landings that can change the decision —
  /// a heading stops at its first run that makes it unsafe or once its
  /// worst run so far ranks it behind the best complete safe heading. The
  /// decision, the chosen heading and its S are the full sweep's, bit for
  /// bit, for any thread count; the other headings' scores are partial
  /// (HeadingScore::flown says how far each went). Not with time_budget.
  bool decide = false;
  /// With `decide`: no wave of landings starts after this many wall
  /// seconds since the call; 0 = none. The headings not settled by then
  /// are HeadingFlown::UntilDeadline and SweepResult::decided is false; a
  /// safe answer is a complete safe heading (safe in the full sweep too),
  /// not necessarily its best; "do not land" when none is complete and
  /// safe. Not deterministic (it depends on the wall clock). Once every
  /// heading is unsafe it stops: "do not land" is settled (the lowest S
  /// reported is then the lowest so far, not necessarily the full sweep's).
  double deadline = 0;
  SimulationOptions simulation{};  ///< tip_nutation is set from the threshold
  /// Called after each finished landing (from worker threads, serialised).
  ProgressCallback progress;

  [[nodiscard]] bool validate(std::string* why) const;
};

/// How far the decision mode flew a heading's runs (SweepOptions::decide).
enum class HeadingFlown {
  All,             ///< every run (the full sweep flies every heading so)
  UntilUnsafe,     ///< until a run made it unsafe: settled
  UntilOutranked,  ///< until its worst run ranked it behind the chosen heading: it cannot be chosen, its safety unknown
  UntilDeadline,   ///< the deadline came first: not settled
};

}  // namespace touchdown::twin

template <>
struct touchdown::EnumNames<touchdown::twin::HeadingFlown> {
  static constexpr std::array<std::string_view, 4> names{"all", "until unsafe", "until outranked",
                                                         "until the deadline"};
};

namespace touchdown::twin {

inline std::string_view to_string(HeadingFlown flown) { return enum_name(flown); }

struct HeadingScore {
  double yaw = 0;  ///< ψ_j [rad]
  /// S(ψ) = max over the settled runs of the final nutation (eq. 6) [rad].
  /// Runs that did not settle (timeout, unstable) are not scored: NaN when
  /// no run settled. A heading with any such run is unsafe.
  double score = 0;
  double mean = 0;           ///< mean final nutation of the settled runs [rad] (NaN if none)
  double max_touchdown = 0;  ///< max nutation during touchdown over settled runs [rad]
  int runs = 0;
  /// Settled runs with each kind of strike (a run counts once per kind).
  int prop_strike_runs = 0, arm_strike_runs = 0, body_strike_runs = 0;
  int tipped_runs = 0, feet_not_all_down_runs = 0;
  int invalid_runs = 0;  ///< timeout_runs + unstable_runs
  int timeout_runs = 0, unstable_runs = 0;
  /// "timeout: …" / "unstable: …" of the first invalid run; empty if none.
  std::string invalid_reason;
  /// The twin's feet, arms, propellers or body would be over terrain the
  /// camera never observed (TerrainModel::unknown_under): never safe.
  bool unobserved = false;
  double max_offset = 0;  ///< [m]
  bool safe = false;      ///< under the threshold and clean by the chosen metric (decision mode: and every run flown)
  HeadingFlown flown = HeadingFlown::All;  ///< decision mode: how far its runs were flown (`runs` of them)
  /// Why the heading is unsafe (the most severe reason, a fixed phrase:
  /// see to_string(UnsafeReason)); None when safe.
  enum class UnsafeReason {
    None,
    UnobservedTerrain,
    InvalidRuns,
    TipsOver,
    BodyStrike,
    ArmStrike,
    PropellerStrike,
    AboveThreshold
  } reason = UnsafeReason::None;
  [[nodiscard]] bool scored() const { return runs > invalid_runs; }
};
using UnsafeReason = HeadingScore::UnsafeReason;

}  // namespace touchdown::twin

/// "unobserved terrain", "invalid runs", "tips over", "body strike", "arm
/// strike", "propeller strike", "S above the threshold" ("" for None).
template <>
struct touchdown::EnumNames<touchdown::twin::UnsafeReason> {
  static constexpr std::array<std::string_view, 8> names{
      "",           "unobserved terrain", "invalid runs",         "tips over", "body strike",
      "arm strike", "propeller strike",   "S above the threshold"};
};

namespace touchdown::twin {

inline std::string_view to_string(UnsafeReason reason) { return enum_name(reason); }

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

}  // namespace touchdown::twin

template <>
struct touchdown::EnumNames<touchdown::twin::SweepStatus> {
  static constexpr std::array<std::string_view, 2> names{"ok", "footprint_not_covered"};
};

namespace touchdown::twin {

inline std::string_view to_string(SweepStatus status) { return enum_name(status); }

struct SweepResult {
  SweepStatus status = SweepStatus::Ok;
  std::string message;  ///< why, when status is not Ok
  [[nodiscard]] bool ok() const { return status == SweepStatus::Ok; }
  SafetyThreshold threshold;
  Eigen::Vector2d landing_point = Eigen::Vector2d::Zero();  ///< (x_lp, y_lp) swept
  double ground_z = 0;                                      ///< z_lp used
  double yaw_max = 0;                                       ///< ψ_max used [rad]: headings are j ψ_max / n
  std::vector<HeadingScore> headings;
  /// Index of ψ*: the lowest score among safe headings, else the lowest
  /// score among scored headings; -1 when no run at any heading settled.
  int best = -1;
  bool safe = false;            ///< ψ* is safe: land there; false: do not land
  std::vector<RunRecord> runs;  ///< heading-major
  int rounds_completed = 0;     ///< runs per heading actually flown (anytime; 0 in decision mode)
  /// rounds_completed / runs; in decision mode the share of the full
  /// sweep's landings flown.
  double completeness = 0;
  /// The decision is the full sweep's (false only when a decision mode's
  /// deadline stopped it first).
  bool decided = true;
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
  bool evaluated = false;   ///< swept (false: beyond the nearest safe point's ring)
  bool covered = false;     ///< the terrain covers the footprint there
  bool unobserved = false;  ///< every heading is over unobserved terrain
  int best = -1;            ///< best heading index at this point (-1: no run settled)
  double yaw = 0;           ///< its heading [rad]
  double score = 0;         ///< its S(ψ) [rad]; NaN when no run settled
  bool safe = false;
};

struct SearchResult {
  /// FootprintNotCovered when no candidate is covered (then best is -1).
  SweepStatus status = SweepStatus::Ok;
  std::string message;
  [[nodiscard]] bool ok() const { return status == SweepStatus::Ok; }
  std::vector<SearchCandidate> candidates;
  int best = -1;      ///< index into candidates
  SweepResult sweep;  ///< the full sweep at the best candidate (its own runs, seconds, ...)
  /// Totals over every candidate swept, the chosen one included (what the
  /// search cost; `sweep` has the chosen point's own figures).
  int points_flown = 0;          ///< candidates evaluated and covered (their sweeps flew landings)
  std::size_t landings = 0;      ///< landings flown at all points
  double seconds = 0;            ///< wall time of the whole search
  double simulated_seconds = 0;  ///< sum over all landings flown
  double run_sim_to_wall = 0;    ///< median over all landings of simulated / wall time of one run
};

/// Which safe candidate a search returns.
enum class SearchPreference {
  LowestScore,  ///< the lowest S among safe points (ties: the nearer one)
  Nearest,      ///< the safe point nearest the requested one (ties: the lower S); farther rings are not flown
};

}  // namespace touchdown::twin

/// As landing_sweep's --search-prefer spells them.
template <>
struct touchdown::EnumNames<touchdown::twin::SearchPreference> {
  static constexpr std::array<std::string_view, 2> names{"lowest", "nearest"};
};

namespace touchdown::twin {

inline std::string_view to_string(SearchPreference preference) { return enum_name(preference); }

/// Beyond the paper: also explores landing points on a square grid of
/// `spacing` (0: radius / 2) within `radius` of options.landing_point, runs
/// the sweep at each, nearest first, and returns the best (x, y, ψ) by
/// `prefer`. Without a safe point, the lowest score among the covered
/// points, reported unsafe. Points where the terrain does not cover the
/// footprint are skipped; points over unobserved terrain are unsafe (so
/// never chosen as safe).
SearchResult search_landing_point(const Airframe& airframe, std::shared_ptr<const TerrainModel> terrain,
                                  const SweepOptions& options, double radius, double spacing = 0,
                                  SearchPreference prefer = SearchPreference::LowestScore);

/// Why no heading is safe, one class per reason with its heading count,
/// most severe first: "6 headings: propeller strike; 2 headings: invalid
/// runs (timeout: did not come to rest before the timeout)". Empty when
/// the sweep found a safe heading.
std::string unsafe_summary(const SweepResult& result);

/// The conditions of run `run` at heading `heading` (what run_sweep flies).
LandingConditions sweep_conditions(const SweepOptions& options, double ground_z, double yaw, int heading, int run);

}  // namespace touchdown::twin
