// libFuzzer target for the mission file parser (mission/mission_io.hpp).
// Relative airframe paths resolve against the bundled missions' folder, so
// the seed (a copy of data/missions/circle.yaml) reads its airframe.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/mission/mission_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto f = touchdown::mission::parse_mission(std::string_view(reinterpret_cast<const char*>(data), size),
                                                     "fuzz.yaml", TOUCHDOWN_MISSIONS_DIR);
    // A parsed mission always validates.
    std::string why;
    if (!f.options.validate(&why)) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
