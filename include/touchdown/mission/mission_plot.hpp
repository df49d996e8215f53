#pragma once
/// \file
/// Figures of a recorded mission (MissionResult::trace), like the
/// non-robocentric landing paper's Figs. 6–8, and of the envelope: SVG text
/// (render with rsvg-convert). Every time plot marks the state changes.
#include <string>
#include <vector>

#include "touchdown/mission/mission.hpp"

namespace touchdown::mission {

/// x, y, z against time: the drone (truth), its estimate, the setpoint it
/// flies and the pad (three panels, world frame).
std::string plot_positions(const MissionResult& result, const std::string& title);
/// The same for the velocities.
std::string plot_velocities(const MissionResult& result, const std::string& title);
/// The pose measurement's error and the tracking error (setpoint − truth)
/// against time.
std::string plot_errors(const MissionResult& result, const std::string& title);
/// Top view: the drone's and the pad's paths, the state changes marked.
std::string plot_top_view(const MissionResult& result, const std::string& title);

/// One cell of the envelope: the vehicle's speed, the wind and the share of
/// missions that landed.
struct EnvelopeCell {
  double speed = 0, wind = 0;
  int runs = 0, landed = 0;
  int crashed = 0;    ///< of the runs (the others that did not land aborted or timed out)
  bool valid = true;  ///< false: the options refuse this speed (not flown; shown as n/a)
  /// Why the runs that did not land did not (failure_reason), most
  /// frequent first.
  FailureCounts reasons;
  /// Of the landed runs (0 when none landed): touchdown error from the pad
  /// centre [m] and relative speed at touchdown [m/s], median and 95th
  /// percentile.
  double error_median = 0, error_p95 = 0, speed_median = 0, speed_p95 = 0;
  [[nodiscard]] double success() const { return runs > 0 ? static_cast<double>(landed) / runs : 0.0; }
};
/// The success rate over vehicle speed × wind as a coloured grid (each
/// cell also names the most frequent reason its missions did not land).
std::string plot_envelope(const std::vector<EnvelopeCell>& cells, const std::string& title);

}  // namespace touchdown::mission
