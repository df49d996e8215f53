#pragma once
// The options that choose the landing system under test and its marker
// detector, the same in landing_scenario and landing_fuzz.
#include <CLI/CLI.hpp>
#include <string>

#include "app_common.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/system_registry.hpp"

namespace touchdown::app {

/// --system SPEC: a registered name, plugin:PATH[:NAME] or exec:COMMAND, resolved while
/// the command line is read (a plug-in is loaded then), so that an unknown
/// name or a library that cannot be loaded is refused with its reason.
inline CLI::Option* add_system_option(CLI::App& cmd, std::string& spec) {
  const std::string names = scenario::system_registry().known();
  return cmd
      .add_option("--system", spec,
                  "landing system under test: " + names +
                      " (landing_scenario systems lists them), plugin:PATH[:NAME] for a plug-in library, or "
                      "exec:'COMMAND ARGS' for a system in another process (docs/formats.md, \"System protocol\")")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            try {
              (void)scenario::resolve_system(s);
              return "";
            } catch (const Error& e) {
              return e.what();
            }
          },
          "SYSTEM"))
      ->capture_default_str();
}

/// --detector KIND of the reference systems.
inline CLI::Option* add_detector_option(CLI::App& cmd, std::string& kind) {
  return cmd
      .add_option("--detector", kind,
                  "the system's marker detector (learned-mls: always learned; the model: data/models/, or "
                  "TOUCHDOWN_MODEL)")
      ->check(one_of_names(scenario::marker_detector_names()))
      ->capture_default_str();
}

}  // namespace touchdown::app
