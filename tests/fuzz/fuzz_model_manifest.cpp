// libFuzzer target for the learned detector's model manifest reader
// (scenario/learned_detector.hpp): any bytes give a manifest whose values
// are in range, or InvalidArgument naming the file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scenario/learned_detector.hpp"
#include "touchdown/core/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace d = touchdown::scenario::detail;
  try {
    const d::ModelManifest m =
        d::parse_model_manifest(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    if (m.stride < 1 || m.width % m.stride != 0 || m.height % m.stride != 0 || m.channels != 11) __builtin_trap();
    if (!(m.corner_scale > 0) || !(m.pad_value >= 0 && m.pad_value <= 1)) __builtin_trap();
    if (m.verifier) {
      const d::VerifierManifest& v = *m.verifier;
      // The verifier's file is beside the manifest, never elsewhere.
      if (v.file.parent_path() != "" || v.file.filename() == ".." || v.file.filename() == ".") __builtin_trap();
      if (v.patch < 8 || v.max_proposals < 1 || !(v.proposal_threshold > 0 && v.proposal_threshold <= 1) ||
          !(v.min_range >= 1) || v.cells < 3)
        __builtin_trap();
    }
  } catch (const touchdown::InvalidArgument&) {
  }
  return 0;
}
