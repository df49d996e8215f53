#pragma once
/// \file
/// Hand-built scenarios for testing a landing system (no GoogleTest here:
/// the contract suite, landing_system_contract.hpp, and the project's own
/// closed-loop tests start from them).
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario::contract {

/// The clear scenario of the closed-loop tests: clear weather, a 1 m 4X4_50
/// marker (id 3) at the origin, the drone 8 m west at 12 m, the GPS target
/// 1 m off.
inline Scenario clear_scenario(double time_limit = 60) {
  Scenario s;
  s.map = MapKind::Ground;
  s.seed = 7;
  s.time_limit = time_limit;
  s.marker.dictionary = "4X4_50";
  s.marker.id = 3;
  s.marker.size = 1.0;
  s.drone.position = {-8, 0, 12};
  s.drone.gps_error = {1.0, -0.5};
  return s;
}

}  // namespace touchdown::scenario::contract
