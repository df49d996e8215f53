#pragma once
// The hand-built clear scenario that the closed-loop tests start from:
// clear weather, a 1 m 4X4_50 marker (id 3) at the origin, the drone 8 m
// west at 12 m, the GPS target 1 m off.
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario::test {

inline Scenario clear_scenario(double time_limit = 60) {
  Scenario s;
  s.map = MapKind::ground;
  s.seed = 7;
  s.time_limit = time_limit;
  s.marker.dictionary = "4X4_50";
  s.marker.id = 3;
  s.marker.size = 1.0;
  s.drone.position = {-8, 0, 12};
  s.drone.gps_error = {1.0, -0.5};
  return s;
}

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
  pole.kind = StaticKind::pole;
  pole.position = {0.2, 0.2};
  pole.size = {0.05, 0.05, 4.0};
  s.static_objects = {pole};
  return s;
}

}  // namespace touchdown::scenario::test
