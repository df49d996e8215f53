// campaign.json and state.json of a results directory (search_io.hpp).
// nlohmann-json stays in this file and records_io.cpp.
#include "search/search_io.hpp"

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/json_read.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/version.hpp"

namespace touchdown::search::detail {

namespace {

using Json = nlohmann::ordered_json;

constexpr std::string_view kCampaignFormat = "touchdown-search-campaign";
constexpr std::string_view kStateFormat = "touchdown-search-state";
constexpr int kVersion = 1;

[[noreturn]] void fail(std::string_view source, const std::string& what) {
  throw ParseError(std::string(source) + ": " + what);
}

Json parse_json(std::string_view text, std::string_view source) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    fail(source, std::string("not JSON (") + e.what() + ")");
  }
}

void check_header(const Json& j, std::string_view format, std::string_view source) {
  if (!j.is_object() || !j.contains("format") || j["format"] != format) {
    fail(source, "format: expected \"" + std::string(format) + "\"");
  }
  if (!j.contains("version") || !j["version"].is_number_integer() || j["version"] != kVersion) {
    fail(source, "version: expected " + std::to_string(kVersion));
  }
}

int integer(const Json& j, std::string_view key, std::string_view source) {
  const std::optional<int> i = touchdown::detail::json_int(j);
  if (!i) fail(source, std::string(key) + ": " + touchdown::detail::json_int_problem(j));
  return *i;
}

// The first key (as a dotted path) where a and b differ, with both values.
std::string first_difference(const Json& a, const Json& b, const std::string& path) {
  if (a.is_object() && b.is_object()) {
    for (const auto& [key, value] : b.items()) {
      const std::string p = path.empty() ? key : path + "." + key;
      if (!a.contains(key)) return p + ": missing in the directory's campaign";
      std::string d = first_difference(a[key], value, p);
      if (!d.empty()) return d;
    }
    for (const auto& [key, value] : a.items()) {
      if (!b.contains(key)) return (path.empty() ? key : path + "." + key) + ": not a key of this campaign";
    }
    return "";
  }
  if (a == b) return "";
  return path + ": the directory's campaign has " + a.dump() + ", this one " + b.dump();
}

}  // namespace

std::string campaign_config(const SearchOptions& o) {
  Json j;
  j["format"] = kCampaignFormat;
  j["version"] = kVersion;
  j["method"] = to_string(o.method);
  j["system"] = o.system;
  j["map"] = scenario::to_string(o.base.map);
  j["budget"] = o.budget;
  j["population"] = o.ga.population;
  j["seed"] = o.seed;
  j["ga"] = {{"crossover_threshold", o.ga.crossover_threshold},
             {"mutation_threshold", o.ga.mutation_threshold},
             {"mutation_candidates", o.ga.mutation_candidates}};
  const ChromosomeOptions c = search_layout(o).options();
  j["chromosome"] = {{"dynamic_slots", c.dynamic_slots},
                     {"static_slots", c.static_slots},
                     {"distractor_slots", c.distractor_slots},
                     {"drive_objects", c.drive_objects}};
  j["violation_radius"] = o.violation_radius;
  j["weights"] = o.weights_id;
  // Written only when set, so that campaigns from before it still resume.
  if (o.detector != "aruco") j["detector"] = o.detector;
  if (!o.detector_model.empty()) j["detector_model"] = o.detector_model;
  if (o.fair_fitness) j["fair_fitness"] = true;
  if (o.near_miss) j["near_miss"] = true;
  if (o.diversity) {
    j["diversity"] = {{"min_distance", o.min_distance}, {"niche_capacity", o.niche_capacity}};
    if (o.diversity_pool != SeedPool::Spread) j["diversity"]["pool"] = std::string(enum_name(o.diversity_pool));
  }
  j["base_scenario"] = Json::parse(scenario::to_json(o.base));
  j["touchdown"] = version();
  return j.dump(2) + "\n";
}

std::string config_difference(std::string_view on_disk, std::string_view wanted, std::string_view source) {
  const Json a = parse_json(on_disk, source);
  check_header(a, kCampaignFormat, source);
  Json b = Json::parse(wanted);
  // The library version that wrote it does not change the results' meaning
  // by itself; every option that does is compared.
  Json a_cmp = a;
  a_cmp.erase("touchdown");
  b.erase("touchdown");
  return first_difference(a_cmp, b, "");
}

std::string state_json(const PoolState& s) {
  Json j;
  j["format"] = kStateFormat;
  j["version"] = kVersion;
  j["generation"] = s.generation;
  j["evaluated"] = s.evaluated;
  Json pool = Json::array();
  for (const PoolMember& m : s.pool) pool.push_back({{"index", m.index}, {"chromosome", m.chromosome}});
  j["pool"] = std::move(pool);
  return j.dump() + "\n";
}

PoolState parse_state(std::string_view text, std::string_view source) {
  const Json j = parse_json(text, source);
  check_header(j, kStateFormat, source);
  PoolState s;
  try {
    s.generation = integer(j.at("generation"), "generation", source);
    s.evaluated = integer(j.at("evaluated"), "evaluated", source);
    for (const Json& m : j.at("pool")) {
      PoolMember p;
      p.index = integer(m.at("index"), "pool[].index", source);
      p.chromosome = m.at("chromosome").get<Chromosome>();
      s.pool.push_back(std::move(p));
    }
  } catch (const Json::exception& e) {
    fail(source, std::string("bad state: ") + e.what());
  }
  if (s.generation < -1 || s.evaluated < 0) fail(source, "generation, evaluated: out of range");
  return s;
}

}  // namespace touchdown::search::detail
