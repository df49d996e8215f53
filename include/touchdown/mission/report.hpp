#pragma once
/// \file
/// The mission's reports, in the formats landing_mission writes (docs/cli.md,
/// "landing_mission"): the missions as one JSON line, their summary for a
/// person, run 0's trace as CSV, and the envelope (share landed over vehicle
/// speed × wind) with its JSON and table. For a program of your own that
/// flies missions and reports them the same way.
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/mission/mission.hpp"
#include "touchdown/mission/mission_plot.hpp"

namespace touchdown::mission {

/// The summary over runs: counts, success rate, nearest-rank percentiles of
/// the landings' touchdown error and speed (NaN when none landed), the
/// largest tracking error, axis speed and acceleration against the limits,
/// medians of the replanning time, pose error, mission and landing time.
struct MissionSummary {
  int runs = 0, landed = 0, crashed = 0, aborted = 0, timeout = 0;
  FailureCounts reasons;  ///< why the others did not land, most frequent first
  double error_median = 0, error_p95 = 0, error_max = 0;
  double speed_median = 0, speed_p95 = 0, speed_max = 0;
  double tracking_max = 0, axis_speed_max = 0, axis_accel_max = 0, v_limit = 0, a_limit = 0;
  double replan_ms_median = 0, pose_error_median = 0, duration_median = 0;
  double landing_time_median = 0;
  [[nodiscard]] double success() const { return runs ? static_cast<double>(landed) / runs : 0.0; }
};
[[nodiscard]] MissionSummary summarise(const std::vector<MissionResult>& results);

/// What ran: the mission's name (a file or "built-in circle mission"), the
/// first seed, the perception in the loop.
struct MissionRunInfo {
  std::string source;
  std::uint64_t seed = 1;
  std::string perception;
};

/// Every mission and their summary as one JSON line (keys sorted), with the
/// wall time `seconds`.
[[nodiscard]] std::string missions_json(const MissionRunInfo& info, const std::vector<MissionResult>& results,
                                        double seconds);

/// The summary for a person (`options`' vehicle path and speed named).
/// Ends in a newline.
[[nodiscard]] std::string summary_text(const MissionRunInfo& info, const MissionOptions& options,
                                       const MissionSummary& s, double seconds);

/// A recorded mission's trace (MissionResult::trace, 50 Hz) as CSV.
[[nodiscard]] std::string trace_csv(const MissionResult& r);

/// "gave up: low_off_centre 2, timeout in tracking 1".
[[nodiscard]] std::string reasons_text(const FailureCounts& reasons);

/// The envelope: `runs` missions per cell of vehicle speed × wind (the
/// wind along x, gusts of a quarter of it; the vehicle's wheels allowed the
/// speed's need, the drone's limits the file's), cells wind-major. A cell
/// whose options the drone's limits refuse is not flown (valid = false) and
/// `refused` says why, per speed.
struct Envelope {
  std::vector<double> speeds, winds;
  int runs = 0;
  TurbulenceLevel turbulence = TurbulenceLevel::None;  ///< in every cell
  std::vector<EnvelopeCell> cells;
  std::vector<std::pair<double, std::string>> refused;  ///< speed, why
};
[[nodiscard]] Envelope run_envelope(const MissionOptions& base, const std::vector<double>& speeds,
                                    const std::vector<double>& winds, int runs, std::uint64_t seed, int threads,
                                    const ProgressCallback& progress = {});

/// The envelope's cells as one JSON line (keys sorted).
[[nodiscard]] std::string envelope_json(const Envelope& e, std::string_view source, std::uint64_t seed);

/// The envelope as a table for a person (winds down, speeds across), the
/// reasons and the refused speeds. Ends in a newline.
[[nodiscard]] std::string envelope_text(const Envelope& e, std::string_view source);

}  // namespace touchdown::mission
