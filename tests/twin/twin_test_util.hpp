#pragma once
// Analytic terrains for the twin's oracle tests.
#include <cmath>
#include <functional>
#include <memory>

#include "touchdown/terrain/height_map.hpp"
#include "touchdown/twin/terrain_model.hpp"

namespace touchdown::test {

/// A closed terrain solid of z = f(x, y) sampled on a grid of `cell` over
/// [-half, half]^2.
inline std::shared_ptr<const twin::TerrainModel> analytic_terrain(const std::function<double(double, double)>& f,
                                                                  double half = 1.0, double cell = 0.01) {
  const int n = static_cast<int>(std::round(2 * half / cell));
  terrain::HeightMap m(-half, -half, cell, n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      m.set(i, j, static_cast<float>(f(m.centre_x(i), m.centre_y(j))), terrain::CellState::Measured);
  return std::make_shared<const twin::TerrainModel>(terrain::triangulate_solid(m, 0.1));
}

inline std::shared_ptr<const twin::TerrainModel> flat_terrain(double z = 0.0) {
  return analytic_terrain([z](double, double) { return z; }, 1.0, 0.05);
}

inline std::shared_ptr<const twin::TerrainModel> incline_terrain(double angle_rad) {
  return analytic_terrain([angle_rad](double x, double) { return std::tan(angle_rad) * x; }, 1.0, 0.05);
}

}  // namespace touchdown::test
