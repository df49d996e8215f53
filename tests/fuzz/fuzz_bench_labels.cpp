// libFuzzer target for the detector benchmark's label reader
// (touchdown/scenario/detector_bench.hpp): any bytes give labels that are
// safe to use (an image path inside the dataset, finite numbers), or
// ParseError naming the file and line.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "touchdown/core/error.hpp"
#include "touchdown/scenario/detector_bench.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ts = touchdown::scenario;
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    for (const ts::BenchLabel& l : ts::parse_bench_labels(in, "labels.jsonl")) {
      if (l.image.empty() || l.image.front() == '/' || l.image.find("..") != std::string::npos) __builtin_trap();
      if (!std::isfinite(l.distance) || !l.box_min.allFinite() || !l.box_max.allFinite()) __builtin_trap();
      (void)ts::bench_role(l);
    }
  } catch (const touchdown::ParseError&) {
  }
  return 0;
}
