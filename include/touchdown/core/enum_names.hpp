#pragma once
/// \file
/// Names of enumerators, as files, JSON and the command line spell them.
/// Every enum `E` of the library that is named anywhere specialises
/// `EnumNames<E>` with its names in enumerator order (enumerators 0..N−1);
/// the module's `to_string(E)` and `from_string<E>` are derived from that one
/// table, so a reader, a writer and an app cannot disagree on a spelling:
///
///     enum class MapKind { Ground, Lawn };
///     template <> struct touchdown::EnumNames<MapKind> {
///       static constexpr std::array<std::string_view, 2> names{"ground", "lawn"};
///     };
///     touchdown::from_string<MapKind>("lawn") == MapKind::Lawn
///     touchdown::from_string<MapKind>("grass")   // InvalidArgument:
///         // "expected one of ground, lawn; got 'grass'"
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <type_traits>

#include "touchdown/core/error.hpp"

namespace touchdown {

/// Specialise with `static constexpr std::array<std::string_view, N> names`.
template <typename E>
struct EnumNames;

/// An enum with a names table.
template <typename E>
concept NamedEnum = std::is_enum_v<E> && requires {
  EnumNames<E>::names;
};

/// The name of `e`; "unknown" for a value outside the enumeration (a cast
/// from a bad integer), so that a message never reads out of bounds.
template <NamedEnum E>
constexpr std::string_view enum_name(E e) {
  const auto i = static_cast<std::size_t>(e);
  const auto& names = EnumNames<E>::names;
  return i < names.size() ? names[i] : std::string_view("unknown");
}

/// The accepted names, comma-separated ("ground, lawn"), for messages and
/// `--help`.
template <NamedEnum E>
std::string enum_names_list() {
  std::string s;
  for (const std::string_view n : EnumNames<E>::names) {
    if (!s.empty()) s += ", ";
    s += n;
  }
  return s;
}

/// The enumerator named `name` (exact, case-sensitive); throws
/// InvalidArgument "expected one of <names>; got '<name>'" otherwise. A
/// reader or an app prefixes the file, line or option at fault.
template <NamedEnum E>
E from_string(std::string_view name) {
  const auto& names = EnumNames<E>::names;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<E>(i);
  }
  throw InvalidArgument("expected one of " + enum_names_list<E>() + "; got '" + std::string(name) + "'");
}

}  // namespace touchdown
