#pragma once
// The one YAML config reader of every module (internal; the CMake target
// touchdown_yaml makes it available and links yaml-cpp). Every message reads
// "source:line: key: what" (docs/formats.md).
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "format.hpp"
#include "io_util.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::detail {

/// Finds a key repeated in one mapping, at any depth (block or flow style,
/// maps inside sequences too). yaml-cpp keeps both entries and its
/// `map[key]` returns the first, so a repeated key would silently lose its
/// second value. Works on the parser's events, not on the loaded tree: an
/// alias is one event, so a document of nested aliases costs its length, not
/// its expansion. Only scalar keys are compared (by their text); null keys
/// (`~`, `null`, an empty key) count as the same key.
class DuplicateKeyCheck final : public YAML::EventHandler {
 public:
  /// The first repeated key of the first document, as "line: key: duplicate
  /// key (first at line N)" (1-based lines, `key` a dotted path with [i] for
  /// sequence items), or "" when every key is unique.
  static std::string first_duplicate(std::string_view text) {
    std::istringstream in{std::string(text)};
    YAML::Parser parser(in);
    DuplicateKeyCheck check;
    parser.HandleNextDocument(check);
    return check.found_;
  }

  void OnDocumentStart(const YAML::Mark& /*mark*/) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { done(mark, "null", true); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t /*anchor*/) override { done(mark, "", false); }
  void OnScalar(const YAML::Mark& mark, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                const std::string& value) override {
    done(mark, value, true);
  }
  void OnSequenceStart(const YAML::Mark& /*mark*/, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                       YAML::EmitterStyle::value /*style*/) override {
    open(false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& /*mark*/, const std::string& /*tag*/, YAML::anchor_t /*anchor*/,
                  YAML::EmitterStyle::value /*style*/) override {
    open(true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Level {
    bool is_map = false;
    std::string path;                     // "" at the root, "a.b", "a[2]"
    bool at_key = true;                   // a map: the next node is a key
    std::string key;                      // a map: the key of the value being read
    std::size_t index = 0;                // a sequence: the index of the next item
    std::map<std::string, int> key_line;  // a map: each scalar key and its 0-based line
  };

  // The path of the node about to start inside the innermost open collection.
  [[nodiscard]] std::string child_path() const {
    if (levels_.empty()) return {};
    const Level& l = levels_.back();
    if (!l.is_map) return l.path + "[" + std::to_string(l.index) + "]";
    if (l.at_key) return l.path.empty() ? "<key>" : l.path + ".<key>";
    return l.path.empty() ? l.key : l.path + "." + l.key;
  }
  void open(bool is_map) {
    Level l;
    l.is_map = is_map;
    l.path = child_path();
    levels_.push_back(std::move(l));
  }
  void close() {
    if (levels_.empty()) return;
    levels_.pop_back();
    done({}, "", false);
  }
  // A whole node ended in the innermost open collection.
  void done(const YAML::Mark& mark, const std::string& text, bool scalar) {
    if (levels_.empty()) return;
    Level& l = levels_.back();
    if (!l.is_map) {
      ++l.index;
      return;
    }
    if (l.at_key) {
      l.key = scalar ? text : "<key>";
      if (scalar && found_.empty()) {
        const auto [it, fresh] = l.key_line.emplace(text, mark.line);
        if (!fresh) {
          found_ = std::to_string(mark.line + 1) + ": " + (l.path.empty() ? text : l.path + "." + text) +
                   ": duplicate key (first at line " + std::to_string(it->second + 1) + ")";
        }
      }
    }
    l.at_key = !l.at_key;
  }

  std::vector<Level> levels_;
  std::string found_;
};

/// Parses YAML text; syntax errors become ParseError "source:line: invalid
/// YAML: ...", a key repeated in one mapping "source:line: key: duplicate key
/// (first at line N)".
inline YAML::Node load_yaml(std::string_view text, std::string_view source) {
  try {
    YAML::Node root = YAML::Load(std::string(text));
    const std::string duplicate = DuplicateKeyCheck::first_duplicate(text);
    if (!duplicate.empty()) throw ParseError(std::string(source) + ":" + duplicate);
    return root;
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
  /// A warning (never an error) for angles in degrees that look like
  /// radians: every value within ±2π and one not a whole number of degrees
  /// ("cam.yaml:2: rpy_deg: [3.14159, 0, 1.5708] look like radians (all
  /// within +-2 pi, not whole degrees) but are read as degrees; if radians
  /// were meant, write [180, 0, 90]"); "" when they look like degrees. The
  /// reader never prints: the caller collects it for the app to show.
  std::string radians_warning(const YAML::Node& n, const std::string& key, const std::vector<double>& deg) const {
    if (!look_like_radians(deg)) return "";
    std::string as_read, as_radians;
    for (std::size_t i = 0; i < deg.size(); ++i) {
      as_read += (i ? ", " : "") + format_general(deg[i]);
      as_radians += (i ? ", " : "") + format_general(std::round(rad_to_deg(deg[i]) * 100) / 100);
    }
    if (deg.size() > 1) {
      as_read = "[" + as_read + "]";
      as_radians = "[" + as_radians + "]";
    }
    std::string where(source);
    if (n.IsDefined() && n.Mark().line >= 0) where += ":" + std::to_string(n.Mark().line + 1);
    return where + ": " + key + ": " + as_read +
           (deg.size() > 1 ? " look like radians (all within +-2 pi, not whole degrees) but are read as degrees"
                           : " looks like radians (within +-2 pi, not a whole degree) but is read as degrees") +
           "; if radians were meant, write " + as_radians;
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
