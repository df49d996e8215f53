// Landing scenario files: the YAML reader (errors at the line of the key at
// fault) and the YAML/JSON writer (docs/formats.md, "Landing scenarios").
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <utility>

#include "core/io_util.hpp"
#include "core/yaml_util.hpp"
#include "scenario/scenario_internal.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

using namespace detail;  // NOLINT(google-build-using-namespace): the module's own private helpers

// ---- reading --------------------------------------------------------------------------

namespace {

using touchdown::detail::YamlReader;

// Reads the file and remembers the node of every key it read, so that a
// problem validate() finds ("static_objects[2].size: ...") is reported at
// the line of its key.
class ScenarioReader {
 public:
  explicit ScenarioReader(const YamlReader& r) : r_(r) {}

  void read(const YAML::Node& root, Scenario& s) {
    only(root, "",
         {"map", "seed", "time_limit", "marker", "distractors", "static_objects", "dynamic_objects", "weather",
          "drone"});
    s.map = read_enum<MapKind>(r_.child(root, "", "map"), "map");
    if (const YAML::Node n = root["seed"]) s.seed = read_seed(n);
    if (const YAML::Node n = root["time_limit"]) s.time_limit = number(n, "time_limit");
    read_marker(r_.child(root, "", "marker"), s.marker);
    read_list(root, "distractors", s.distractors, [&](const YAML::Node& n, const std::string& p, Distractor& d) {
      only(n, p, {"kind", "id", "flipped_bits", "size", "position", "yaw_deg"});
      d.kind = read_enum<DistractorKind>(r_.child(n, p, "kind"), p + "kind");
      d.position = vec2(r_.child(n, p, "position"), p + "position");
      if (const YAML::Node v = n["id"]) d.id = integer(v, p + "id");
      if (const YAML::Node v = n["flipped_bits"]) d.flipped_bits = integer(v, p + "flipped_bits");
      if (const YAML::Node v = n["size"]) d.size = number(v, p + "size");
      if (const YAML::Node v = n["yaw_deg"]) d.yaw_deg = number(v, p + "yaw_deg");
    });
    read_list(root, "static_objects", s.static_objects,
              [&](const YAML::Node& n, const std::string& p, StaticObject& o) {
                only(n, p, {"kind", "position", "yaw_deg", "size"});
                o.kind = read_enum<StaticKind>(r_.child(n, p, "kind"), p + "kind");
                o.position = vec2(r_.child(n, p, "position"), p + "position");
                if (const YAML::Node v = n["yaw_deg"]) o.yaw_deg = number(v, p + "yaw_deg");
                if (const YAML::Node v = n["size"]) o.size = vec3(v, p + "size");
              });
    read_list(root, "dynamic_objects", s.dynamic_objects,
              [&](const YAML::Node& n, const std::string& p, DynamicObject& o) {
                only(n, p, {"kind", "size", "position", "altitude", "heading_deg", "speed", "motion", "extent"});
                o.kind = read_enum<DynamicKind>(r_.child(n, p, "kind"), p + "kind");
                o.position = vec2(r_.child(n, p, "position"), p + "position");
                if (const YAML::Node v = n["size"]) o.size = vec3(v, p + "size");
                if (const YAML::Node v = n["altitude"]) o.altitude = number(v, p + "altitude");
                if (const YAML::Node v = n["heading_deg"]) o.heading_deg = number(v, p + "heading_deg");
                if (const YAML::Node v = n["speed"]) o.speed = number(v, p + "speed");
                if (const YAML::Node v = n["motion"]) o.motion = read_enum<MotionKind>(v, p + "motion");
                if (const YAML::Node v = n["extent"]) o.extent = number(v, p + "extent");
              });
    if (const YAML::Node n = root["weather"]) read_weather(n, s.weather);
    read_drone(r_.child(root, "", "drone"), s.drone);

    // Bounds and consistency, reported at the line of the key at fault.
    std::string why;
    if (!s.validate(&why)) fail_at_key(why);
  }

 private:
  void read_marker(const YAML::Node& n, Marker& m) {
    remember("marker", n);
    only(n, "marker.", {"dictionary", "id", "size", "position", "yaw_deg"});
    m.position = vec2(r_.child(n, "marker.", "position"), "marker.position");
    if (const YAML::Node v = n["dictionary"]) m.dictionary = text(v, "marker.dictionary");
    if (const YAML::Node v = n["id"]) m.id = integer(v, "marker.id");
    if (const YAML::Node v = n["size"]) m.size = number(v, "marker.size");
    if (const YAML::Node v = n["yaw_deg"]) m.yaw_deg = number(v, "marker.yaw_deg");
  }

  void read_weather(const YAML::Node& n, Weather& w) {
    remember("weather", n);
    only(n, "weather.",
         {"fog", "rain", "snow", "dust", "leaves", "ground_wetness", "ground_snow", "ground_leaves",
          "sun_elevation_deg", "sun_azimuth_deg", "ambient"});
    const std::pair<const char*, double*> fields[] = {{"fog", &w.fog},
                                                      {"rain", &w.rain},
                                                      {"snow", &w.snow},
                                                      {"dust", &w.dust},
                                                      {"leaves", &w.leaves},
                                                      {"ground_wetness", &w.ground_wetness},
                                                      {"ground_snow", &w.ground_snow},
                                                      {"ground_leaves", &w.ground_leaves},
                                                      {"sun_elevation_deg", &w.sun_elevation_deg},
                                                      {"sun_azimuth_deg", &w.sun_azimuth_deg},
                                                      {"ambient", &w.ambient}};
    for (const auto& [key, value] : fields) {
      if (const YAML::Node v = n[key]) *value = number(v, std::string("weather.") + key);
    }
  }

  void read_drone(const YAML::Node& n, DroneStart& d) {
    remember("drone", n);
    only(n, "drone.", {"position", "yaw_deg", "gps_error"});
    d.position = vec3(r_.child(n, "drone.", "position"), "drone.position");
    if (const YAML::Node v = n["yaw_deg"]) d.yaw_deg = number(v, "drone.yaw_deg");
    if (const YAML::Node v = n["gps_error"]) d.gps_error = vec2(v, "drone.gps_error");
  }

  // An optional list; its length is checked before its elements are read.
  template <typename T, typename ReadElement>
  void read_list(const YAML::Node& root, const std::string& key, std::vector<T>& out, ReadElement&& read_element) {
    const YAML::Node list = root[key];
    if (!list) return;
    // The key's own line: a block list starts on the line after it.
    YAML::Node at = list;
    for (const auto& kv : root) {
      if (kv.first.Scalar() == key) at.reset(kv.first);  // operator= would overwrite `list`
    }
    remember(key, at);
    if (list.IsNull()) return;  // "distractors:" with nothing after it: none
    if (!list.IsSequence()) r_.fail(at, key, "expected a list");
    const PropertyBound& count = property_bound(key);
    if (static_cast<double>(list.size()) > count.max) {
      r_.fail(at, key, "at most " + num(count.max) + " allowed, got " + std::to_string(list.size()));
    }
    out.assign(list.size(), T{});
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string name = key + "[" + std::to_string(i) + "]";
      remember(name, list[i]);
      read_element(list[i], name + ".", out[i]);
    }
  }

  // YamlReader::only, with a readable error for a key that is not a plain
  // name (yaml-cpp's own would be "bad conversion").
  void only(const YAML::Node& map, const std::string& prefix, std::initializer_list<const char*> keys) const {
    if (map.IsMap()) {
      for (const auto& kv : map) {
        if (!kv.first.IsScalar()) {
          r_.fail(kv.first, prefix.empty() ? "<document>" : prefix.substr(0, prefix.size() - 1),
                  "a key must be a plain name");
        }
      }
    }
    r_.only(map, prefix, keys);
  }

  double number(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.number(n, key);
  }
  int integer(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.integer(n, key);
  }
  std::string text(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    return r_.text(n, key);
  }
  Eigen::Vector2d vec2(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    const auto v = r_.numbers(n, key);
    if (v.size() != 2) r_.fail(n, key, "expected 2 numbers [x, y], got " + std::to_string(v.size()));
    return {v[0], v[1]};
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& key) {
    remember(key, n);
    const auto v = r_.vec3(n, key);
    return {v[0], v[1], v[2]};
  }
  // Digits only: a uint64 must not go through a double.
  std::uint64_t read_seed(const YAML::Node& n) {
    remember("seed", n);
    std::uint64_t v = 0;
    if (!n.IsScalar() || !touchdown::detail::parse_int(touchdown::detail::trim(n.Scalar()), v) || v > kMaxSeedInteger) {
      r_.fail(n, "seed",
              "expected an integer in [0, " + num(kMaxSeed) + "]" +
                  (n.IsScalar() ? ", got '" + n.Scalar() + "'" : std::string()));
    }
    return v;
  }
  // "map: expected one of ground, lawn; got 'moon'", at the key's line.
  template <NamedEnum E>
  E read_enum(const YAML::Node& n, const std::string& key) {
    const std::string t = text(n, key);
    try {
      return from_string<E>(t);
    } catch (const InvalidArgument& e) {
      r_.fail(n, key, e.what());
    }
  }

  // `why` is "key: what" from validate(): thrown at the line of the key, or
  // of the closest enclosing key the file gave ("static_objects[2].size[1]"
  // -> "static_objects[2].size" -> "static_objects[2]" -> ...).
  [[noreturn]] void fail_at_key(const std::string& why) const {
    const std::string named = why.substr(0, why.find(": "));
    const std::string what = why.substr(std::min(why.size(), named.size() + 2));
    std::string key = named;
    while (!key.empty()) {
      if (const auto it = nodes_.find(key); it != nodes_.end()) r_.fail(it->second, named, what);
      const auto cut = key.find_last_of(".[");
      key.resize(cut == std::string::npos ? 0 : cut);
    }
    throw ParseError(std::string(r_.source) + ": " + why);
  }

  // YAML::Node's operator= writes into the node it refers to: rebind instead.
  void remember(const std::string& key, const YAML::Node& n) {
    nodes_.erase(key);
    nodes_.emplace(key, n);
  }

  const YamlReader& r_;
  std::map<std::string, YAML::Node> nodes_;
};

}  // namespace

Scenario parse_scenario(std::string_view text, std::string_view source) {
  return touchdown::detail::parse_validated<Scenario>(
      text, source, [](const YamlReader& r, const YAML::Node& root, Scenario& s) { ScenarioReader(r).read(root, s); });
}

Scenario load_scenario(const std::filesystem::path& path) {
  return parse_scenario(touchdown::detail::read_text_file(path), path.string());
}

// ---- writing --------------------------------------------------------------------------

namespace {

// The dictionary name is the only free text; JSON escapes keep any name
// readable by both YAML and JSON readers.
std::string quoted(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (u < 0x20 || u == 0x7f) {
      constexpr char hex[] = "0123456789abcdef";
      out += "\\u00";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string list_text(const double* v, int n) { return numbers_text(v, n); }

// One writer for both formats: YAML block mappings with one flow mapping
// per list element, or JSON (whose flow syntax YAML reads too).
class Writer {
 public:
  explicit Writer(bool json) : json_(json) {}

  std::string write(const Scenario& s) {
    open();
    field("map", str(to_string(s.map)));
    field("seed", std::to_string(s.seed));
    field("time_limit", num(s.time_limit));
    begin_map("marker");
    field("dictionary", str(s.marker.dictionary));
    field("id", std::to_string(s.marker.id));
    field("size", num(s.marker.size));
    field("position", list_text(s.marker.position.data(), 2));
    field("yaw_deg", num(s.marker.yaw_deg));
    end_map();
    list("distractors", s.distractors, [&](const Distractor& d) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(d.kind))},
                                                              {"id", std::to_string(d.id)},
                                                              {"flipped_bits", std::to_string(d.flipped_bits)},
                                                              {"size", num(d.size)},
                                                              {"position", list_text(d.position.data(), 2)},
                                                              {"yaw_deg", num(d.yaw_deg)}};
    });
    list("static_objects", s.static_objects, [&](const StaticObject& o) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(o.kind))},
                                                              {"position", list_text(o.position.data(), 2)},
                                                              {"yaw_deg", num(o.yaw_deg)},
                                                              {"size", list_text(o.size.data(), 3)}};
    });
    list("dynamic_objects", s.dynamic_objects, [&](const DynamicObject& o) {
      return std::vector<std::pair<const char*, std::string>>{{"kind", str(to_string(o.kind))},
                                                              {"size", list_text(o.size.data(), 3)},
                                                              {"position", list_text(o.position.data(), 2)},
                                                              {"altitude", num(o.altitude)},
                                                              {"heading_deg", num(o.heading_deg)},
                                                              {"speed", num(o.speed)},
                                                              {"motion", str(to_string(o.motion))},
                                                              {"extent", num(o.extent)}};
    });
    const Weather& w = s.weather;
    begin_map("weather");
    field("fog", num(w.fog));
    field("rain", num(w.rain));
    field("snow", num(w.snow));
    field("dust", num(w.dust));
    field("leaves", num(w.leaves));
    field("ground_wetness", num(w.ground_wetness));
    field("ground_snow", num(w.ground_snow));
    field("ground_leaves", num(w.ground_leaves));
    field("sun_elevation_deg", num(w.sun_elevation_deg));
    field("sun_azimuth_deg", num(w.sun_azimuth_deg));
    field("ambient", num(w.ambient));
    end_map();
    begin_map("drone");
    field("position", list_text(s.drone.position.data(), 3));
    field("yaw_deg", num(s.drone.yaw_deg));
    field("gps_error", list_text(s.drone.gps_error.data(), 2));
    end_map();
    close();
    return out_;
  }

 private:
  // Enum names are plain words in YAML, strings in JSON.
  std::string str(std::string_view s) const {
    if (json_) return quoted(s);
    const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    });
    // A plain name that YAML would read as a number or a boolean is quoted.
    double unused = 0;
    return plain && !touchdown::detail::parse_double(s, unused) ? std::string(s) : quoted(s);
  }
  std::string key(const char* k) const { return json_ ? quoted(k) : std::string(k); }
  void indent() { out_.append(2 * static_cast<std::size_t>(depth_), ' '); }
  void open() {
    if (json_) {
      out_ += "{";
      ++depth_;
    }
  }
  void close() {
    if (json_) out_ += "\n}\n";
  }
  // Before each field: JSON needs commas between fields.
  void next() {
    if (json_) {
      out_ += first_ ? "\n" : ",\n";
      first_ = false;
    }
    indent();
  }
  void field(const char* k, const std::string& value) {
    next();
    out_ += key(k) + ": " + value;
    if (!json_) out_ += "\n";
  }
  void begin_map(const char* k) {
    next();
    out_ += key(k) + (json_ ? ": {" : ":\n");
    ++depth_;
    first_ = true;
  }
  void end_map() {
    --depth_;
    if (json_) {
      out_ += "\n";
      indent();
      out_ += "}";
    }
    first_ = false;
  }
  template <typename T, typename Fields>
  void list(const char* k, const std::vector<T>& items, Fields&& fields) {
    next();
    out_ += key(k) + ":";
    if (items.empty()) {
      out_ += json_ ? " []" : " []\n";
      return;
    }
    out_ += json_ ? " [" : "\n";
    for (std::size_t i = 0; i < items.size(); ++i) {
      if (json_) out_ += i ? ",\n" : "\n";
      indent();
      out_ += json_ ? "  {" : "  - {";
      bool first = true;
      for (const auto& [name, value] : fields(items[i])) {
        out_ += (first ? "" : ", ") + key(name) + ": " + value;
        first = false;
      }
      out_ += json_ ? "}" : "}\n";
    }
    if (json_) {
      out_ += "\n";
      indent();
      out_ += "]";
    }
  }

  bool json_;
  int depth_ = 0;
  bool first_ = true;
  std::string out_;
};

}  // namespace

std::string to_yaml(const Scenario& s) { return Writer(false).write(s); }
std::string to_json(const Scenario& s) { return Writer(true).write(s); }

}  // namespace touchdown::scenario
