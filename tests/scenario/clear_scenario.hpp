#pragma once
// The hand-built scenarios of the closed-loop tests. The clear one they
// start from is the LandingSystem contract suite's
// (touchdown/scenario/testing/scenarios.hpp).
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/testing/scenarios.hpp"

namespace touchdown::scenario::test {

using contract::clear_scenario;

/// The Type III case: the clear scenario with a 2 m marker and a 5 cm pole
/// 4 m high standing on it, on the diagonal 0.28 m from its centre. On the
/// approach, seen from the side, the pole crosses the code and the marker
/// is not read; from above (where the search brings the drone) the pole's
/// top and shadow hide too little of the 33 cm cells, whatever the ground
/// around (a 1 m marker is read there on few map placements). The rotor
/// disk centred at (0.16, 0.16) meets the pole on the way down; at (0.25, 0)
/// the pole would pass between two rotors.
inline Scenario pole_on_marker_scenario(double time_limit = 60) {
  Scenario s = clear_scenario(time_limit);
  s.marker.size = 2.0;
  StaticObject pole;
  pole.kind = StaticKind::Pole;
  pole.position = {0.2, 0.2};
  pole.size = {0.05, 0.05, 4.0};
  s.static_objects = {pole};
  return s;
}

}  // namespace touchdown::scenario::test
