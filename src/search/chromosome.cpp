// The violation search's chromosome (chromosome.hpp; RLaGA paper, Fig. 3).
// The repair rules of decode() are listed in docs/architecture.md,
// "The violation search" → "Chromosome and GA operators".
#include "touchdown/search/chromosome.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/format.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"
#include "touchdown/scenario/footprint.hpp"

namespace touchdown::search {

namespace {

using scenario::DistractorKind;
using scenario::DynamicKind;
using scenario::MotionKind;
using scenario::PropertyBound;
using scenario::StaticKind;

constexpr int kDynamicGenes = 8;     // kind, position, heading_deg, speed, motion, extent, size, altitude
constexpr int kStaticGenes = 4;      // kind, position, yaw_deg, size
constexpr int kDistractorGenes = 6;  // kind, position, yaw_deg, size, id, flipped_bits
// Scripted motions a motion gene chooses from (External is the DQN's).
constexpr int kScriptedMotions = 4;

constexpr std::array<std::string_view, 11> kWeather{"fog",
                                                    "rain",
                                                    "snow",
                                                    "dust",
                                                    "leaves",
                                                    "ground_wetness",
                                                    "ground_snow",
                                                    "ground_leaves",
                                                    "sun_elevation_deg",
                                                    "sun_azimuth_deg",
                                                    "ambient"};

double* weather_field(scenario::Weather& w, std::size_t i) {
  double* fields[] = {&w.fog,
                      &w.rain,
                      &w.snow,
                      &w.dust,
                      &w.leaves,
                      &w.ground_wetness,
                      &w.ground_snow,
                      &w.ground_leaves,
                      &w.sun_elevation_deg,
                      &w.sun_azimuth_deg,
                      &w.ambient};
  return fields[i];
}

std::string slot_key(std::string_view list, int slot, std::string_view prop) {
  return std::string(list) + "[" + std::to_string(slot) + "]." + std::string(prop);
}

int max_count(std::string_view list) { return static_cast<int>(scenario::property_bound(list).max); }

double clamp_to_kind(double v, std::string_view list, std::string_view kind, std::string_view prop, int j) {
  const PropertyBound* b = scenario::find_kind_bound(list, kind, prop, j);
  return b ? std::clamp(v, b->min, b->max) : v;
}

const pose::ArucoDictionaryInfo& dictionary_of(const scenario::Scenario& s) {
  const auto* dict = pose::find_aruco_dictionary(s.marker.dictionary);
  TD_ASSERT(dict != nullptr);  // the base validated
  return *dict;
}

// Reads consecutive genes of a chromosome.
class GeneReader {
 public:
  GeneReader(const std::vector<NuclearGene>& genes, std::span<const double> c, int first)
      : genes_(genes), c_(c), gene_(first) {}
  double value() { return c_[static_cast<std::size_t>(genes_[static_cast<std::size_t>(gene_++)].offset)]; }
  int integer() { return static_cast<int>(value()); }
  Eigen::Vector2d vec2() {
    const auto o = static_cast<std::size_t>(genes_[static_cast<std::size_t>(gene_++)].offset);
    return {c_[o], c_[o + 1]};
  }
  Eigen::Vector3d vec3() {
    const auto o = static_cast<std::size_t>(genes_[static_cast<std::size_t>(gene_++)].offset);
    return {c_[o], c_[o + 1], c_[o + 2]};
  }

 private:
  const std::vector<NuclearGene>& genes_;
  std::span<const double> c_;
  int gene_;
};

// Writes consecutive genes, each value clamped into its gene's range.
class GeneWriter {
 public:
  GeneWriter(const std::vector<NuclearGene>& genes, Chromosome& c, int first) : genes_(genes), c_(c), gene_(first) {}
  void values(const double* v) {
    const NuclearGene& g = genes_[static_cast<std::size_t>(gene_++)];
    for (int j = 0; j < g.size; ++j) c_[static_cast<std::size_t>(g.offset + j)] = std::clamp(v[j], g.min, g.max);
  }
  void value(double v) { values(&v); }
  // An absent slot: every gene of it at its minimum.
  void skip_absent(int genes) {
    for (int k = 0; k < genes; ++k) {
      const NuclearGene& g = genes_[static_cast<std::size_t>(gene_++)];
      for (int j = 0; j < g.size; ++j) c_[static_cast<std::size_t>(g.offset + j)] = g.min;
    }
  }

 private:
  const std::vector<NuclearGene>& genes_;
  Chromosome& c_;
  int gene_;
};

[[noreturn]] void does_not_fit(const std::string& field, const std::string& what) {
  throw InvalidArgument("chromosome encode: " + field + ": " + what);
}

}  // namespace

// ---- options --------------------------------------------------------------------------

bool ChromosomeOptions::validate(std::string* why) const {
  const auto check = [&](std::string_view name, int v, std::string_view list) {
    if (v >= 0 && v <= max_count(list)) return true;
    if (why)
      *why = std::string(name) + ": must be in [0, " + std::to_string(max_count(list)) + "], got " + std::to_string(v);
    return false;
  };
  return check("dynamic_slots", dynamic_slots, "dynamic_objects") &&
         check("static_slots", static_slots, "static_objects") &&
         check("distractor_slots", distractor_slots, "distractors");
}

ChromosomeOptions ChromosomeOptions::source() {
  ChromosomeOptions o;
  o.static_slots = 0;
  o.distractor_slots = 0;
  return o;
}

// ---- layout ---------------------------------------------------------------------------

void ChromosomeLayout::add_gene(std::string name, GeneGroup group, int slot, int size, double min, double max,
                                bool integer) {
  genes_.push_back({std::move(name), group, slot, values_, size, min, max, integer});
  values_ += size;
}

ChromosomeLayout::ChromosomeLayout(scenario::Scenario base, const ChromosomeOptions& options)
    : base_(std::move(base)), options_(options) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument("chromosome options: " + why);
  if (!base_.validate(&why)) throw InvalidArgument("chromosome base scenario: " + why);
  const auto row = [](std::string_view key) -> const PropertyBound& { return scenario::property_bound(key); };
  // Environment (Fig. 3's environment composite gene; the seed is ours).
  add_gene("seed", GeneGroup::Environment, -1, 1, row("seed").min, row("seed").max, true);
  for (const std::string_view w : kWeather) {
    const std::string key = "weather." + std::string(w);
    add_gene(key, GeneGroup::Environment, -1, 1, row(key).min, row(key).max, false);
  }
  add_gene("marker.position", GeneGroup::Marker, -1, 2, row("marker.position").min, row("marker.position").max, false);

  first_dynamic_ = static_cast<int>(genes_.size());
  for (int k = 0; k < options_.dynamic_slots; ++k) {
    const auto add = [&](std::string_view prop, int size, double min, double max, bool integer) {
      add_gene(slot_key("dynamic_objects", k, prop), GeneGroup::DynamicObject, k, size, min, max, integer);
    };
    const auto env = [&](std::string_view prop, int size) {
      const PropertyBound& b = row("dynamic_objects[]." + std::string(prop));
      add(prop, size, b.min, b.max, false);
    };
    add("kind", 1, 0, static_cast<double>(EnumNames<DynamicKind>::names.size()), true);
    env("position", 2);
    env("heading_deg", 1);
    env("speed", 1);
    add("motion", 1, 0, kScriptedMotions - 1, true);
    env("extent", 1);
    env("size", 3);
    env("altitude", 1);
  }
  for (int k = 0; k < options_.static_slots; ++k) {
    const auto env = [&](std::string_view prop, int size) {
      const PropertyBound& b = row("static_objects[]." + std::string(prop));
      add_gene(slot_key("static_objects", k, prop), GeneGroup::StaticObject, k, size, b.min, b.max, false);
    };
    add_gene(slot_key("static_objects", k, "kind"), GeneGroup::StaticObject, k, 1, 0,
             static_cast<double>(EnumNames<StaticKind>::names.size()), true);
    env("position", 2);
    env("yaw_deg", 1);
    env("size", 3);
  }
  for (int k = 0; k < options_.distractor_slots; ++k) {
    const auto env = [&](std::string_view prop, int size, bool integer) {
      const PropertyBound& b = row("distractors[]." + std::string(prop));
      add_gene(slot_key("distractors", k, prop), GeneGroup::Distractor, k, size, b.min, b.max, integer);
    };
    add_gene(slot_key("distractors", k, "kind"), GeneGroup::Distractor, k, 1, 0,
             static_cast<double>(EnumNames<DistractorKind>::names.size()), true);
    env("position", 2, false);
    env("yaw_deg", 1, false);
    env("size", 1, false);
    env("id", 1, true);
    env("flipped_bits", 1, true);
  }
}

void ChromosomeLayout::check(std::span<const double> c) const {
  if (c.size() != static_cast<std::size_t>(values_)) {
    throw InvalidArgument("chromosome: expected " + std::to_string(values_) + " values, got " +
                          std::to_string(c.size()));
  }
  for (const NuclearGene& g : genes_) {
    for (int j = 0; j < g.size; ++j) {
      const double v = c[static_cast<std::size_t>(g.offset + j)];
      const std::string at = g.name + (g.size > 1 ? "[" + std::to_string(j) + "]" : "");
      if (std::isnan(v)) throw InvalidArgument("chromosome: " + at + ": NaN");
      if (v < g.min || v > g.max) {
        throw InvalidArgument("chromosome: " + at + ": must be in [" + touchdown::detail::format_exact(g.min) + ", " +
                              touchdown::detail::format_exact(g.max) + "], got " + touchdown::detail::format_exact(v));
      }
      if (g.integer && v != std::floor(v)) {
        throw InvalidArgument("chromosome: " + at + ": must be an integer, got " + touchdown::detail::format_exact(v));
      }
    }
  }
}

Chromosome ChromosomeLayout::write(const scenario::Scenario& s) const {
  Chromosome c(static_cast<std::size_t>(values_), 0.0);
  GeneWriter w(genes_, c, 0);
  w.value(static_cast<double>(s.seed));
  scenario::Weather weather = s.weather;
  for (std::size_t i = 0; i < kWeather.size(); ++i) w.value(*weather_field(weather, i));
  w.values(s.marker.position.data());
  for (int k = 0; k < options_.dynamic_slots; ++k) {
    if (static_cast<std::size_t>(k) >= s.dynamic_objects.size()) {
      w.skip_absent(kDynamicGenes);
      continue;
    }
    const scenario::DynamicObject& o = s.dynamic_objects[static_cast<std::size_t>(k)];
    w.value(1.0 + static_cast<double>(o.kind));
    w.values(o.position.data());
    w.value(o.heading_deg);
    w.value(o.speed);
    w.value(o.motion == MotionKind::External ? 0.0 : static_cast<double>(o.motion));
    w.value(o.extent);
    w.values(o.size.data());
    w.value(o.altitude);
  }
  for (int k = 0; k < options_.static_slots; ++k) {
    if (static_cast<std::size_t>(k) >= s.static_objects.size()) {
      w.skip_absent(kStaticGenes);
      continue;
    }
    const scenario::StaticObject& o = s.static_objects[static_cast<std::size_t>(k)];
    w.value(1.0 + static_cast<double>(o.kind));
    w.values(o.position.data());
    w.value(o.yaw_deg);
    w.values(o.size.data());
  }
  for (int k = 0; k < options_.distractor_slots; ++k) {
    if (static_cast<std::size_t>(k) >= s.distractors.size()) {
      w.skip_absent(kDistractorGenes);
      continue;
    }
    const scenario::Distractor& d = s.distractors[static_cast<std::size_t>(k)];
    w.value(1.0 + static_cast<double>(d.kind));
    w.values(d.position.data());
    w.value(d.yaw_deg);
    w.value(d.size);
    w.value(d.id);
    w.value(d.flipped_bits);
  }
  return c;
}

Chromosome ChromosomeLayout::encode(const scenario::Scenario& s) const {
  std::string why;
  if (!s.validate(&why)) throw InvalidArgument("chromosome encode: invalid scenario: " + why);
  const scenario::Scenario& b = base_;
  if (s.map != b.map) does_not_fit("map", "differs from the base's (not a gene)");
  if (s.time_limit != b.time_limit) does_not_fit("time_limit", "differs from the base's (not a gene)");
  if (s.marker.dictionary != b.marker.dictionary) does_not_fit("marker.dictionary", "differs from the base's");
  if (s.marker.id != b.marker.id) does_not_fit("marker.id", "differs from the base's (not a gene)");
  if (s.marker.size != b.marker.size) does_not_fit("marker.size", "differs from the base's (not a gene)");
  if (s.marker.yaw_deg != b.marker.yaw_deg) does_not_fit("marker.yaw_deg", "differs from the base's (not a gene)");
  if (s.drone.position != b.drone.position || s.drone.yaw_deg != b.drone.yaw_deg ||
      s.drone.gps_error != b.drone.gps_error) {
    does_not_fit("drone", "differs from the base's (not a gene)");
  }
  const auto check_list = [](std::string_view list, std::size_t n, int slots, bool same_as_base) {
    if (slots == 0 && !same_as_base) does_not_fit(std::string(list), "differs from the base's (group switched off)");
    if (slots > 0 && n > static_cast<std::size_t>(slots)) {
      does_not_fit(std::string(list),
                   std::to_string(n) + " objects, the layout has " + std::to_string(slots) + " slots");
    }
  };
  scenario::Scenario lists = b;
  lists.dynamic_objects = s.dynamic_objects;
  check_list("dynamic_objects", s.dynamic_objects.size(), options_.dynamic_slots,
             options_.dynamic_slots > 0 || lists == b);
  lists = b;
  lists.static_objects = s.static_objects;
  check_list("static_objects", s.static_objects.size(), options_.static_slots, options_.static_slots > 0 || lists == b);
  lists = b;
  lists.distractors = s.distractors;
  check_list("distractors", s.distractors.size(), options_.distractor_slots,
             options_.distractor_slots > 0 || lists == b);
  for (std::size_t i = 0; i < s.dynamic_objects.size() && options_.dynamic_slots > 0; ++i) {
    const bool external = s.dynamic_objects[i].motion == MotionKind::External;
    if (external != options_.drive_objects) {
      does_not_fit(scenario::indexed_key("dynamic_objects", i, "motion"),
                   options_.drive_objects ? "must be external (drive_objects: the DQN moves every object)"
                                          : "external needs drive_objects");
    }
  }
  return write(s);
}

scenario::Scenario ChromosomeLayout::decode(std::span<const double> c) const {
  check(c);
  scenario::Scenario s = base_;
  GeneReader r(genes_, c, 0);
  s.seed = static_cast<std::uint64_t>(r.value());
  for (std::size_t i = 0; i < kWeather.size(); ++i) *weather_field(s.weather, i) = r.value();
  s.marker.position = r.vec2();

  if (options_.dynamic_slots > 0) s.dynamic_objects.clear();
  for (int k = 0; k < options_.dynamic_slots; ++k) {
    const int kind = r.integer();
    scenario::DynamicObject o;
    o.position = r.vec2();
    o.heading_deg = r.value();
    o.speed = r.value();
    o.motion = static_cast<MotionKind>(r.integer());
    o.extent = r.value();
    o.size = r.vec3();
    o.altitude = r.value();
    if (kind == 0) continue;
    o.kind = static_cast<DynamicKind>(kind - 1);
    if (options_.drive_objects) o.motion = MotionKind::External;
    // Repair 1: the per-kind rows narrow the envelope (clamp).
    const std::string_view name = scenario::to_string(o.kind);
    o.speed = clamp_to_kind(o.speed, "dynamic_objects", name, "speed", 0);
    o.altitude = clamp_to_kind(o.altitude, "dynamic_objects", name, "altitude", 0);
    for (int j = 0; j < 3; ++j) o.size[j] = clamp_to_kind(o.size[j], "dynamic_objects", name, "size", j);
    s.dynamic_objects.push_back(o);
  }

  if (options_.static_slots > 0) s.static_objects.clear();
  for (int k = 0; k < options_.static_slots; ++k) {
    const int kind = r.integer();
    scenario::StaticObject o;
    o.position = r.vec2();
    o.yaw_deg = r.value();
    o.size = r.vec3();
    if (kind == 0) continue;
    o.kind = static_cast<StaticKind>(kind - 1);
    const std::string_view name = scenario::to_string(o.kind);
    for (int j = 0; j < 3; ++j) o.size[j] = clamp_to_kind(o.size[j], "static_objects", name, "size", j);
    // Repair 2: a pole is round; a tree's trunk is thinner than its crown.
    if (o.kind == StaticKind::Pole) o.size.y() = o.size.x();
    if (o.kind == StaticKind::Tree && !(o.size.y() < o.size.x())) o.size.y() = o.size.x() / 2;
    // Repair 3: an object the drone would start inside is dropped.
    if (scenario::static_footprint(o).contains(s.drone.position.head<2>()) &&
        s.drone.position.z() < o.size.z() + scenario::kDroneClearance) {
      continue;
    }
    s.static_objects.push_back(o);
  }

  if (options_.distractor_slots > 0) s.distractors.clear();
  const auto& dict = dictionary_of(s);
  const scenario::Footprint target =
      scenario::marker_square(s.marker.position, s.marker.yaw_deg, s.marker.size, dict.bits);
  for (int k = 0; k < options_.distractor_slots; ++k) {
    const int kind = r.integer();
    scenario::Distractor d;
    d.position = r.vec2();
    d.yaw_deg = r.value();
    d.size = r.value();
    d.id = r.integer();
    d.flipped_bits = r.integer();
    if (kind == 0) continue;
    d.kind = static_cast<DistractorKind>(kind - 1);
    // Repair 4: a wrong_id shows another id of the marker's dictionary.
    if (d.kind == DistractorKind::WrongId) {
      d.id = std::min(d.id, dict.codes - 1);
      if (d.id == s.marker.id) d.id = (d.id + 1) % dict.codes;
    }
    if (d.kind == DistractorKind::Lookalike) d.flipped_bits = std::min(d.flipped_bits, dict.bits * dict.bits);
    // Repair 5: a distractor over the marker or an earlier distractor is dropped.
    const scenario::Footprint square = scenario::marker_square(d.position, d.yaw_deg, d.size, dict.bits);
    bool free = !scenario::overlap(square, target);
    for (const scenario::Distractor& e : s.distractors) {
      free = free && !scenario::overlap(square, scenario::marker_square(e.position, e.yaw_deg, e.size, dict.bits));
    }
    if (free) s.distractors.push_back(d);
  }
  std::string why;
  TD_ASSERT(s.validate(&why));
  return s;
}

Chromosome ChromosomeLayout::draw(std::uint64_t seed) const {
  const scenario::Scenario r = scenario::random_scenario(seed, base_.map);
  scenario::Scenario s = base_;
  s.seed = r.seed;
  s.weather = r.weather;
  s.marker.position = r.marker.position;
  const auto first = [](auto list, int slots) {
    if (list.size() > static_cast<std::size_t>(slots)) list.resize(static_cast<std::size_t>(slots));
    return list;
  };
  if (options_.dynamic_slots > 0) s.dynamic_objects = first(r.dynamic_objects, options_.dynamic_slots);
  if (options_.static_slots > 0) s.static_objects = first(r.static_objects, options_.static_slots);
  if (options_.distractor_slots > 0) s.distractors = first(r.distractors, options_.distractor_slots);
  return fit(s);
}

Chromosome ChromosomeLayout::fit(const scenario::Scenario& s) const { return encode(decode(write(s))); }

std::vector<double> ChromosomeLayout::normalised(std::span<const double> c) const {
  check(c);
  std::vector<double> n(c.size(), 0.0);
  bool absent = false;
  for (const NuclearGene& g : genes_) {
    const bool kind_gene = g.slot >= 0 && g.name.ends_with("].kind");
    if (kind_gene) absent = c[static_cast<std::size_t>(g.offset)] == 0;
    if (g.slot >= 0 && absent && !kind_gene) continue;
    const double width = g.max - g.min;
    for (int j = 0; j < g.size; ++j) {
      const auto i = static_cast<std::size_t>(g.offset + j);
      n[i] = width > 0 ? (c[i] - g.min) / width : 0.0;
    }
  }
  return n;
}

std::array<int, 3> ChromosomeLayout::dynamic_counts(std::span<const double> c) const {
  check(c);
  std::array<int, 3> counts{};
  for (int k = 0; k < options_.dynamic_slots; ++k) {
    const NuclearGene& g = genes_[static_cast<std::size_t>(first_dynamic_ + k * kDynamicGenes)];
    const int kind = static_cast<int>(c[static_cast<std::size_t>(g.offset)]);
    if (kind > 0) ++counts[static_cast<std::size_t>(kind - 1)];
  }
  return counts;
}

}  // namespace touchdown::search
