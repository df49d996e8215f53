// The landing-system registry, spec strings and plug-in loading
// (system_registry.hpp, plugin.hpp). Plug-ins are loaded with dlopen(3)
// (RTLD_NOW: an unresolved symbol fails the load, not a later call;
// RTLD_LOCAL: two plug-ins' own symbols do not meet) and never unloaded.
#include "touchdown/scenario/system_registry.hpp"

#include <dlfcn.h>

#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "scenario/mm_mls.hpp"
#include "scenario/opencv_mls.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/plugin.hpp"
#include "touchdown/scenario/process_system.hpp"

namespace touchdown::scenario {

namespace {

constexpr std::string_view kPluginPrefix = "plugin:";
constexpr std::string_view kExecPrefix = "exec:";
constexpr std::string_view kExecOptions = "exec,";

const MlsOptions& checked(const MlsOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("landing system options: " + why);
  return o;
}

void add_builtins(Registry<MakeSystem>& r) {
  // What the command line sets of MlsOptions (the library takes all of it).
  const std::string detector =
      "--detector aruco|learned, --whole-frame-detection (landing_scenario); from C++ every MlsOptions field";
  r.add("opencv-mls", "ArUco marker detection; lands after 5 s of continuous sighting (the source's OpenCV-MLS)",
        detector, [](const MlsOptions& o) -> std::unique_ptr<LandingSystem> {
          return std::make_unique<detail::OpencvMls>(checked(o), "opencv-mls");
        });
  r.add("learned-mls", "opencv-mls on the learned marker detector (OpenCV DNN; the source's TPHYoLo-MLS)",
        "the model (data/models/, or TOUCHDOWN_MODEL), --whole-frame-detection (landing_scenario); from C++ every "
        "MlsOptions field",
        [](const MlsOptions& o) -> std::unique_ptr<LandingSystem> {
          MlsOptions learned = checked(o);
          learned.detector.kind = "learned";
          return std::make_unique<detail::OpencvMls>(learned, "learned-mls");
        });
  r.add("mm-mls", "opencv-mls plus a depth obstacle map and planned descents (the source's MM-MLS)", detector,
        [](const MlsOptions& o) -> std::unique_ptr<LandingSystem> {
          return std::make_unique<detail::MmMls>(checked(o));
        });
}

// Adds a plug-in's systems to the registry, all or none.
class Registrar final : public PluginRegistrar {
 public:
  explicit Registrar(std::string path) : path_(std::move(path)) {}
  void add(std::string name, std::string description, std::string options, MakeSystem make) override {
    if (!make) throw InvalidArgument("plugin:" + path_ + ": system '" + name + "' has an empty factory");
    added_.push_back({std::move(name), std::move(description), std::move(make), std::move(options)});
  }
  std::vector<Registry<MakeSystem>::Entry>& added() { return added_; }

 private:
  std::string path_;
  std::vector<Registry<MakeSystem>::Entry> added_;
};

std::string abi_text(const char* version, std::uint32_t compiler, std::uint32_t library, std::uint64_t layout) {
  return "touchdown " + std::string(version != nullptr ? version : "?") + ", C++ ABI " + std::to_string(compiler) +
         ", standard library ABI " + std::to_string(library) + ", type layout " + std::to_string(layout);
}

// The systems each loaded library registered, by canonical path.
struct Loaded {
  std::mutex mutex;
  std::map<std::string, std::vector<std::string>> systems;
};

Loaded& loaded() {
  static Loaded l;
  return l;
}

std::vector<std::string> load_locked(const std::string& path, const std::string& key) {
  const std::string where = "plugin:" + path;
  ::dlerror();
  void* handle = ::dlopen(key.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* e = ::dlerror();
    throw InvalidArgument(where + ": cannot load: " + (e != nullptr ? e : "unknown error"));
  }
  // Anything refused is closed again: only its static initialisers have run.
  const auto refuse = [&](const std::string& why) {
    ::dlclose(handle);
    throw InvalidArgument(where + ": " + why);
  };
  using Entry = const PluginInfo* (*)();
  void* symbol = ::dlsym(handle, kPluginEntryPoint);
  if (symbol == nullptr) {
    refuse("not a touchdown plug-in (it has no " + std::string(kPluginEntryPoint) +
           " entry point; define one with TOUCHDOWN_PLUGIN, touchdown/scenario/plugin.hpp)");
  }
  const PluginInfo* info =
      reinterpret_cast<Entry>(symbol)();  // NOLINT(cppcoreguidelines-pro-type-reinterpret-cast): dlsym's result
  if (info == nullptr) refuse("its entry point returned null");
  if (info->abi_version != kPluginAbiVersion) {
    refuse("plug-in ABI " + std::to_string(info->abi_version) + ", this touchdown loads ABI " +
           std::to_string(kPluginAbiVersion) + ": rebuild it against this touchdown");
  }
  const std::string theirs =
      abi_text(info->touchdown_version, info->compiler_abi, info->standard_library, info->layout);
  const std::string ours = abi_text(TOUCHDOWN_VERSION, compiler_abi(), standard_library_abi(), plugin_layout());
  if (theirs != ours) refuse("built against " + theirs + "; this is " + ours + ": rebuild it against this touchdown");
  if (info->register_systems == nullptr) refuse("its entry point gives no register function");

  Registrar registrar(path);
  try {
    info->register_systems(registrar);
  } catch (const std::exception& e) {
    throw InvalidArgument(where + ": registering its systems failed: " + e.what());
  } catch (...) {
    throw InvalidArgument(where + ": registering its systems failed (a non-standard exception)");
  }
  if (registrar.added().empty()) throw InvalidArgument(where + ": registers no landing system");
  std::vector<std::string> names;
  Registry<MakeSystem>& registry = system_registry();
  for (auto& e : registrar.added()) {
    if (registry.find(e.name)) throw InvalidArgument(where + ": system '" + e.name + "' is already registered");
  }
  for (auto& e : registrar.added()) {
    names.push_back(e.name);
    registry.add(std::move(e.name), std::move(e.description), std::move(e.options), std::move(e.factory));
  }
  return names;  // the handle stays open for the process's life
}

}  // namespace

Registry<MakeSystem>& system_registry() {
  static Registry<MakeSystem> r("landing system");
  static const bool kBuiltins = (add_builtins(r), true);
  (void)kBuiltins;
  return r;
}

std::vector<std::string> load_system_plugin(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty()) throw InvalidArgument("plugin: empty path");
  if (!fs::is_regular_file(path, ec)) throw InvalidArgument("plugin:" + path + ": no such file");
  // dlopen searches the library path for a name without '/': always give it a path.
  const std::string key = fs::canonical(path, ec).string();
  if (ec) throw InvalidArgument("plugin:" + path + ": " + ec.message());
  Loaded& l = loaded();
  const std::lock_guard lock(l.mutex);
  if (const auto it = l.systems.find(key); it != l.systems.end()) return it->second;
  std::vector<std::string> names = load_locked(path, key);
  l.systems.emplace(key, names);
  return names;
}

MakeSystem resolve_system(std::string_view spec) {
  if (spec.substr(0, kExecPrefix.size()) == kExecPrefix || spec.substr(0, kExecOptions.size()) == kExecOptions) {
    const ProcessOptions o = parse_exec_spec(spec);
    return [o](const MlsOptions&) { return make_process_system(o); };
  }
  if (spec.substr(0, kPluginPrefix.size()) != kPluginPrefix) return system_registry().get(spec).factory;
  const std::string rest(spec.substr(kPluginPrefix.size()));
  // plugin:PATH or plugin:PATH:NAME (a PATH that is a file as a whole wins).
  std::string path = rest;
  std::string name;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(rest, ec)) {
    if (const auto colon = rest.rfind(':'); colon != std::string::npos) {
      path = rest.substr(0, colon);
      name = rest.substr(colon + 1);
    }
  }
  const std::vector<std::string> names = load_system_plugin(path);
  std::string listed;
  for (const std::string& n : names) listed += (listed.empty() ? "" : ", ") + n;
  if (name.empty()) {
    if (names.size() != 1) {
      throw InvalidArgument(std::string(spec) + ": the library registers " + std::to_string(names.size()) +
                            " systems (" + listed + "): name one, plugin:" + path + ":NAME");
    }
    name = names.front();
  } else if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw InvalidArgument(std::string(spec) + ": the library registers no '" + name + "' (it has " + listed + ")");
  }
  return system_registry().get(name).factory;
}

SystemFactory::SystemFactory() : SystemFactory("opencv-mls") {}

SystemFactory::SystemFactory(std::string spec) : name_(std::move(spec)) {}

SystemFactory::SystemFactory(const char* spec) : name_(spec != nullptr ? spec : "") {}

SystemFactory::SystemFactory(std::string name, MakeSystem make) : name_(std::move(name)), make_(std::move(make)) {
  if (!make_) throw InvalidArgument("system factory '" + name_ + "': empty");
}

std::unique_ptr<LandingSystem> SystemFactory::make(const MlsOptions& options) const {
  if (name_.empty()) throw InvalidArgument("landing system: empty name");
  const MakeSystem make = make_ ? make_ : resolve_system(name_);
  std::unique_ptr<LandingSystem> system;
  try {
    system = make(options);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw InvalidArgument("landing system '" + name_ + "': its factory failed: " + e.what());
  }
  if (!system) throw InvalidArgument("landing system '" + name_ + "': its factory returned no system");
  return system;
}

}  // namespace touchdown::scenario
