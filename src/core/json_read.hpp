#pragma once
// Reading integers from parsed JSON, private to the library (not installed).
// nlohmann's get<int>() casts a fraction or an out-of-range number to int,
// which is undefined behaviour for a double outside int's range (UBSan,
// fuzz_model_manifest: "channels": 1.4e44). Every reader that takes an int
// from JSON goes through json_int.
#include <climits>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace touchdown::detail {

/// `v` as an int when it is a JSON integer within int's range; nothing for
/// a fraction, a number out of range or any other type. `Json`: any
/// nlohmann::basic_json (json, ordered_json).
template <class Json = nlohmann::json>
std::optional<int> json_int(const Json& v) {
  if (v.is_number_unsigned()) {
    const auto u = v.template get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(INT_MAX)) return std::nullopt;
    return static_cast<int>(u);
  }
  if (v.is_number_integer()) {
    const auto i = v.template get<std::int64_t>();
    if (i < INT_MIN || i > INT_MAX) return std::nullopt;
    return static_cast<int>(i);
  }
  return std::nullopt;
}

/// Why json_int gave nothing, for an error message after a key:
/// "integer out of range", "expected an integer, got a fraction" or
/// "expected an integer, got TYPE" (TYPE: nlohmann's type name).
template <class Json = nlohmann::json>
std::string json_int_problem(const Json& v) {
  if (v.is_number_integer()) return "integer out of range";
  if (v.is_number()) return "expected an integer, got a fraction";
  return std::string("expected an integer, got ") + v.type_name();
}

}  // namespace touchdown::detail
