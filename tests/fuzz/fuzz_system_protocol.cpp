// libFuzzer target for the host's reader of the system protocol
// (touchdown/scenario/system_protocol.hpp): a process system's header line
// and its hello and command payloads, and the system side's readers of the
// setup and state payloads. Any bytes give a header, hello and output that
// are safe to use (sizes within the limits, finite numbers, a non-empty
// name), a setup and state read without undefined behaviour, or
// ProtocolError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/scenario/system_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace tp = touchdown::scenario::protocol;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const std::size_t eol = text.find('\n');
  const std::string_view line = text.substr(0, eol);
  const std::string_view rest = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
  try {
    const tp::Header h = tp::parse_header(line);
    if (h.verb.empty()) __builtin_trap();
    for (const std::size_t n : h.sizes) {
      if (n > tp::kMaxPayload) __builtin_trap();
    }
    try {
      const tp::Hello hello = tp::parse_hello(h, rest);
      if (hello.name.empty() || hello.version != 1) __builtin_trap();
    } catch (const tp::ProtocolError&) {
    }
  } catch (const tp::ProtocolError&) {
  }
  try {
    std::string phase;
    const touchdown::scenario::SystemOutput out = tp::parse_output(rest, phase);
    if (!out.command.velocity_world.allFinite() || !std::isfinite(out.command.yaw_rate_deg)) __builtin_trap();
    if (!out.target.allFinite() || phase.size() > 64 || out.phase != phase) __builtin_trap();
    for (const auto& d : out.detections) {
      for (const auto& c : d.corners) {
        if (!c.allFinite()) __builtin_trap();
      }
      if (!std::isfinite(d.quality) || !std::isfinite(d.confidence) || !d.ground.allFinite()) __builtin_trap();
    }
  } catch (const tp::ProtocolError&) {
  }
  // The system side (a C++ system behind `exec:`) reads setup and state.
  try {
    (void)tp::parse_setup(rest);
  } catch (const tp::ProtocolError&) {
  }
  try {
    const tp::StepState st = tp::parse_state(rest);
    if (!st.state.position.allFinite() || !std::isfinite(st.state.t)) __builtin_trap();
  } catch (const tp::ProtocolError&) {
  }
  return 0;
}
