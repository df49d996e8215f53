#pragma once
/// \file
/// Which landing system a campaign or a search tests. The library takes a
/// SystemFactory (it makes one fresh system per worker thread); the command
/// line names one with a spec string:
///   NAME                 a registered system: the built-ins (opencv-mls,
///                        learned-mls, mm-mls) and those of loaded plug-ins;
///   plugin:PATH[:NAME]   a shared library built against this touchdown
///                        (touchdown/scenario/plugin.hpp), loaded once;
///                        NAME picks one of its systems (may be left out
///                        when it registers exactly one).
/// A SystemFactory made from a spec resolves it when a system is made, so
/// that a bad spec fails there with one line naming it (InvalidArgument).
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/registry.hpp"
#include "touchdown/scenario/landing_system.hpp"

namespace touchdown::scenario {

/// Makes a fresh system from the reference systems' options (a system of
/// your own may ignore them). Called concurrently from worker threads.
using MakeSystem = std::function<std::unique_ptr<LandingSystem>(const MlsOptions&)>;

/// The registry of landing systems (built-ins registered; a plug-in adds to it).
Registry<MakeSystem>& system_registry();

class SystemFactory {
 public:
  /// opencv-mls.
  SystemFactory();
  /// A spec (see the file comment), resolved when a system is made. Implicit,
  /// so that options take a name as before (`options.system = "mm-mls"`).
  SystemFactory(std::string spec);  // NOLINT(google-explicit-constructor,hicpp-explicit-conversions)
  SystemFactory(const char* spec);  // NOLINT(google-explicit-constructor,hicpp-explicit-conversions)
  /// A factory of your own, not registered: `name` is what results record.
  SystemFactory(std::string name, MakeSystem make);

  /// The spec or the name given: what campaign.json and the results record.
  [[nodiscard]] const std::string& name() const { return name_; }
  /// A fresh system. Throws InvalidArgument for a spec that does not
  /// resolve (unknown name, a plug-in that cannot be loaded), for options
  /// the factory refuses, or when the factory returns null.
  [[nodiscard]] std::unique_ptr<LandingSystem> make(const MlsOptions& options = {}) const;

  friend bool operator==(const SystemFactory& a, std::string_view name) { return a.name_ == name; }

 private:
  std::string name_;
  MakeSystem make_;  ///< empty: name_ is a spec, resolved by each make()
};

/// Resolves a spec (file comment) to its factory: a registered name, or a
/// plug-in's system (loading the library on first use). Throws
/// InvalidArgument naming the spec and what is wrong.
MakeSystem resolve_system(std::string_view spec);

/// Loads a plug-in library (once per path; later calls return the same) and
/// returns the names of the systems it registered. Throws InvalidArgument:
/// the file cannot be loaded, has no touchdown entry point, was built
/// against another touchdown or compiler ABI (refused before any of its
/// code runs), or registers nothing or a name already taken.
std::vector<std::string> load_system_plugin(const std::string& path);

}  // namespace touchdown::scenario
