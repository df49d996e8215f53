#pragma once
/// \file
/// Writing a landing-system plug-in: a shared library, built against this
/// touchdown (find_package(touchdown), link touchdown::scenario), that
/// registers its systems through one C-linkage entry point. In one of its
/// source files:
///
///   #include <touchdown/scenario/plugin.hpp>
///   namespace {
///   void register_systems(touchdown::scenario::PluginRegistrar& r) {
///     r.add("my-mls", "my landing system (one line)",
///           [](const touchdown::scenario::MlsOptions&) { return std::make_unique<MyMls>(); });
///   }
///   }  // namespace
///   TOUCHDOWN_PLUGIN("my landing systems", register_systems)
///
/// then `landing_fuzz campaign --system plugin:./libmy_mls.so:my-mls …`
/// (examples/plugin_system/ is a whole one). The entry point returns a
/// PluginInfo whose first field is the entry point's own ABI version and
/// whose others say which touchdown, compiler ABI and type layouts the
/// library was compiled against; the host compares all of them before it
/// calls anything in the library, and refuses a mismatch with a message
/// naming both sides, never a crash. The library is never unloaded (its
/// systems' code must outlive them).
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "touchdown/core/version_defs.hpp"
#include "touchdown/scenario/system_registry.hpp"

namespace touchdown::scenario {

/// The entry point's ABI: bumped when PluginInfo or PluginRegistrar change
/// (2: options).
inline constexpr std::uint32_t kPluginAbiVersion = 2;

/// What a plug-in's register function is given: add each system with a
/// name (letters, digits, '.', '_', '-'), a one-line description, one line
/// on the options it reads (MlsOptions' keys, or how else it is set up;
/// `landing_scenario systems` lists it) and its factory. A name already
/// registered is refused (the load fails).
class PluginRegistrar {
 public:
  virtual ~PluginRegistrar() = default;
  virtual void add(std::string name, std::string description, std::string options, MakeSystem make) = 0;
  /// A system that reads no options.
  void add(std::string name, std::string description, MakeSystem make) {
    add(std::move(name), std::move(description), std::string(), std::move(make));
  }

 protected:
  PluginRegistrar() = default;
  PluginRegistrar(const PluginRegistrar&) = default;
  PluginRegistrar& operator=(const PluginRegistrar&) = default;
};

/// The compiler's C++ ABI (the Itanium ABI's version, as GCC and Clang give it).
constexpr std::uint32_t compiler_abi() {
#ifdef __GXX_ABI_VERSION
  return __GXX_ABI_VERSION;
#else
  return 0;
#endif
}

/// The standard library's ABI: libstdc++'s old or new std::string
/// (0 or 1), libc++ 1000 + its ABI version.
constexpr std::uint32_t standard_library_abi() {
#if defined(_LIBCPP_ABI_VERSION)
  return 1000 + _LIBCPP_ABI_VERSION;
#elif defined(_GLIBCXX_USE_CXX11_ABI)
  return _GLIBCXX_USE_CXX11_ABI;
#else
  return 999;
#endif
}

/// A fingerprint (FNV-1a) of the size and alignment of every type that
/// crosses the plug-in boundary: a library compiled against headers of
/// another layout gets another one.
constexpr std::uint64_t plugin_layout() {
  const std::array<std::size_t, 30> sizes{sizeof(SystemSetup),
                                          alignof(SystemSetup),
                                          sizeof(SystemInput),
                                          alignof(SystemInput),
                                          sizeof(SystemOutput),
                                          alignof(SystemOutput),
                                          sizeof(Detection),
                                          alignof(Detection),
                                          sizeof(MlsOptions),
                                          alignof(MlsOptions),
                                          sizeof(DetectorOptions),
                                          alignof(DetectorOptions),
                                          sizeof(CameraOptions),
                                          alignof(CameraOptions),
                                          sizeof(CameraFrame),
                                          alignof(CameraFrame),
                                          sizeof(DroneState),
                                          alignof(DroneState),
                                          sizeof(DroneCommand),
                                          alignof(DroneCommand),
                                          sizeof(LandingSystem),
                                          sizeof(std::string),
                                          sizeof(std::vector<int>),
                                          sizeof(std::function<void()>),
                                          sizeof(std::unique_ptr<int>),
                                          sizeof(MakeSystem),
                                          sizeof(PluginRegistrar),
                                          sizeof(void*),
                                          sizeof(long),
                                          sizeof(long double)};
  std::uint64_t h = 14695981039346656037ULL;
  for (const std::size_t s : sizes) {
    for (int byte = 0; byte < 8; ++byte) {
      h ^= (static_cast<std::uint64_t>(s) >> (8 * byte)) & 0xFFU;
      h *= 1099511628211ULL;
    }
  }
  return h;
}

/// What the entry point returns (a static object of the library). The host
/// reads abi_version first and nothing else when it differs.
struct PluginInfo {
  std::uint32_t abi_version;       ///< kPluginAbiVersion of the library's headers
  const char* touchdown_version;   ///< TOUCHDOWN_VERSION of the library's headers
  std::uint32_t compiler_abi;      ///< compiler_abi()
  std::uint32_t standard_library;  ///< standard_library_abi()
  std::uint64_t layout;            ///< plugin_layout()
  const char* description;         ///< one line about the library
  void (*register_systems)(PluginRegistrar&);
};

/// The entry point's name (what TOUCHDOWN_PLUGIN defines).
inline constexpr const char* kPluginEntryPoint = "touchdown_plugin_info";

}  // namespace touchdown::scenario

/// Defines the plug-in's entry point: DESCRIPTION a string literal,
/// REGISTER a function void(touchdown::scenario::PluginRegistrar&).
#define TOUCHDOWN_PLUGIN(DESCRIPTION, REGISTER)                                                                        \
  extern "C" __attribute__((visibility("default"))) const ::touchdown::scenario::PluginInfo* touchdown_plugin_info() { \
    static const ::touchdown::scenario::PluginInfo kInfo{::touchdown::scenario::kPluginAbiVersion,                     \
                                                         TOUCHDOWN_VERSION,                                            \
                                                         ::touchdown::scenario::compiler_abi(),                        \
                                                         ::touchdown::scenario::standard_library_abi(),                \
                                                         ::touchdown::scenario::plugin_layout(),                       \
                                                         (DESCRIPTION),                                                \
                                                         &(REGISTER)};                                                 \
    return &kInfo;                                                                                                     \
  }
