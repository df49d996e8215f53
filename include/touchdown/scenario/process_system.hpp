#pragma once
/// \file
/// A landing system that runs as its own process, in any language, and
/// speaks touchdown's system protocol (version 1, docs/formats.md "System
/// protocol") on its standard input and output: `--system exec:COMMAND`.
/// The host starts COMMAND with /bin/sh (`exec COMMAND`, so the system is
/// the shell's own process) with its stdin and stdout on one socket; its
/// stderr is the host's. Per run it sends the setup, then per physics step
/// the drone's state and, at the camera rate, the frame (the payloads the
/// system asked for: image, depth, mask); each answer is the command, the
/// phase, the descent and the detections.
///
/// Faults are the system's, and end its run as "system failed" (run.hpp)
/// with the reason: the process exits, gives no answer within the step
/// timeout, answers a malformed header, a payload cut short or a command
/// that is not valid. The process is then killed, and the next reset()
/// starts a fresh one. None outlives its LandingSystem (it is killed when
/// the object is destroyed) nor the host (it gets SIGKILL when the host
/// thread that started it ends: PR_SET_PDEATHSIG), so a campaign runs its
/// systems from the worker threads that use them.
#include <memory>
#include <string>
#include <string_view>

#include "touchdown/scenario/landing_system.hpp"

namespace touchdown::scenario {

/// The protocol's version: the first line of each side says it.
inline constexpr int kSystemProtocolVersion = 1;

struct ProcessOptions {
  std::string command;          ///< run by /bin/sh -c "exec COMMAND"
  double start_timeout_s = 30;  ///< for the process's hello (an interpreter may take a while to start)
  double step_timeout_s = 10;   ///< for each later answer

  /// False (with "key: what" in *why) for an empty command or a timeout
  /// outside (0, 3600] s.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Reads a spec `exec:COMMAND` or `exec,KEY=SECONDS,…:COMMAND` (KEY:
/// step-timeout, start-timeout; the options end at the first ':').
/// Throws InvalidArgument naming the spec and the key for an unknown key, a
/// value that is not a number, or options that do not validate.
ProcessOptions parse_exec_spec(std::string_view spec);

/// A system in another process. The process starts at the first reset().
/// Throws InvalidArgument for invalid options.
std::unique_ptr<LandingSystem> make_process_system(const ProcessOptions& options);

}  // namespace touchdown::scenario
