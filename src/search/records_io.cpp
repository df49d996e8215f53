// results.jsonl records and the Evaluation as JSON (records.hpp). The one
// translation unit that includes nlohmann-json: the text is written by hand
// (fixed key order, doubles via format_exact so they read back bit-exact)
// and parsed with nlohmann, whose parser callback refuses repeated keys.
#include <climits>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/io_util.hpp"
#include "core/json_read.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/search/records.hpp"

namespace touchdown::search {
namespace {

using nlohmann::json;

// ---------------------------------------------------------------- write --

void put_double(std::string& out, double v, std::string_view key) {
  if (!std::isfinite(v)) throw InvalidArgument("results record: " + std::string(key) + ": not finite");
  // "-0" would read back as the integer 0: keep the sign with a fraction.
  if (v == 0 && std::signbit(v)) {
    out += "-0.0";
    return;
  }
  out += detail::format_exact(v);
}

void put_string(std::string& out, const std::string& s) {
  out += json(s).dump(-1, ' ', false, json::error_handler_t::replace);
}

void put_key_double(std::string& out, std::string_view key, double v) {
  out += ",\"";
  out += key;
  out += "\":";
  put_double(out, v, "evaluation.facts." + std::string(key));
}

void put_key_string(std::string& out, std::string_view key, const std::string& v) {
  out += ",\"";
  out += key;
  out += "\":";
  put_string(out, v);
}

void append_facts(std::string& out, const Facts& f) {
  out += f.fair ? "{\"fair\":true" : "{\"fair\":false";
  put_key_double(out, "sighting_time", f.sighting_time);
  put_key_double(out, "observable_s", f.observable_s);
  put_key_double(out, "longest_s", f.longest_s);
  put_key_double(out, "probe_observable_s", f.probe_observable_s);
  put_key_double(out, "probe_longest_s", f.probe_longest_s);
  put_key_string(out, "probe_failure", f.probe_failure);
  put_key_double(out, "probe_contrast", f.probe_contrast);
  out += f.descent_started ? ",\"descent_started\":true" : ",\"descent_started\":false";
  put_key_double(out, "descent_time", f.descent_time);
  out += ",\"descent_target\":[";
  put_double(out, f.descent_target[0], "evaluation.facts.descent_target");
  out += ',';
  put_double(out, f.descent_target[1], "evaluation.facts.descent_target");
  out += ']';
  put_key_string(out, "trigger", f.trigger);
  put_key_double(out, "trigger_t", f.trigger_t);
  put_key_string(out, "last_accepted", f.last_accepted);
  out += f.false_detection ? ",\"false_detection\":true" : ",\"false_detection\":false";
  out += ",\"occluders\":[";
  for (std::size_t i = 0; i < f.occluders.size(); ++i) {
    const OccluderFact& o = f.occluders[i];
    out += i > 0 ? ",{\"object\":" : "{\"object\":";
    put_string(out, o.object);
    put_key_double(out, "first_t", o.first_t);
    put_key_double(out, "last_t", o.last_t);
    out += ",\"frames\":" + std::to_string(o.frames) + ",\"frames_descending\":" + std::to_string(o.frames_descending) +
           '}';
  }
  out += ']';
  put_key_string(out, "collided_with", f.collided_with);
  put_key_string(out, "collision_phase", f.collision_phase);
  // Written only when there is one, so that files from before it read the same.
  if (!f.nearest_object.empty()) {
    out += ",\"nearest\":{\"object\":";
    put_string(out, f.nearest_object);
    put_key_double(out, "m", f.nearest_m);
    put_key_double(out, "t", f.nearest_t);
    put_key_string(out, "phase", f.nearest_phase);
    out += '}';
  }
  out += '}';
}

void append_evaluation(std::string& out, const Evaluation& e) {
  out += "{\"violation\":\"";
  out += scenario::to_string(e.violation);
  out += "\",\"message\":";
  put_string(out, e.message);
  out += ",\"dtl\":";
  put_double(out, e.dtl, "evaluation.dtl");
  out += ",\"ttl\":";
  put_double(out, e.ttl, "evaluation.ttl");
  out += ",\"time_limit\":";
  put_double(out, e.time_limit, "evaluation.time_limit");
  out += e.landed ? ",\"landed\":true" : ",\"landed\":false";
  out += e.collided ? ",\"collided\":true" : ",\"collided\":false";
  out += ",\"reward_sum\":";
  put_double(out, e.reward_sum, "evaluation.reward_sum");
  out += ",\"frames\":" + std::to_string(e.frames);
  out += ",\"flight_s\":";
  put_double(out, e.flight_s, "evaluation.flight_s");
  out += ",\"cells\":[";
  for (std::size_t i = 0; i < e.cells.size(); ++i) {
    if (i > 0) out += ',';
    const auto& c = e.cells[i];
    out += '[' + std::to_string(c[0]) + ',' + std::to_string(c[1]) + ',' + std::to_string(c[2]) + ']';
  }
  out += ']';
  if (e.facts.recorded) {
    out += ",\"facts\":";
    append_facts(out, e.facts);
  }
  out += '}';
}

// ---------------------------------------------------------------- parse --

// Parses `text` as one JSON object; a repeated key, or text that is not
// JSON, is a ParseError prefixed by `where` ("results.jsonl:4").
json parse_object(std::string_view text, const std::string& where) {
  std::vector<std::pair<std::set<std::string>, std::string>> levels;  // keys seen, last key
  const json::parser_callback_t check_keys = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      levels.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!levels.empty()) levels.pop_back();
    } else if (event == json::parse_event_t::key && !levels.empty()) {
      const auto name = parsed.get<std::string>();
      std::string path;
      for (std::size_t i = 0; i + 1 < levels.size(); ++i) path += levels[i].second + ".";
      if (!levels.back().first.insert(name).second) throw ParseError(where + ": " + path + name + ": repeated key");
      levels.back().second = name;
    }
    return true;
  };
  json j;
  try {
    j = json::parse(text.begin(), text.end(), check_keys);
  } catch (const json::exception& e) {
    std::string what = e.what();
    if (const auto at = what.find("] "); what.rfind("[json.exception", 0) == 0 && at != std::string::npos) {
      what.erase(0, at + 2);
    }
    for (char& ch : what) {
      if (ch == '\n' || ch == '\r') ch = ' ';
    }
    throw ParseError(where + ": not a JSON object: " + what);
  }
  if (!j.is_object()) throw ParseError(where + ": not a JSON object");
  return j;
}

// Reads the keys of one JSON object, each once; fail() names the key.
class ObjectReader {
 public:
  ObjectReader(const json& object, std::string where, std::string prefix)
      : object_(object), where_(std::move(where)), prefix_(std::move(prefix)) {}

  [[noreturn]] void fail(std::string_view key, const std::string& what) const {
    throw ParseError(where_ + ": " + prefix_ + std::string(key) + ": " + what);
  }

  const json& at(std::string_view key) {
    const auto it = object_.find(key);
    if (it == object_.end()) fail(key, "missing");
    ++used_;
    return *it;
  }

  // Call after reading every key: any key left over is unknown.
  void no_other_keys(const std::set<std::string_view>& known) const {
    if (used_ == object_.size()) return;
    for (const auto& [key, value] : object_.items()) {
      if (known.count(key) == 0) fail(key, "unknown key");
    }
  }

  double number(std::string_view key, double lo = -HUGE_VAL) {
    const json& v = at(key);
    if (!v.is_number()) fail(key, "expected a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "not finite");
    if (d < lo) fail(key, detail::format_general(d, 17) + " is below " + detail::format_general(lo));
    return d;
  }

  int integer(std::string_view key, int lo) {
    const json& v = at(key);
    return to_int(v, key, lo);
  }

  bool boolean(std::string_view key) {
    const json& v = at(key);
    if (!v.is_boolean()) fail(key, "expected true or false, got " + std::string(v.type_name()));
    return v.get<bool>();
  }

  std::string string(std::string_view key) {
    const json& v = at(key);
    if (!v.is_string()) fail(key, "expected a string, got " + std::string(v.type_name()));
    return v.get<std::string>();
  }

  [[nodiscard]] bool has(std::string_view key) const { return object_.contains(key); }

  const json& object(std::string_view key) {
    const json& v = at(key);
    if (!v.is_object()) fail(key, "expected an object, got " + std::string(v.type_name()));
    return v;
  }

  const json& array(std::string_view key) {
    const json& v = at(key);
    if (!v.is_array()) fail(key, "expected an array, got " + std::string(v.type_name()));
    return v;
  }

  int to_int(const json& v, std::string_view key, int lo) const {
    const std::optional<int> got = detail::json_int(v);
    if (!got) fail(key, detail::json_int_problem(v));
    const int i = *got;
    if (i < lo) fail(key, std::to_string(i) + " is below " + std::to_string(lo));
    return i;
  }

 private:
  const json& object_;
  std::string where_, prefix_;
  std::size_t used_ = 0;
};

Facts read_facts(const json& object, const std::string& where, const std::string& prefix) {
  ObjectReader r(object, where, prefix);
  Facts f;
  f.recorded = true;
  f.fair = r.boolean("fair");
  f.sighting_time = r.number("sighting_time", 0);
  f.observable_s = r.number("observable_s", 0);
  f.longest_s = r.number("longest_s", 0);
  f.probe_observable_s = r.number("probe_observable_s", 0);
  f.probe_longest_s = r.number("probe_longest_s", 0);
  f.probe_failure = r.string("probe_failure");
  try {
    (void)from_string<scenario::Sight>(f.probe_failure);
  } catch (const InvalidArgument& err) {
    r.fail("probe_failure", err.what());
  }
  f.probe_contrast = r.number("probe_contrast", 0);
  f.descent_started = r.boolean("descent_started");
  f.descent_time = r.number("descent_time", 0);
  const json& target = r.array("descent_target");
  if (target.size() != 2 || !target[0].is_number() || !target[1].is_number())
    r.fail("descent_target", "expected [x, y] in metres");
  for (std::size_t k = 0; k < 2; ++k) {
    f.descent_target[k] = target[k].get<double>();
    if (!std::isfinite(f.descent_target[k])) r.fail("descent_target", "not finite");
  }
  f.trigger = r.string("trigger");
  f.trigger_t = r.number("trigger_t", 0);
  f.last_accepted = r.string("last_accepted");
  f.false_detection = r.boolean("false_detection");
  const json& occluders = r.array("occluders");
  for (std::size_t i = 0; i < occluders.size(); ++i) {
    const std::string key = "occluders[" + std::to_string(i) + "]";
    if (!occluders[i].is_object()) r.fail(key, "expected an object");
    ObjectReader o(occluders[i], where, prefix + key + ".");
    OccluderFact fact;
    fact.object = o.string("object");
    if (fact.object.empty()) o.fail("object", "empty");
    fact.first_t = o.number("first_t", 0);
    fact.last_t = o.number("last_t", fact.first_t);
    fact.frames = o.integer("frames", 1);
    fact.frames_descending = o.integer("frames_descending", 0);
    if (fact.frames_descending > fact.frames) o.fail("frames_descending", "more than frames");
    o.no_other_keys({"object", "first_t", "last_t", "frames", "frames_descending"});
    f.occluders.push_back(std::move(fact));
  }
  f.collided_with = r.string("collided_with");
  f.collision_phase = r.string("collision_phase");
  if (r.has("nearest")) {
    const json& n = r.object("nearest");
    ObjectReader o(n, where, prefix + "nearest.");
    f.nearest_object = o.string("object");
    if (f.nearest_object.empty()) o.fail("object", "empty");
    f.nearest_m = o.number("m", 0);
    f.nearest_t = o.number("t", 0);
    f.nearest_phase = o.string("phase");
    o.no_other_keys({"object", "m", "t", "phase"});
  }
  r.no_other_keys({"fair", "sighting_time", "observable_s", "longest_s", "probe_observable_s", "probe_longest_s",
                   "probe_failure", "probe_contrast", "descent_started", "descent_time", "descent_target", "trigger",
                   "trigger_t", "last_accepted", "false_detection", "occluders", "collided_with", "collision_phase",
                   "nearest"});
  return f;
}

Evaluation read_evaluation(const json& object, const std::string& where, const std::string& prefix) {
  ObjectReader r(object, where, prefix);
  Evaluation e;
  const std::string type = r.string("violation");
  try {
    e.violation = from_string<scenario::Violation>(type);
  } catch (const InvalidArgument& err) {
    r.fail("violation", err.what());
  }
  e.message = r.string("message");
  e.dtl = r.number("dtl", 0);
  e.ttl = r.number("ttl", 0);
  e.time_limit = r.number("time_limit", 0);
  if (e.time_limit <= 0) r.fail("time_limit", "must be positive");
  e.landed = r.boolean("landed");
  e.collided = r.boolean("collided");
  e.reward_sum = r.number("reward_sum", 0);
  e.frames = r.integer("frames", 0);
  e.flight_s = r.number("flight_s", 0);
  const json& cells = r.array("cells");
  e.cells.reserve(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const std::string key = "cells[" + std::to_string(i) + "]";
    const json& c = cells[i];
    if (!c.is_array() || c.size() != 3) r.fail(key, "expected a triple of integers [x, y, z]");
    std::array<int, 3> cell{};
    for (std::size_t k = 0; k < 3; ++k) cell[k] = r.to_int(c[k], key, INT_MIN);
    if (!e.cells.empty() && !(e.cells.back() < cell)) r.fail(key, "cells must be sorted and unique");
    e.cells.push_back(cell);
  }
  if (object.contains("facts")) {
    const json& f = r.at("facts");
    if (!f.is_object()) r.fail("facts", "expected an object, got " + std::string(f.type_name()));
    e.facts = read_facts(f, where, prefix + "facts.");
  }
  r.no_other_keys({"violation", "message", "dtl", "ttl", "time_limit", "landed", "collided", "reward_sum", "frames",
                   "flight_s", "cells", "facts"});
  return e;
}

EvaluationRecord read_record(const json& object, const std::string& where) {
  ObjectReader r(object, where, "");
  EvaluationRecord rec;
  rec.index = r.integer("index", 0);
  rec.generation = r.integer("generation", 0);
  rec.scenario = r.string("scenario");
  if (rec.scenario.empty()) r.fail("scenario", "empty");
  if (rec.scenario.front() == '/') r.fail("scenario", "must be relative to the results directory");
  rec.fitness = r.number("fitness");
  const json& genes = r.array("genes");
  rec.genes.reserve(genes.size());
  for (std::size_t i = 0; i < genes.size(); ++i) {
    const std::string key = "genes[" + std::to_string(i) + "]";
    if (!genes[i].is_number()) r.fail(key, "expected a number, got " + std::string(genes[i].type_name()));
    const double g = genes[i].get<double>();
    if (!(g >= 0 && g <= 1)) r.fail(key, detail::format_general(g, 17) + " outside [0, 1]");
    rec.genes.push_back(g);
  }
  const json& e = r.at("evaluation");
  if (!e.is_object()) r.fail("evaluation", "expected an object, got " + std::string(e.type_name()));
  rec.evaluation = read_evaluation(e, where, "evaluation.");
  r.no_other_keys({"index", "generation", "scenario", "fitness", "genes", "evaluation"});
  return rec;
}

LoadedRecords load(const std::filesystem::path& path, bool tolerant) {
  const std::string text = detail::read_text_file(path);
  const std::string source = path.string();
  LoadedRecords out;
  std::size_t begin = 0;
  int line_number = 0;
  while (begin < text.size()) {
    ++line_number;
    const auto end = text.find('\n', begin);
    if (end == std::string::npos) {
      if (tolerant) {
        out.truncated_tail = true;
        break;
      }
      detail::parse_fail_line(source, line_number,
                              "truncated last line (no newline: a killed campaign? --resume drops it)");
    }
    EvaluationRecord rec = parse_record_line(std::string_view(text).substr(begin, end - begin), source, line_number);
    const std::string where = source + ":" + std::to_string(line_number);
    if (rec.index != line_number - 1) {
      throw ParseError(where + ": index: " + std::to_string(rec.index) + ", expected " +
                       std::to_string(line_number - 1) + " (records count 0, 1, 2, ...)");
    }
    if (!out.records.empty() && rec.genes.size() != out.records.front().genes.size()) {
      throw ParseError(where + ": genes: " + std::to_string(rec.genes.size()) + " values, the first record has " +
                       std::to_string(out.records.front().genes.size()));
    }
    out.records.push_back(std::move(rec));
    begin = end + 1;
  }
  return out;
}

}  // namespace

std::string evaluation_json(const Evaluation& e) {
  std::string out;
  append_evaluation(out, e);
  return out;
}

Evaluation parse_evaluation_json(std::string_view text, std::string_view source) {
  const std::string where(source);
  return read_evaluation(parse_object(text, where), where, "");
}

std::string record_line(const EvaluationRecord& r) {
  std::string out =
      "{\"index\":" + std::to_string(r.index) + ",\"generation\":" + std::to_string(r.generation) + ",\"scenario\":";
  put_string(out, r.scenario);
  out += ",\"fitness\":";
  put_double(out, r.fitness, "fitness");
  out += ",\"genes\":[";
  for (std::size_t i = 0; i < r.genes.size(); ++i) {
    if (i > 0) out += ',';
    put_double(out, r.genes[i], "genes");
  }
  out += "],\"evaluation\":";
  append_evaluation(out, r.evaluation);
  out += '}';
  return out;
}

EvaluationRecord parse_record_line(std::string_view line, std::string_view source, int line_number) {
  const std::string where = std::string(source) + ":" + std::to_string(line_number);
  if (detail::trim(line).empty()) throw ParseError(where + ": empty line");
  return read_record(parse_object(line, where), where);
}

std::vector<EvaluationRecord> load_records(const std::filesystem::path& results_jsonl) {
  return load(results_jsonl, false).records;
}

LoadedRecords load_records_tolerant(const std::filesystem::path& results_jsonl) { return load(results_jsonl, true); }

}  // namespace touchdown::search
