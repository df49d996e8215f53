#pragma once
/// \file
/// touchdown's system protocol (version 1; docs/formats.md, "System
/// protocol"), both sides: what the host (process_system.hpp) writes and
/// reads, and serve_system(), which runs any LandingSystem as a process
/// system on stdin/stdout, for a system written in C++ that is to run in
/// its own process.
///
/// A message is one header line of ASCII, `VERB N1 N2 …\n`, then payloads
/// of exactly N1, N2, … bytes. Host → system: `touchdown-system 1` (no
/// payload), `reset J` (J: the setup, JSON), `step J I M D` (the state,
/// JSON; the frame's BGR image, mask and float32 depth, each empty when no
/// frame came this step or the system did not ask for it), `bye`.
/// System → host: `touchdown-system 1 J` (JSON {name, wants}), `ready`,
/// `command J` (JSON: the output), `error T` (T: text; the run fails with it).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/scenario/landing_system.hpp"

namespace touchdown::scenario::protocol {

/// A message that breaks the protocol (its text says what and where).
class ProtocolError : public Error {
 public:
  using Error::Error;
};

inline constexpr std::size_t kMaxHeader = 256;              ///< bytes of a header line, '\n' included
inline constexpr std::size_t kMaxPayload = 256U << 20U;     ///< bytes of one payload
inline constexpr std::size_t kMaxJsonPayload = 16U << 20U;  ///< bytes of one JSON payload

struct Header {
  std::string verb;
  std::vector<std::size_t> sizes;
};

/// `line` without its '\n'. Throws ProtocolError: not printable ASCII, no
/// verb, a size that is not a decimal number or is over kMaxPayload.
Header parse_header(std::string_view line);
std::string header(std::string_view verb, const std::vector<std::size_t>& sizes = {});

/// The system's hello: its name and the frame payloads it wants.
struct Hello {
  int version = 0;
  std::string name;
  bool image = true, depth = false, mask = false;
};
/// Throws ProtocolError for a bad version line or JSON (unknown keys, an
/// empty name, an unknown payload name).
Hello parse_hello(const Header& h, std::string_view json);
std::string hello_json(const Hello& hello);

std::string setup_json(const SystemSetup& setup);
SystemSetup parse_setup(std::string_view json);

/// The step's state (and the frame's size when it has one).
std::string state_json(const SystemInput& input);
/// The state and, when the step had a frame, its width and height.
struct StepState {
  DroneState state;
  bool frame = false;
  int width = 0, height = 0;
};
StepState parse_state(std::string_view json);

/// The system's answer. `phase` receives the phase (SystemOutput::phase is
/// a view of it). Throws ProtocolError naming the key: not JSON, a missing
/// velocity, an unknown key, a wrong type, a non-finite number, corners
/// that are not four pairs.
SystemOutput parse_output(std::string_view json, std::string& phase);
std::string output_json(const SystemOutput& output);

/// Runs `system` as a process system: reads the host's messages on the
/// file descriptor `in_fd` and answers on `out_fd` (default stdin and
/// stdout) until `bye` or the end of the input. Returns 0 after bye, 1
/// after a protocol error (written to stderr). What `system` throws from
/// reset() or update() is answered as `error` (the host ends that run as
/// system-failed and goes on). For a system in C++ that the host runs with
/// exec: a main() that calls this. `hello` says which frame payloads it
/// wants (its name is the system's).
int serve_system(LandingSystem& system, const Hello& hello = {}, int in_fd = 0, int out_fd = 1);

}  // namespace touchdown::scenario::protocol
