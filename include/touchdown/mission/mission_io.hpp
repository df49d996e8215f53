#pragma once
/// \file
/// The mission file of `landing_mission` (docs/formats.md, "Landing
/// mission"): vehicle, pad, drone (airframe file, controller gains, start),
/// state machine, guidance (with the planner's keys of the landing problem
/// file under `guidance.planner`), perception, wind, link and fix, in one
/// YAML file. SI units; angles in degrees in the file.
///
/// Every error is a ParseError "source:line: key: what" naming the key path
/// (`vehicle.radius`, `guidance.planner.limits.v_max`); unknown keys are
/// errors at every level; the options then validate (a vehicle speed the
/// drone cannot follow, a camera that cannot see the rendezvous point are
/// refused naming the key). Thread-safe: pure functions.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/mission/mission.hpp"

namespace touchdown::mission {

struct MissionFile {
  MissionOptions options;
  std::filesystem::path airframe;     ///< the airframe file read (empty: the built-in 180 mm quadrotor)
  std::filesystem::path vehicle_log;  ///< the vehicle log read (path log), else empty
  std::vector<std::string> warnings;  ///< values that parse but look wrong (degrees that look like radians)
};

/// Parses a mission; `base` is the directory relative paths (the airframe)
/// are taken from.
MissionFile parse_mission(std::string_view yaml_text, std::string_view source, const std::filesystem::path& base);

/// Reads and parses a mission file (IoError when it cannot be read).
MissionFile load_mission(const std::filesystem::path& path);

}  // namespace touchdown::mission
