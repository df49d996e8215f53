// libFuzzer target for the sequence.yaml parser (touchdown/pose/sim/sequence.hpp).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/pose/sim/sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace tp = touchdown::pose;
  try {
    const tp::SequenceInfo info =
        tp::parse_sequence_info(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    // What was parsed writes back to text that parses to the same values.
    const tp::SequenceInfo again = tp::parse_sequence_info(tp::sequence_info_to_yaml(info), "again");
    if (again.seed != info.seed || again.aruco.has_value() != info.aruco.has_value()) __builtin_trap();
    if (info.aruco &&
        (again.aruco->dictionary != info.aruco->dictionary || again.aruco->marker_id != info.aruco->marker_id ||
         again.aruco->marker_size != info.aruco->marker_size)) {
      __builtin_trap();
    }
  } catch (const touchdown::Error&) {
  }
  return 0;
}
