// libFuzzer target for a results.jsonl line (touchdown/search/records.hpp).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/error.hpp"
#include "touchdown/search/records.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ts = touchdown::search;
  try {
    const ts::EvaluationRecord r =
        ts::parse_record_line(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.jsonl", 1);
    // What was parsed writes back to a line that parses to the same text
    // (doubles bit-exact), and the Evaluation alone round-trips too.
    const std::string line = ts::record_line(r);
    if (ts::record_line(ts::parse_record_line(line, "again", 1)) != line) __builtin_trap();
    const std::string e = ts::evaluation_json(r.evaluation);
    if (ts::evaluation_json(ts::parse_evaluation_json(e, "again")) != e) __builtin_trap();
  } catch (const touchdown::Error&) {
  }
  return 0;
}
