#pragma once
/// \file
/// The landing sweep's outputs, in the formats landing_sweep writes
/// (docs/cli.md, "landing_sweep"): every run as CSV, the decision with its
/// headings (and, for a search, its points) as JSON, and the summary table.
#include <string>

#include "touchdown/twin/sweep.hpp"

namespace touchdown::twin {

/// What the report names: the terrain and airframe as the user gave them,
/// and the sweep's options (landing point, headings, runs).
struct SweepReportInfo {
  std::string terrain;
  std::string airframe = "built-in f450";
  SweepOptions options;
  /// The contact the landings used: options.simulation.contact, except
  /// "trimesh" when the height field was asked for on a terrain that is
  /// not one (TerrainModel::height_field).
  std::string contact = "trimesh";
};

/// One row per run: heading, run, status and reason, the final attitude,
/// strikes and contacts, the perturbed conditions and the simulated time.
[[nodiscard]] std::string runs_csv(const SweepResult& r);

/// The decision as one JSON line: threshold, land or not and why, the best
/// heading, every heading's score and counts, the search's points, and how
/// many landings ran how fast (NaN scores as null).
[[nodiscard]] std::string sweep_json(const SearchResult& search, const SweepReportInfo& info);

/// The summary for a person: landings and speed, the threshold, the table
/// of headings, the search's points and the decision. Ends in a newline.
[[nodiscard]] std::string sweep_summary(const SearchResult& search, const SweepReportInfo& info);

}  // namespace touchdown::twin
