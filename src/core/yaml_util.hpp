#pragma once
// The one YAML config reader of every module (internal; the CMake target
// touchdown_yaml makes it available and links yaml-cpp). Every message reads
// "source:line: key: what" (docs/formats.md).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include "io_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::detail {

/// Parses YAML text; syntax errors become ParseError "source:line: invalid YAML: ...".
inline YAML::Node load_yaml(std::string_view text, std::string_view source) {
  try {
    return YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
}

/// Reads typed values out of a YAML tree; every failure is a ParseError
/// "source:line: key: what".
struct YamlReader {
  std::string_view source;

  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& what) const {
    std::string where(source);
    if (node.IsDefined() && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
    throw ParseError(where + ": " + key + ": " + what);
  }
  YAML::Node child(const YAML::Node& map, const std::string& prefix, const std::string& key) const {
    const YAML::Node n = map[key];
    if (!n) fail(map, prefix + key, "missing");
    return n;
  }
  double number(const YAML::Node& n, const std::string& key) const {
    double v = 0;
    if (!n.IsScalar()) fail(n, key, "expected a number");
    if (!parse_double(trim(n.Scalar()), v) || !std::isfinite(v)) {
      fail(n, key, "expected a number, got '" + n.Scalar() + "'");
    }
    return v;
  }
  int integer(const YAML::Node& n, const std::string& key) const {
    const double v = number(n, key);
    if (v != std::floor(v) || std::abs(v) > 1e9) fail(n, key, "expected an integer");
    return static_cast<int>(v);
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence()) fail(n, key, "expected a list of numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < n.size(); ++i) out.push_back(number(n[i], key));
    return out;
  }
  /// Exactly three numbers.
  std::vector<double> vec3(const YAML::Node& n, const std::string& key) const {
    auto v = numbers(n, key);
    if (v.size() != 3) fail(n, key, "expected 3 numbers, got " + std::to_string(v.size()));
    return v;
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a string");
    return n.Scalar();
  }
  /// Fails on any key of `map` not in `keys` (catches typos).
  void only(const YAML::Node& map, const std::string& prefix, std::initializer_list<const char*> keys) const {
    if (!map.IsMap())
      fail(map, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1), "expected a mapping");
    for (const auto& kv : map) {
      const auto k = kv.first.as<std::string>();
      if (std::none_of(keys.begin(), keys.end(), [&](const char* x) { return k == x; })) {
        std::string known;
        for (const char* x : keys) known += (known.empty() ? "" : ", ") + std::string(x);
        fail(kv.first, prefix + k, "unknown key (expected " + known + ")");
      }
    }
  }
};

/// The frame of every validated YAML config reader: parses `text`, lets
/// `read(reader, root, value)` fill a default `T`, turns yaml-cpp's own
/// exceptions into "source:line: what" and rejects a value whose
/// `validate(&why)` fails with "source: why".
template <typename T, typename Read>
T parse_validated(std::string_view text, std::string_view source, Read&& read) {
  const YAML::Node root = load_yaml(text, source);
  const YamlReader reader{source};
  T value;
  try {
    read(reader, root, value);
  } catch (const YAML::Exception& e) {
    throw ParseError(std::string(source) + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  std::string why;
  if (!value.validate(&why)) throw ParseError(std::string(source) + ": " + why);
  return value;
}

}  // namespace touchdown::detail
