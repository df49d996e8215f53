#pragma once
/// \file
/// SVG figures of a landing sweep for people deciding whether to land: S(ψ)
/// per heading with every run, the threshold and why each heading is
/// unsafe; and, for a landing-point search, a top view of the terrain with
/// the candidates coloured by their best S and the chosen (x, y, ψ) drawn as
/// the airframe's footprint.
#include <string>

#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/sweep.hpp"
#include "touchdown/twin/terrain_model.hpp"

namespace touchdown::twin {

struct SweepPlotLabels {
  std::string terrain;   ///< shown in the title (e.g. the file name)
  std::string airframe;  ///< shown in the title
};

/// The S(ψ) figure: x heading [deg] over [0, ψ_max), y final nutation [rad]
/// (the table's units; the threshold is also given in degrees). Settled runs
/// are dots (strikes and tip-overs marked), runs that did not settle sit in
/// an "invalid" band above the axes, values beyond the axis are arrows at
/// its top, headings over unobserved terrain are shaded.
std::string sweep_plot_svg(const SweepResult& result, const SweepPlotLabels& labels);

/// The S(ψ) figure and, below it, the search's top view: the terrain's
/// height (unobserved cells hatched, off-scan blank) around the requested
/// point, every candidate coloured by its best S (hollow: not covered or not
/// scored; small: not flown), and the chosen point with the airframe's arms,
/// propellers, body and feet at the chosen heading.
std::string search_plot_svg(const SearchResult& search, const Eigen::Vector2d& requested, double radius,
                            const Airframe& airframe, const TerrainModel& terrain, const SweepPlotLabels& labels);

}  // namespace touchdown::twin
