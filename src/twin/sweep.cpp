#include "touchdown/twin/sweep.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/format.hpp"
#include "touchdown/core/batch.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/core/units.hpp"
#include "twin/sweep_decide.hpp"

namespace touchdown::twin {
namespace {

using detail::format_fixed;

// The edges of the scanned area's outline: the edges of the non-vertical
// triangles (those top_z sees) that only one of them uses. A point off the
// scan is nearest to the scan on one of these (for a triangle soup, every
// edge is listed: still exact, only slower).
std::vector<std::array<Eigen::Vector2d, 2>> outline_edges(const TerrainModel& terrain) {
  const auto& mesh = terrain.mesh();
  std::vector<std::uint64_t> edges;  // lo << 32 | hi, one per use
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector2f a = mesh.vertices[t[0]].head<2>(), b = mesh.vertices[t[1]].head<2>(),
                          c = mesh.vertices[t[2]].head<2>();
    const double det = (static_cast<double>(b.x()) - a.x()) * (static_cast<double>(c.y()) - a.y()) -
                       (static_cast<double>(c.x()) - a.x()) * (static_cast<double>(b.y()) - a.y());
    if (std::abs(det) < 1e-15) continue;  // vertical: not part of the scanned area seen from above
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t u = t[static_cast<std::size_t>(k)], v = t[static_cast<std::size_t>((k + 1) % 3)];
      edges.push_back(std::min(u, v) << 32 | std::max(u, v));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::array<Eigen::Vector2d, 2>> out;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      const auto u = static_cast<std::size_t>(edges[i] >> 32), v = static_cast<std::size_t>(edges[i] & 0xffffffffu);
      out.push_back({mesh.vertices[u].head<2>().cast<double>(), mesh.vertices[v].head<2>().cast<double>()});
    }
    i = j;
  }
  return out;
}

double distance_to_segment(const Eigen::Vector2d& p, const std::array<Eigen::Vector2d, 2>& e) {
  const Eigen::Vector2d d = e[1] - e[0];
  const double len2 = d.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - e[0]).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (e[0] + t * d - p).norm();
}

double distance_to_edges(const Eigen::Vector2d& p, const std::vector<std::array<Eigen::Vector2d, 2>>& edges) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& e : edges) best = std::min(best, distance_to_segment(p, e));
  return best;
}

// Why the terrain does not cover the footprint disk: how far the disk reaches
// beyond the scanned area (the largest distance from a point of the disk,
// sampled every centimetre, to the scan), how far the landing point itself is
// from the scan when it is off it, and the scan's extent.
std::string off_scan_message(const TerrainModel& terrain, const Eigen::Vector2d& centre, double radius) {
  auto edges = outline_edges(terrain);
  // Only edges within reach matter: a point of the disk is at most
  // radius + (the centre's distance to the outline) from its nearest edge.
  const double reach = 2 * radius + distance_to_edges(centre, edges) + 1e-9;
  std::erase_if(edges, [&](const auto& e) { return distance_to_segment(centre, e) > reach; });
  const int n = std::max(1, static_cast<int>(std::ceil(radius / 0.01)));
  double overhang = 0;
  for (int j = -n; j <= n; ++j) {
    for (int i = -n; i <= n; ++i) {
      const Eigen::Vector2d p = centre + Eigen::Vector2d(i, j) * (radius / n);
      if ((p - centre).norm() > radius + 1e-12 || terrain.top_z(p.x(), p.y())) continue;
      overhang = std::max(overhang, distance_to_edges(p, edges));
    }
  }
  std::string off;
  if (!terrain.top_z(centre.x(), centre.y())) {
    off = " (the landing point itself is " + format_fixed(distance_to_edges(centre, edges), 3) + " m outside it)";
  }
  const auto& b = terrain.bounds();
  return "terrain does not cover the footprint (radius " + format_fixed(radius, 3) + " m) around the landing point (" +
         format_fixed(centre.x(), 3) + ", " + format_fixed(centre.y(), 3) + "): it sticks out of the scanned area by " +
         format_fixed(overhang, 3) + " m" + off + "; the scan covers x in [" + format_fixed(b.min.x(), 3) + ", " +
         format_fixed(b.max.x(), 3) + "], y in [" + format_fixed(b.min.y(), 3) + ", " + format_fixed(b.max.y(), 3) +
         "] m";
}

// Whether any part of the twin that can touch the ground (feet, arms,
// propellers, body), at heading `yaw` over `point`, would be over terrain the
// camera never observed; `pad` widens every part for the perturbations.
bool over_unknown(const TerrainModel& terrain, const Airframe& af, const Eigen::Vector2d& point, double yaw,
                  double pad) {
  if (terrain.unknown_cells().empty()) return false;
  const Eigen::Rotation2Dd R(yaw);
  auto world = [&](const Eigen::Vector3d& body) -> Eigen::Vector2d { return point + R * body.head<2>(); };
  for (const auto& leg : af.legs) {
    const Eigen::Vector2d p = point + R * leg;
    if (terrain.unknown_near(p, p, std::max(af.foot_radius, af.leg_radius) + pad)) return true;
  }
  for (std::size_t i = 0; i < af.motor_count(); ++i) {
    const Capsule arm = af.arm(i);
    if (terrain.unknown_near(world(arm.a), world(arm.b), arm.radius + pad)) return true;
    const Eigen::Vector2d m = world(af.motor_position(i));
    if (terrain.unknown_near(m, m, af.prop_radius + pad)) return true;
  }
  const Box body = af.body_box();
  return terrain.unknown_in_box(world(body.centre), body.half_extents.head<2>(), yaw, pad);
}

}  // namespace

bool SweepOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (headings < 1 || headings > kMaxHeadings) {
    return fail("headings must be in 1.." + std::to_string(kMaxHeadings) + " (one every 0.1 deg), got " +
                std::to_string(headings));
  }
  if (runs < 1 || runs > kMaxRuns) {
    return fail("runs must be in 1.." + std::to_string(kMaxRuns) + ", got " + std::to_string(runs));
  }
  if (const long long n = static_cast<long long>(headings) * runs; n > kMaxLandings) {
    // Refused before anything is allocated, with what it would have cost.
    return fail("headings x runs = " + std::to_string(n) + " landings is more than " + std::to_string(kMaxLandings) +
                ": ~" + std::to_string(n * static_cast<long long>(sizeof(RunRecord)) / 1'000'000) +
                " MB of run records and ~" + std::to_string(n / 100 / 3600) +
                " h at 100 landings/s; use fewer headings or runs, or --time-budget");
  }
  if (!(yaw_max_deg >= 0 && yaw_max_deg <= 360)) return fail("yaw-max must be in [0, 360] degrees (0 = automatic)");
  if (!landing_point.allFinite()) return fail("landing point must be finite");
  if (!(hover_offset > 0 && hover_offset <= kMaxHoverOffset)) {
    return fail("hover-offset must be in (0, " + touchdown::detail::format_general(kMaxHoverOffset) + "] m, got " +
                touchdown::detail::format_general(hover_offset));
  }
  if (!(land_speed > 0 && land_speed < 5)) return fail("land-speed must be in (0, 5) m/s");
  // A descent that cannot reach the ground before the timeout makes every
  // run invalid (issue 58: --hover-offset 80 "ran" 100 % invalid and exited 0).
  if (const double descent = hover_offset / land_speed; descent >= simulation.timeout) {
    return fail("hover-offset " + touchdown::detail::format_general(hover_offset) + " m at land-speed " +
                touchdown::detail::format_general(land_speed) + " m/s is a descent of " +
                touchdown::detail::format_general(descent, 3) + " s, not shorter than the timeout of " +
                touchdown::detail::format_general(simulation.timeout) +
                " s: every landing would time out before touching the ground (lower the offset, or raise the land "
                "speed or the timeout)");
  }
  const auto& p = perturbation;
  if (!(p.sigma_xy >= 0 && p.sigma_yaw_deg >= 0 && p.sigma_tilt_deg >= 0 && p.sigma_land_speed >= 0)) {
    return fail("perturbation sigmas must be >= 0");
  }
  if (!(p.friction_min > 0 && p.friction_max >= p.friction_min)) return fail("friction range must be 0 < min <= max");
  if (!check_threads(threads, "threads", why)) return false;
  if (!(time_budget >= 0)) return fail("time budget must be >= 0");
  if (!(deadline >= 0) || !std::isfinite(deadline)) return fail("deadline must be >= 0 s");
  if (deadline > 0 && !decide) return fail("a deadline needs the decision mode (the full sweep flies every landing)");
  if (decide && time_budget > 0) {
    return fail("the time budget is the full sweep's anytime mode; the decision mode has a deadline instead");
  }
  return true;
}

LandingConditions sweep_conditions(const SweepOptions& o, double ground_z, double yaw, int heading, int run) {
  // One stream per (heading, run): results do not depend on scheduling.
  Rng rng(o.seed, static_cast<std::uint64_t>(heading) * 1000003ull + static_cast<std::uint64_t>(run));
  const auto& p = o.perturbation;
  LandingConditions c;
  c.landing_point = o.landing_point;
  c.ground_z = ground_z;
  c.hover_offset = o.hover_offset;
  c.heading = yaw;
  c.start_offset = normal_vector2(rng) * p.sigma_xy;
  c.heading_error = rng.normal(0, deg_to_rad(p.sigma_yaw_deg));
  c.roll = rng.normal(0, deg_to_rad(p.sigma_tilt_deg));
  c.pitch = rng.normal(0, deg_to_rad(p.sigma_tilt_deg));
  c.land_speed = std::max(0.1, o.land_speed + rng.normal(0, p.sigma_land_speed));
  c.friction = rng.uniform(p.friction_min, p.friction_max);
  return c;
}

namespace {

// One record per (heading j, run i), with the run's perturbed conditions.
void plan_runs(SweepResult& out, const SweepOptions& o, double yaw_max) {
  const int n = o.headings, m = o.runs;
  out.runs.resize(static_cast<std::size_t>(n) * m);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < m; ++i) {
      auto& r = out.runs[static_cast<std::size_t>(j) * m + i];
      r.heading = j;
      r.run = i;
      r.conditions = sweep_conditions(o, out.ground_z, j * yaw_max / n, j, i);  // ψ_j = j ψ_max / n
    }
  }
}

// Lands every run in the twin on `o.threads` threads. With a time budget,
// round by round (run i of every heading) until the budget since `t0` is
// spent; the runs of unflown rounds are dropped.
void fly_runs(SweepResult& out, const LandingSimulator& sim, const SweepOptions& o,
              std::chrono::steady_clock::time_point t0) {
  const int n = o.headings, m = o.runs;
  const std::size_t total = out.runs.size();
  std::size_t done = 0;   // over the rounds; progress calls are serialised
  std::size_t round = 0;  // with a time budget, the round being flown
  BatchOptions batch;
  batch.threads = o.threads;
  if (o.progress) {
    batch.progress = [&](const Progress& p) {
      const std::size_t k = o.time_budget > 0 ? p.index * static_cast<std::size_t>(m) + round : p.index;
      o.progress(progress_since(t0, ++done, total, k));
    };
  }
  auto fly = [&](std::size_t k) { internal::fly_run(out.runs[k], sim); };
  // Rounds: run i of every heading, so that an interrupted (anytime) sweep
  // has the same number of runs at every heading.
  int rounds = 0;
  if (o.time_budget > 0) {
    for (int i = 0; i < m; ++i) {
      round = static_cast<std::size_t>(i);
      run_batch(static_cast<std::size_t>(n), batch, [&](std::size_t j, std::size_t) {
        fly(j * static_cast<std::size_t>(m) + static_cast<std::size_t>(i));
      });
      ++rounds;
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > o.time_budget) break;
    }
  } else {
    run_batch(total, batch, [&](std::size_t k, std::size_t) { fly(k); });
    rounds = m;
  }
  if (rounds < m) {
    std::vector<RunRecord> kept;
    for (const auto& r : out.runs) {
      if (r.run < rounds) kept.push_back(r);
    }
    out.runs = std::move(kept);
  }
  out.rounds_completed = rounds;
  out.completeness = static_cast<double>(rounds) / m;
}

// Per heading: its yaw and whether the twin would stand over unobserved
// terrain there.
void place_headings(SweepResult& out, const TerrainModel& terrain, const Airframe& airframe, const SweepOptions& o,
                    double footprint) {
  const int n = o.headings;
  const double yaw_max = out.yaw_max;
  out.headings.resize(static_cast<std::size_t>(n));
  // The perturbations move the twin by ~3 σ_xy and turn it by ~3 σ_yaw.
  const double pad = 3 * o.perturbation.sigma_xy + footprint * 3 * deg_to_rad(o.perturbation.sigma_yaw_deg);
  for (int j = 0; j < n; ++j) {
    auto& h = out.headings[static_cast<std::size_t>(j)];
    h.yaw = j * yaw_max / n;
    h.unobserved = over_unknown(terrain, airframe, o.landing_point, h.yaw, pad);
  }
}

// Each flown run into its heading's counts, S (eq. 6: the maximum of the
// settled runs' nutation) and mean.
void add_runs_to_headings(SweepResult& out) {
  for (const auto& r : out.runs) {
    auto& h = out.headings[static_cast<std::size_t>(r.heading)];
    const RunResult& res = r.result;
    ++h.runs;
    out.simulated_seconds += res.sim_time;
    if (!res.ok()) {
      ++h.invalid_runs;
      ++(res.status == RunStatus::Timeout ? h.timeout_runs : h.unstable_runs);
      if (h.invalid_reason.empty()) h.invalid_reason = std::string(to_string(res.status)) + ": " + res.message;
      continue;
    }
    h.score = std::max(h.score, res.nutation);
    h.mean += res.nutation;
    h.max_touchdown = std::max(h.max_touchdown, res.max_touchdown_nutation);
    h.prop_strike_runs += res.prop_strike;
    h.arm_strike_runs += res.arm_strike;
    h.body_strike_runs += res.body_strike;
    h.tipped_runs += res.tipped;
    h.feet_not_all_down_runs += !res.all_feet_in_contact;
    h.max_offset = std::max(h.max_offset, res.offset);
  }
}

// Per heading: the mean over its settled runs (NaN scores if none settled)
// and the first reason, in order of precedence, that makes it unsafe.
void classify_headings(SweepResult& out, const SweepOptions& o) {
  const double threshold = out.threshold.value();
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  for (auto& h : out.headings) {
    if (h.scored()) {
      h.mean /= h.runs - h.invalid_runs;
    } else {
      h.score = h.mean = h.max_touchdown = nan;
    }
    const bool full = o.metric == SafetyMetric::Full;
    if (h.unobserved) {
      h.reason = UnsafeReason::UnobservedTerrain;
    } else if (h.runs == 0 || h.invalid_runs > 0) {
      h.reason = UnsafeReason::InvalidRuns;
    } else if (full && h.tipped_runs > 0) {
      h.reason = UnsafeReason::TipsOver;
    } else if (full && h.body_strike_runs > 0) {
      h.reason = UnsafeReason::BodyStrike;
    } else if (full && h.arm_strike_runs > 0) {
      h.reason = UnsafeReason::ArmStrike;
    } else if (full && h.prop_strike_runs > 0) {
      h.reason = UnsafeReason::PropellerStrike;
    } else if (!(h.score < threshold)) {
      h.reason = UnsafeReason::AboveThreshold;
    }
    // Decision mode: safe only with every run flown (a heading stopped by
    // the deadline or outranked is not known to be safe).
    h.safe = h.reason == UnsafeReason::None && h.flown == HeadingFlown::All;
  }
}

// ψ* = argmin S over safe headings (ties: the lowest heading); if none is
// safe, the lowest score among scored headings, reported as unsafe.
void choose_best_heading(SweepResult& out, int n) {
  for (int pass = 0; pass < 2 && out.best < 0; ++pass) {
    for (int j = 0; j < n; ++j) {
      const auto& h = out.headings[static_cast<std::size_t>(j)];
      if ((pass == 0 && !h.safe) || !h.scored()) continue;
      if (out.best < 0 || h.score < out.headings[static_cast<std::size_t>(out.best)].score) out.best = j;
    }
  }
  out.safe = out.best >= 0 && out.headings[static_cast<std::size_t>(out.best)].safe;
}

// Appends each run's simulated time / wall time.
void add_sim_to_wall_ratios(const SweepResult& sweep, std::vector<double>& ratios) {
  for (const auto& r : sweep.runs) {
    if (r.wall_seconds > 0) ratios.push_back(r.result.sim_time / r.wall_seconds);
  }
}

// The median over runs of simulated time / wall time.
void median_run_sim_to_wall(SweepResult& out) {
  std::vector<double> ratios;
  add_sim_to_wall_ratios(out, ratios);
  if (!ratios.empty()) out.run_sim_to_wall = upper_median(std::move(ratios));
}

}  // namespace

SweepResult run_sweep(const Airframe& airframe, std::shared_ptr<const TerrainModel> terrain, const SweepOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("sweep options: " + why);
  if (!airframe.validate(&why)) throw InvalidArgument("airframe: " + why);
  if (!terrain) throw InvalidArgument("sweep: no terrain");

  SweepResult out;
  out.landing_point = o.landing_point;
  out.threshold = compute_safety_threshold(airframe);
  const double footprint = airframe.footprint_radius();
  const auto zlp = terrain->max_top_z(o.landing_point, footprint);
  if (!zlp) {
    out.status = SweepStatus::FootprintNotCovered;
    out.message = off_scan_message(*terrain, o.landing_point, footprint);
    return out;
  }
  out.ground_z = *zlp;

  SimulationOptions sim_opt = o.simulation;
  sim_opt.tip_nutation = out.threshold.tip_rad;
  sim_opt.controller.land_speed = o.land_speed;
  const LandingSimulator sim(airframe, terrain, sim_opt);

  const double yaw_max = deg_to_rad(o.yaw_max_deg > 0 ? o.yaw_max_deg : 360.0 / airframe.symmetry_order());
  out.yaw_max = yaw_max;
  plan_runs(out, o, yaw_max);
  place_headings(out, *terrain, airframe, o, footprint);
  if (o.decide) {
    internal::fly_decisive(out, sim, o, t0);
  } else {
    fly_runs(out, sim, o, t0);
  }

  // Scores (eq. 3 per run, eq. 6 per heading, eq. 7 overall). Only settled
  // runs have a final nutation to score; any other run makes its heading
  // unsafe (and says why) without inventing a nutation for it.
  add_runs_to_headings(out);
  classify_headings(out, o);
  choose_best_heading(out, o.headings);
  median_run_sim_to_wall(out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::string unsafe_summary(const SweepResult& r) {
  if (r.safe) return {};
  std::string out;
  for (int k = static_cast<int>(UnsafeReason::UnobservedTerrain); k <= static_cast<int>(UnsafeReason::AboveThreshold);
       ++k) {
    const auto reason = static_cast<UnsafeReason>(k);
    int count = 0;
    const HeadingScore* first = nullptr;
    for (const auto& h : r.headings) {
      if (h.reason != reason) continue;
      ++count;
      if (!first) first = &h;
    }
    if (count == 0) continue;
    if (!out.empty()) out += "; ";
    out += std::to_string(count) + (count == 1 ? " heading: " : " headings: ") + std::string(to_string(reason));
    if (reason == UnsafeReason::InvalidRuns && !first->invalid_reason.empty()) {
      out += " (" + first->invalid_reason + ")";
    }
  }
  return out;
}

SearchResult search_landing_point(const Airframe& airframe, std::shared_ptr<const TerrainModel> terrain,
                                  const SweepOptions& options, double radius, double spacing, SearchPreference prefer) {
  if (!(radius >= 0) || !std::isfinite(radius)) throw InvalidArgument("search radius must be >= 0");
  if (spacing <= 0) spacing = radius > 0 ? radius / 2 : 1.0;
  if (!(spacing > 0) || !std::isfinite(spacing)) throw InvalidArgument("search spacing must be positive");
  const auto t0 = std::chrono::steady_clock::now();
  SearchResult out;
  const double half_width = std::floor(radius / spacing + 1e-9);
  if (half_width > 50) {
    throw InvalidArgument("search radius / spacing = " + std::to_string(radius / spacing) + " gives more than " +
                          std::to_string(101 * 101) +
                          " candidate points; use a search spacing of at least radius / 50");
  }
  const int n = static_cast<int>(half_width);
  for (int j = -n; j <= n; ++j) {
    for (int i = -n; i <= n; ++i) {
      const Eigen::Vector2d d(i * spacing, j * spacing);
      if (d.norm() > radius + 1e-9) continue;
      SearchCandidate c;
      c.xy = options.landing_point + d;
      out.candidates.push_back(c);
    }
  }
  // Nearest to the requested point first (stable: row-major within a ring).
  std::stable_sort(out.candidates.begin(), out.candidates.end(),
                   [&](const SearchCandidate& a, const SearchCandidate& b) {
                     return (a.xy - options.landing_point).norm() < (b.xy - options.landing_point).norm() - 1e-12;
                   });
  // Safe beats unsafe, then the lower score. Preferring the nearest safe
  // point, the first ring with one ends the search (ties within a ring go
  // to the lower score). Without any safe point, the lowest score among the
  // covered ones is reported as unsafe.
  double safe_distance = std::numeric_limits<double>::infinity();
  auto rank = [](const SearchCandidate& x) {
    return std::isnan(x.score) ? std::numeric_limits<double>::infinity() : x.score;
  };
  // One progress count across all candidates (a candidate off the scan or
  // not flown counts as done).
  const std::size_t per = static_cast<std::size_t>(options.headings) * options.runs;
  const std::size_t total = per * out.candidates.size();
  std::vector<double> ratios;  // every landing's simulated / wall time
  for (std::size_t k = 0; k < out.candidates.size(); ++k) {
    auto& c = out.candidates[k];
    if ((c.xy - options.landing_point).norm() > safe_distance + 1e-9) break;
    c.evaluated = true;
    // Off the map: run_sweep's own check, made here so that its message (the
    // overhang, sampled over the footprint) is not built only to be dropped.
    if (!terrain->max_top_z(c.xy, airframe.footprint_radius())) continue;
    SweepOptions o = options;
    o.landing_point = c.xy;
    if (options.progress) {
      o.progress = [&options, base = k * per, total, t0](const Progress& p) {
        options.progress(progress_since(t0, base + p.done, total, base + p.index));
      };
    }
    SweepResult r = run_sweep(airframe, terrain, o);
    if (r.status == SweepStatus::FootprintNotCovered) continue;  // off the map
    c.covered = true;
    ++out.points_flown;
    out.landings += r.landings();
    out.simulated_seconds += r.simulated_seconds;
    add_sim_to_wall_ratios(r, ratios);
    c.best = r.best;
    c.yaw = r.best >= 0 ? r.headings[static_cast<std::size_t>(r.best)].yaw : 0.0;
    c.score =
        r.best >= 0 ? r.headings[static_cast<std::size_t>(r.best)].score : std::numeric_limits<double>::quiet_NaN();
    c.safe = r.safe;
    c.unobserved =
        std::all_of(r.headings.begin(), r.headings.end(), [](const HeadingScore& h) { return h.unobserved; });
    if (c.safe && prefer == SearchPreference::Nearest) {
      safe_distance = std::min(safe_distance, (c.xy - options.landing_point).norm());
    }
    const SearchCandidate* b = out.best >= 0 ? &out.candidates[static_cast<std::size_t>(out.best)] : nullptr;
    const bool better = !b || (c.safe && !b->safe) || (c.safe == b->safe && rank(c) < rank(*b));
    if (better) {
      out.best = static_cast<int>(k);
      out.sweep = std::move(r);
    }
  }
  if (options.progress) options.progress(progress_since(t0, total, total, total > 0 ? total - 1 : 0));
  out.run_sim_to_wall = upper_median(std::move(ratios));
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (out.best < 0) {
    out.status = SweepStatus::FootprintNotCovered;
    out.message = "terrain does not cover the footprint at any landing point within " + std::to_string(radius) +
                  " m of (" + std::to_string(options.landing_point.x()) + ", " +
                  std::to_string(options.landing_point.y()) + ")";
    out.sweep.status = out.status;
    out.sweep.message = out.message;
  }
  return out;
}

}  // namespace touchdown::twin
