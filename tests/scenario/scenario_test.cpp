#include "touchdown/scenario/scenario.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "test_util.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

// A scenario with every kind of thing in it, each on a known line (the
// bad-input cases below name these lines).
const char* const kScnFull = R"(map: ground
seed: 7
time_limit: 60
marker:
  dictionary: 4X4_50
  id: 3
  size: 1.0
  position: [0.5, -0.5]
  yaw_deg: 10
distractors:
  - {kind: wrong_id, id: 4, position: [3, 0]}
  - {kind: lookalike, flipped_bits: 2, size: 0.8, position: [-3, 1], yaw_deg: 45}
static_objects:
  - {kind: pole, position: [2, 3], size: [0.2, 0.2, 5]}
  - {kind: tree, position: [-6, -6], yaw_deg: 0, size: [4, 0.4, 9]}
dynamic_objects:
  - {kind: person, position: [1, -5], speed: 1.4, motion: line, extent: 6}
  - {kind: bird, size: [0.3, 0.8, 0.2], position: [0, 5], altitude: 10, speed: 8, motion: circle, extent: 4}
weather:
  fog: 0.02
  rain: 0.5
  sun_elevation_deg: 30
drone:
  position: [-8, 2, 12]
  yaw_deg: 90
  gps_error: [1, -0.5]
)";

// kScnFull as a struct, written independently of the reader.
Scenario scn_full() {
  Scenario s;
  s.map = MapKind::Ground;
  s.seed = 7;
  s.time_limit = 60;
  s.marker = {"4X4_50", 3, 1.0, {0.5, -0.5}, 10};
  Distractor wrong;
  wrong.kind = DistractorKind::WrongId;
  wrong.id = 4;
  wrong.position = {3, 0};
  Distractor lookalike;
  lookalike.kind = DistractorKind::Lookalike;
  lookalike.flipped_bits = 2;
  lookalike.size = 0.8;
  lookalike.position = {-3, 1};
  lookalike.yaw_deg = 45;
  s.distractors = {wrong, lookalike};
  s.static_objects = {{StaticKind::Pole, {2, 3}, 0, {0.2, 0.2, 5}}, {StaticKind::Tree, {-6, -6}, 0, {4, 0.4, 9}}};
  DynamicObject person;
  person.kind = DynamicKind::Person;
  person.position = {1, -5};
  person.speed = 1.4;
  person.motion = MotionKind::Line;
  person.extent = 6;
  DynamicObject bird;
  bird.kind = DynamicKind::Bird;
  bird.size = {0.3, 0.8, 0.2};
  bird.position = {0, 5};
  bird.altitude = 10;
  bird.speed = 8;
  bird.motion = MotionKind::Circle;
  bird.extent = 4;
  s.dynamic_objects = {person, bird};
  s.weather.fog = 0.02;
  s.weather.rain = 0.5;
  s.weather.sun_elevation_deg = 30;
  s.drone = {{-8, 2, 12}, 90, {1, -0.5}};
  return s;
}

// `text` with the first `from` replaced by `to`; a marker that fails the
// case when `from` is missing (the tables are built outside any test).
std::string scn_replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) return "<<scn_replace: '" + from + "' not found>>";
  return text.replace(at, from.size(), to);
}

std::string scn_num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return {buf, r.ptr};
}

// parse(to_yaml(s)) == s, parse(to_json(s)) == s, and writing again gives
// the same text.
void scn_expect_round_trip(const Scenario& s, const std::string& label) {
  SCOPED_TRACE(label);
  const std::string yaml = to_yaml(s), json = to_json(s);
  const Scenario from_yaml = parse_scenario(yaml, "s.yaml");
  const Scenario from_json = parse_scenario(json, "s.json");
  EXPECT_TRUE(from_yaml == s) << yaml;
  EXPECT_TRUE(from_json == s) << json;
  EXPECT_EQ(to_yaml(from_yaml), yaml);
  EXPECT_EQ(to_json(from_json), json);
}

// ---- round trips ----

TEST(ScenarioIo, DefaultScenarioIsValidAndRoundTrips) {
  std::string why;
  EXPECT_TRUE(Scenario{}.validate(&why)) << why;
  scn_expect_round_trip(Scenario{}, "default");
}

TEST(ScenarioIo, HandWrittenScenarioRoundTrips) { scn_expect_round_trip(scn_full(), "full"); }

TEST(ScenarioIo, AwkwardNumbersRoundTripExactly) {
  Scenario s = scn_full();
  s.marker.position = {0.1 + 0.2, -1.0 / 3};  // no short decimal
  s.marker.size = std::nextafter(1.0, 2.0);
  s.weather.fog = 1e-300;
  s.drone.gps_error = {-0.0, 4.999999999999999};
  s.seed = 9007199254740992u;  // 2^53, the table's maximum
  std::string why;
  ASSERT_TRUE(s.validate(&why)) << why;
  scn_expect_round_trip(s, "awkward");
}

TEST(ScenarioIo, RandomScenariosRoundTrip) {
  for (std::uint64_t seed = 0; seed < 200; ++seed) scn_expect_round_trip(random_scenario(seed), std::to_string(seed));
}

TEST(ScenarioIo, EqualityComparesEveryField) {
  const Scenario a = scn_full();
  EXPECT_TRUE(a == scn_full());
  std::vector<Scenario> changed(12, a);
  changed[0].map = MapKind::Lawn;
  changed[1].seed = 8;
  changed[2].marker.dictionary = "4x4_50";  // the same dictionary, spelt otherwise: kept as written
  changed[3].distractors[1].flipped_bits = 3;
  changed[4].distractors.pop_back();
  changed[5].static_objects[1].size.z() = 9.5;
  changed[6].dynamic_objects[1].motion = MotionKind::Line;
  changed[7].dynamic_objects[0].heading_deg = 1;
  changed[8].weather.ambient = 0.9;
  changed[9].weather.ground_leaves = 0.1;
  changed[10].drone.gps_error.y() = 0;
  changed[11].time_limit = 61;
  for (std::size_t i = 0; i < changed.size(); ++i) EXPECT_FALSE(changed[i] == a) << i;
}

// ---- reading ----

TEST(ScenarioIo, HandWrittenYamlParsesToKnownValues) {
  const Scenario s = parse_scenario(kScnFull, "s.yaml");
  EXPECT_TRUE(s == scn_full()) << to_yaml(s);
  // Spot checks against the text, independent of scn_full().
  EXPECT_EQ(s.marker.id, 3);
  EXPECT_EQ(s.distractors.at(0).kind, DistractorKind::WrongId);
  EXPECT_EQ(s.distractors.at(0).size, 1.0);  // default
  EXPECT_EQ(s.static_objects.at(1).size, Eigen::Vector3d(4, 0.4, 9));
  EXPECT_EQ(s.dynamic_objects.at(0).size, Eigen::Vector3d(0.5, 0.4, 1.75));  // default
  EXPECT_EQ(s.dynamic_objects.at(1).motion, MotionKind::Circle);
  EXPECT_EQ(s.weather.snow, 0.0);
  EXPECT_EQ(s.weather.sun_azimuth_deg, 135.0);  // default
  EXPECT_EQ(s.gps_target(), Eigen::Vector2d(1.5, -1.0));
}

TEST(ScenarioIo, OptionalKeysTakeTheStructDefaults) {
  const Scenario s =
      parse_scenario("map: lawn\nmarker: {position: [0, 0]}\ndrone: {position: [-8, 0, 12]}\n", "min.yaml");
  Scenario expected;
  expected.map = MapKind::Lawn;
  EXPECT_TRUE(s == expected) << to_yaml(s);
  // Empty lists, written either way.
  const Scenario empty = parse_scenario(
      "map: ground\nmarker: {position: [0, 0]}\ndrone: {position: [-8, 0, 12]}\ndistractors: []\nstatic_objects:\n",
      "e.yaml");
  EXPECT_TRUE(empty == Scenario{});
}

TEST(ScenarioIo, ReadsHandWrittenJson) {
  const std::string json = R"({"map": "lawn", "marker": {"dictionary": "6X6_250", "id": 200, "position": [1, 2]},
    "static_objects": [{"kind": "chair", "position": [3, 3], "size": [0.5, 0.5, 0.9]}],
    "drone": {"position": [-6, 0, 10], "gps_error": [0.5, 0.5]}})";
  const Scenario s = parse_scenario(json, "s.json");
  EXPECT_EQ(s.map, MapKind::Lawn);
  EXPECT_EQ(s.marker.dictionary, "6X6_250");
  EXPECT_EQ(s.marker.id, 200);
  ASSERT_EQ(s.static_objects.size(), 1u);
  EXPECT_EQ(s.static_objects[0].kind, StaticKind::Chair);
  EXPECT_EQ(s.drone.gps_error, Eigen::Vector2d(0.5, 0.5));
}

TEST(ScenarioIo, ExampleFileLoads) {
  const auto path = std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/scenarios/clear_ground.yaml";
  const Scenario s = load_scenario(path);
  EXPECT_EQ(s.map, MapKind::Ground);
  EXPECT_EQ(s.marker.position, Eigen::Vector2d(0, 0));
  EXPECT_EQ(s.drone.position, Eigen::Vector3d(-8, 0, 12));
  EXPECT_EQ(s.drone.gps_error, Eigen::Vector2d(1, -0.5));
  EXPECT_TRUE(s.distractors.empty());
  ASSERT_EQ(s.static_objects.size(), 1u);
  EXPECT_EQ(s.static_objects[0].kind, StaticKind::Box);
  EXPECT_DOUBLE_EQ(s.static_objects[0].position.norm(), 4.0);
  ASSERT_EQ(s.dynamic_objects.size(), 1u);
  EXPECT_EQ(s.dynamic_objects[0].kind, DynamicKind::Person);
  EXPECT_EQ(s.dynamic_objects[0].motion, MotionKind::Line);
  // Clear weather: every effect off.
  const Weather& w = s.weather;
  for (double effect : {w.fog, w.rain, w.snow, w.dust, w.leaves, w.ground_wetness, w.ground_snow, w.ground_leaves}) {
    EXPECT_EQ(effect, 0.0);
  }
  EXPECT_EQ(w.ambient, 1.0);
}

// A second `map` appended to a scenario was ignored: it still ran on ground.
TEST(ScenarioIo, RepeatedKeyIsAnError) {
  test::TempDir dir;
  const auto f = test::with_repeated_key(
      std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/scenarios/clear_ground.yaml", dir / "s.yaml", "map", "lawn");
  EXPECT_EQ(test::error_of([&] { (void)load_scenario(f.path); }), f.expected);
  EXPECT_THROW((void)load_scenario(f.path), ParseError);
}

// JSON scenarios go through the same reader: a repeated member is refused too.
TEST(ScenarioIo, RepeatedJsonMemberIsAnError) {
  const std::string json =
      "{\"map\": \"ground\",\n \"marker\": {\"position\": [0, 0], \"id\": 1,\n  \"id\": 2},\n"
      " \"drone\": {\"position\": [-6, 0, 10]}}\n";
  EXPECT_EQ(test::parse_error_of(parse_scenario, json, "s.json"),
            "s.json:3: marker.id: duplicate key (first at line 2)");
}

TEST(ScenarioIo, LoadNamesAMissingFile) {
  const std::string message = test::error_of([] { (void)load_scenario("/nonexistent/scenario.yaml"); });
  EXPECT_NE(message.find("/nonexistent/scenario.yaml"), std::string::npos) << message;
  EXPECT_THROW((void)load_scenario("/nonexistent/scenario.yaml"), IoError);
}

TEST(ScenarioIo, JsonErrorsNameTheKeyAndLine) {
  Scenario s = scn_full();
  const std::string json = scn_replace(to_json(s), "\"fog\": 0.02", "\"fog\": 0.9");
  const std::string message = test::parse_error_of(parse_scenario, json, "s.json");
  EXPECT_NE(message.find("weather.fog: must be in [0, 0.4] 1/m, got 0.9"), std::string::npos) << message;
  EXPECT_EQ(message.rfind("s.json:", 0), 0u) << message;
  EXPECT_TRUE(message.size() > 7 && std::isdigit(static_cast<unsigned char>(message[7]))) << "no line: " << message;
}

// ---- bad input: one line naming the file, the line and the key ----

class ScenarioBadInput : public ::testing::TestWithParam<test::BadInput> {};

TEST_P(ScenarioBadInput, NamesFileLineAndKey) {
  const auto& c = GetParam();
  test::expect_one_line_naming(test::parse_error_of(parse_scenario, c.text, "s.yaml"), c);
}

std::vector<test::BadInput> scn_bad_inputs() {
  const std::string f = kScnFull;
  auto r = [&](const std::string& from, const std::string& to) { return scn_replace(f, from, to); };
  const std::string statics =
      "static_objects:\n  - {kind: pole, position: [2, 3], size: [0.2, 0.2, 5]}\n"
      "  - {kind: tree, position: [-6, -6], yaw_deg: 0, size: [4, 0.4, 9]}\n";
  std::string thirteen = "static_objects:\n";
  for (int i = 0; i < 13; ++i) thirteen += "  - {kind: box, position: [" + std::to_string(i - 6) + ", 8]}\n";
  std::string five = "distractors:\n";
  for (int i = 0; i < 5; ++i) five += "  - {kind: pattern, position: [" + std::to_string(3 * i - 6) + ", 6]}\n";
  const std::string distractors =
      "distractors:\n  - {kind: wrong_id, id: 4, position: [3, 0]}\n"
      "  - {kind: lookalike, flipped_bits: 2, size: 0.8, position: [-3, 1], yaw_deg: 45}\n";
  return {
      // Outside the bounds table.
      {"MarkerSizeTooLarge", r("size: 1.0", "size: 3"), {"s.yaml:7:", "marker.size: must be in [0.3, 2] m, got 3"}},
      {"FogTooDense", r("fog: 0.02", "fog: 0.5"), {"s.yaml:20:", "weather.fog: must be in [0, 0.4] 1/m"}},
      {"RainAboveOne", r("rain: 0.5", "rain: 1.5"), {"s.yaml:21:", "weather.rain: must be in [0, 1], got 1.5"}},
      {"SunBelowHorizon",
       r("sun_elevation_deg: 30", "sun_elevation_deg: -5"),
       {"s.yaml:22:", "weather.sun_elevation_deg", "[5, 90] deg"}},
      {"TimeLimitTooShort", r("time_limit: 60", "time_limit: 5"), {"s.yaml:3:", "time_limit: must be in [10, 300] s"}},
      {"MarkerYawOutOfRange", r("yaw_deg: 10", "yaw_deg: 200"), {"s.yaml:9:", "marker.yaw_deg", "[-180, 180] deg"}},
      {"MarkerOutsideMap",
       r("[0.5, -0.5]", "[25, -0.5]"),
       {"s.yaml:8:", "marker.position: each component must be in [-20, 20] m, got [25, -0.5]"}},
      {"PoleTooTall",
       r("[0.2, 0.2, 5]", "[0.2, 0.2, 9]"),
       {"s.yaml:14:", "static_objects[0].size[2]: must be in [1, 8] m (pole height), got 9"}},
      {"StaticSizeOverEnvelope",
       r("[4, 0.4, 9]", "[4, 0.4, 13]"),
       {"s.yaml:15:", "static_objects[1].size: each component must be in [0.05, 12] m"}},
      {"PoleNotRound", r("[0.2, 0.2, 5]", "[0.2, 0.3, 5]"), {"s.yaml:14:", "static_objects[0].size", "round"}},
      {"TreeTrunkThickerThanCrown", r("[4, 0.4, 9]", "[1, 1, 9]"), {"s.yaml:15:", "static_objects[1].size", "trunk"}},
      {"PersonTooFast",
       r("speed: 1.4", "speed: 3"),
       {"s.yaml:17:", "dynamic_objects[0].speed: must be in [0, 2.5] m/s", "got 3"}},
      {"PersonFlying",
       r("extent: 6}", "extent: 6, altitude: 3}"),
       {"s.yaml:17:", "dynamic_objects[0].altitude: must be in [0, 0] m"}},
      {"BirdTooHigh", r("altitude: 10", "altitude: 30"), {"s.yaml:18:", "dynamic_objects[1].altitude", "[0, 20] m"}},
      {"BirdWithoutAltitude",
       r("altitude: 10, ", ""),
       {"s.yaml:18:", "dynamic_objects[1].altitude: must be in [2, 20] m (bird flight height"}},
      {"BirdTooFast", r("speed: 8", "speed: 12.5"), {"s.yaml:18:", "dynamic_objects[1].speed", "[0, 12] m/s"}},
      {"PersonTooShort",
       r("position: [1, -5]", "size: [0.3, 0.5, 1.2], position: [1, -5]"),
       {"s.yaml:17:", "dynamic_objects[0].size[2]: must be in [1.5, 2] m (person height), got 1.2"}},
      {"ExtentTooLong", r("extent: 4", "extent: 40"), {"s.yaml:18:", "dynamic_objects[1].extent"}},
      {"DroneTooLow", r("[-8, 2, 12]", "[-8, 2, 2]"), {"s.yaml:24:", "drone.position[2]: must be in [4, 30] m"}},
      {"GpsErrorTooLarge", r("[1, -0.5]", "[6, 0]"), {"s.yaml:26:", "drone.gps_error", "[-5, 5] m"}},
      {"FlippedBitsZero",
       r("flipped_bits: 2", "flipped_bits: 0"),
       {"s.yaml:12:", "distractors[1].flipped_bits: must be an integer in [1, 4]"}},
      {"SeedNegative", r("seed: 7", "seed: -1"), {"s.yaml:2:", "seed: expected an integer in [0, 9007199254740992]"}},
      {"SeedFraction", r("seed: 7", "seed: 1.5"), {"s.yaml:2:", "seed: expected an integer"}},
      {"SeedAbove2To53", r("seed: 7", "seed: 9007199254740993"), {"s.yaml:2:", "seed"}},
      // Not numbers.
      {"NanFog", r("fog: 0.02", "fog: .nan"), {"s.yaml:20:", "weather.fog: expected a number, got '.nan'"}},
      {"NanMarkerSize", r("size: 1.0", "size: nan"), {"s.yaml:7:", "marker.size: expected a number"}},
      {"InfDroneYaw", r("yaw_deg: 90", "yaw_deg: .inf"), {"s.yaml:25:", "drone.yaw_deg: expected a number"}},
      {"MinusInfPosition", r("[-8, 2, 12]", "[-8, -.inf, 12]"), {"s.yaml:24:", "drone.position: expected a number"}},
      {"WordForNumber", r("time_limit: 60", "time_limit: soon"), {"s.yaml:3:", "time_limit: expected a number"}},
      {"NumberForList",
       r("position: [0.5, -0.5]", "position: 0.5"),
       {"s.yaml:8:", "marker.position: expected a list of numbers"}},
      {"ThreeNumbersForXY", r("[0.5, -0.5]", "[0.5, -0.5, 0]"), {"s.yaml:8:", "marker.position: expected 2 numbers"}},
      {"TwoNumbersForSize", r("[0.2, 0.2, 5]", "[0.2, 5]"), {"s.yaml:14:", "static_objects[0].size: expected 3"}},
      {"FractionalId", r("id: 3", "id: 3.5"), {"s.yaml:6:", "marker.id: expected an integer"}},
      {"ListNotAList",
       r(distractors, "distractors: {kind: pattern}\n"),
       {"s.yaml:10:", "distractors: expected a list"}},
      {"MarkerNotAMapping",
       "map: ground\nmarker: 3\ndrone: {position: [-8, 0, 12]}\n",
       {"s.yaml:2:", "marker: expected a mapping"}},
      {"DocumentNotAMapping", "[1, 2]\n", {"s.yaml:1:", "<document>: expected a mapping"}},
      {"KeyNotAName", "[a]: 1\n" + f, {"s.yaml:1:", "a key must be a plain name"}},
      {"InvalidYaml", r("marker:\n", "marker: [\n"), {"s.yaml:", "invalid YAML"}},
      // Unknown keys and enum values.
      {"UnknownTopLevelKey",
       r("time_limit: 60", "time_limt: 60"),
       {"s.yaml:3:", "time_limt: unknown key (expected map, seed, time_limit, marker"}},
      {"UnknownNestedKey", r("yaw_deg: 10", "yaw: 10"), {"s.yaml:9:", "marker.yaw: unknown key"}},
      {"UnknownElementKey",
       r("extent: 6}", "extent: 6, colour: red}"),
       {"s.yaml:17:", "dynamic_objects[0].colour: unknown key"}},
      {"UnknownWeatherKey", r("rain: 0.5", "hail: 0.5"), {"s.yaml:21:", "weather.hail: unknown key"}},
      {"UnknownMap", r("map: ground", "map: desert"), {"s.yaml:1:", "map: expected one of ground, lawn; got 'desert'"}},
      {"UnknownMotion",
       r("motion: line", "motion: zigzag"),
       {"s.yaml:17:", "dynamic_objects[0].motion: expected one of still, line, circle, wander, external"}},
      {"UnknownStaticKind",
       r("kind: pole", "kind: lamp"),
       {"s.yaml:14:", "static_objects[0].kind: expected one of box, chair, pole, tree; got 'lamp'"}},
      {"UnknownDistractorKind",
       r("kind: wrong_id", "kind: qr_code"),
       {"s.yaml:11:", "distractors[0].kind: expected one of wrong_id, lookalike, pattern"}},
      {"UnknownDynamicKind", r("kind: bird", "kind: cat"), {"s.yaml:18:", "dynamic_objects[1].kind", "person, dog"}},
      // Missing keys.
      {"MissingMap", r("map: ground\n", ""), {"s.yaml:", "map: missing"}},
      {"MissingDrone",
       r("drone:\n  position: [-8, 2, 12]\n  yaw_deg: 90\n  gps_error: [1, -0.5]\n", ""),
       {"s.yaml:", "drone: missing"}},
      {"MissingMarkerPosition", r("  position: [0.5, -0.5]\n", ""), {"s.yaml:5:", "marker.position: missing"}},
      {"MissingKind", r("{kind: pole, ", "{"), {"s.yaml:14:", "static_objects[0].kind: missing"}},
      {"MissingElementPosition", r(", position: [3, 0]", ""), {"s.yaml:11:", "distractors[0].position: missing"}},
      // Markers and consistency.
      {"UnknownDictionary",
       r("dictionary: 4X4_50", "dictionary: 9X9_7"),
       {"s.yaml:5:", "marker.dictionary: unknown '9X9_7' (known: 4X4_50"}},
      {"IdOutsideDictionary", r("id: 3", "id: 50"), {"s.yaml:6:", "marker.id: 4X4_50 has ids 0..49, got 50"}},
      {"IdOutsideEveryDictionary", r("id: 3", "id: 2000"), {"s.yaml:6:", "marker.id: must be an integer in [0, 1023]"}},
      {"WrongIdEqualsMarkerId",
       r("id: 4", "id: 3"),
       {"s.yaml:11:", "distractors[0].id: a wrong_id distractor must differ from marker.id (3)"}},
      {"WrongIdOutsideDictionary", r("id: 4", "id: 60"), {"s.yaml:11:", "distractors[0].id: 4X4_50 has ids 0..49"}},
      {"DistractorOnTheMarker",
       r("position: [3, 0]", "position: [1, 0]"),
       {"s.yaml:11:", "distractors[0].position: overlaps the marker"}},
      {"DistractorsOverlap",
       r("position: [-3, 1]", "position: [3, 0.5]"),
       {"s.yaml:12:", "distractors[1].position: overlaps distractors[0]"}},
      {"DroneInsideTree",
       r("[-8, 2, 12]", "[-6, -5, 8]"),
       {"s.yaml:24:", "drone.position: starts inside static_objects[1] (a tree 9 m tall)"}},
      {"TooManyStaticObjects", r(statics, thirteen), {"s.yaml:13:", "static_objects: at most 12 allowed, got 13"}},
      {"TooManyDistractors", r(distractors, five), {"s.yaml:10:", "distractors: at most 4 allowed, got 5"}},
  };
}

INSTANTIATE_TEST_SUITE_P(Cases, ScenarioBadInput, ::testing::ValuesIn(scn_bad_inputs()), test::bad_input_name);

// ---- validate ----

TEST(ScenarioValidate, NamesTheFieldAtFault) {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  using S = Scenario;
  test::expect_validate_names_fields<Scenario>(
      {
          {"seed", [](S& s) { s.seed = 1ull << 60; }},
          {"time_limit", [&](S& s) { s.time_limit = nan; }},
          {"marker.dictionary", [](S& s) { s.marker.dictionary = "QR"; }},
          {"marker.id", [](S& s) { s.marker.id = -1; }},
          {"marker.size", [&](S& s) { s.marker.size = inf; }},
          {"marker.position", [&](S& s) { s.marker.position.y() = nan; }},
          {"distractors:", [](S& s) { s.distractors.resize(5); }},
          {"distractors[1].flipped_bits", [](S& s) { s.distractors[1].flipped_bits = 5; }},
          {"distractors[0].size", [&](S& s) { s.distractors[0].size = -inf; }},
          {"static_objects[0].size", [](S& s) { s.static_objects[0].size.x() = 0.01; }},
          {"static_objects[1].size[0]", [](S& s) { s.static_objects[1].size.x() = 9; }},
          {"static_objects[1].yaw_deg", [&](S& s) { s.static_objects[1].yaw_deg = nan; }},
          {"dynamic_objects[1].altitude", [](S& s) { s.dynamic_objects[1].altitude = 1; }},
          {"dynamic_objects[0].size[1]", [](S& s) { s.dynamic_objects[0].size.y() = 0.8; }},
          {"dynamic_objects:", [](S& s) { s.dynamic_objects.resize(7); }},
          {"weather.ambient", [](S& s) { s.weather.ambient = 0.1; }},
          {"weather.sun_azimuth_deg", [](S& s) { s.weather.sun_azimuth_deg = 361; }},
          {"weather.ground_snow", [&](S& s) { s.weather.ground_snow = nan; }},
          {"drone.position[2]", [](S& s) { s.drone.position.z() = 31; }},
          {"drone.yaw_deg", [](S& s) { s.drone.yaw_deg = -181; }},
          {"drone.gps_error", [&](S& s) { s.drone.gps_error.x() = inf; }},
          {"drone.position:",
           [](S& s) {
             s.drone.position = {2, 3, 4};
           }},  // on top of the 5 m pole
      },
      scn_full());
}

TEST(ScenarioValidate, AcceptsEveryKindWithinItsBounds) {
  Scenario s = scn_full();
  s.static_objects.push_back({StaticKind::Box, {5, 5}, 0, {3, 3, 3}});
  s.static_objects.push_back({StaticKind::Chair, {5, -5}, 0, {0.35, 0.8, 1.2}});
  DynamicObject dog;
  dog.kind = DynamicKind::Dog;
  dog.size = {1.2, 0.15, 0.3};
  dog.speed = 4;
  dog.motion = MotionKind::External;
  s.dynamic_objects.push_back(dog);
  s.weather.fog = 0.4;
  s.weather.ambient = 0.15;
  s.drone.position = {2, 3, 6};  // above the 5 m pole by 1 m
  std::string why;
  EXPECT_TRUE(s.validate(&why)) << why;
  EXPECT_TRUE(s.validate(nullptr));
}

TEST(ScenarioValidate, LookalikeAndPatternIdsNeedNotDifferFromTheMarker) {
  Scenario s = scn_full();
  s.distractors[1].id = s.marker.id;  // a lookalike's id is unused
  s.distractors[0].kind = DistractorKind::Pattern;
  s.distractors[0].id = 1000;  // a pattern's id is its grid seed, not a code
  std::string why;
  EXPECT_TRUE(s.validate(&why)) << why;
}

// ---- the bounds table ----

TEST(ScenarioBounds, KeysAreUniqueAndRangesOrdered) {
  std::set<std::string_view> keys;
  for (const auto& b : property_bounds()) {
    EXPECT_TRUE(keys.insert(b.key).second) << "duplicate " << b.key;
    EXPECT_LE(b.min, b.max) << b.key;
    EXPECT_FALSE(b.meaning.empty()) << b.key;
    if (b.integer) {
      EXPECT_EQ(b.min, std::floor(b.min)) << b.key;
      EXPECT_EQ(b.max, std::floor(b.max)) << b.key;
    }
    EXPECT_EQ(&property_bound(b.key), &b);
  }
  EXPECT_GE(keys.size(), 40u);
}

TEST(ScenarioBounds, PerKindRowsLieInsideTheirEnvelope) {
  for (const auto& b : property_bounds()) {
    const std::string key(b.key);
    const auto open = key.find('['), close = key.find(']');
    if (open == std::string::npos || close == open + 1 || key.substr(0, open) == "drone.position") continue;
    // "static_objects[pole].size[2]" -> "static_objects[].size"
    std::string envelope = key.substr(0, open) + "[]" + key.substr(close + 1);
    if (const auto sub = envelope.find('[', open + 2); sub != std::string::npos) envelope.resize(sub);
    const PropertyBound& e = property_bound(envelope);
    EXPECT_GE(b.min, e.min) << key;
    EXPECT_LE(b.max, e.max) << key;
  }
}

TEST(ScenarioBounds, RealisticValues) {
  EXPECT_EQ(property_bound("distractors").max, 4);
  EXPECT_EQ(property_bound("static_objects").max, 12);
  EXPECT_EQ(property_bound("dynamic_objects").max, 6);
  EXPECT_TRUE(property_bound("dynamic_objects").integer);
  EXPECT_EQ(property_bound("dynamic_objects[person].speed").max, 2.5);
  EXPECT_EQ(property_bound("dynamic_objects[person].size[2]").min, 1.5);
  // The densest fog still leaves about 10 m of visibility (Koschmieder: 3.912 / extinction).
  EXPECT_GE(3.912 / property_bound("weather.fog").max, 9.5);
  EXPECT_EQ(property_bound("drone.position[2]").min, 4);
  EXPECT_EQ(property_bound("seed").max, 9007199254740992.0);
}

TEST(ScenarioBounds, UnknownKeyThrows) {
  EXPECT_THROW((void)property_bound("marker.colour"), InvalidArgument);
  EXPECT_NE(test::error_of([] { (void)property_bound("nope"); }).find("'nope'"), std::string::npos);
}

// docs/formats.md prints the table: every row, exactly.
TEST(ScenarioBounds, DocsListEveryRow) {
  const std::string docs = test::read_text(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "docs/formats.md");
  ASSERT_FALSE(docs.empty());
  for (const auto& b : property_bounds()) {
    std::string unit(b.unit);
    if (b.integer) unit += unit.empty() ? "integer" : ", integer";
    const std::string row = "| `" + std::string(b.key) + "` | " + scn_num(b.min) + " | " + scn_num(b.max) + " | " +
                            unit + " | " + std::string(b.meaning) + " |";
    EXPECT_NE(docs.find(row + "\n"), std::string::npos) << "docs/formats.md lacks the row\n" << row;
  }
}

// The example of docs/formats.md, "Landing scenarios", is a valid file.
TEST(ScenarioIo, DocsExampleParses) {
  const std::string docs = test::read_text(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "docs/formats.md");
  const auto section = docs.find("## Landing scenarios");
  ASSERT_NE(section, std::string::npos);
  const auto begin = docs.find("```yaml\n", section);
  ASSERT_NE(begin, std::string::npos);
  const auto end = docs.find("```", begin + 8);
  const Scenario s = parse_scenario(docs.substr(begin + 8, end - begin - 8), "formats.md");
  EXPECT_EQ(s.distractors.size(), 2u);
  EXPECT_EQ(s.static_objects.size(), 2u);
  EXPECT_EQ(s.dynamic_objects.size(), 2u);
}

// ---- names ----

TEST(ScenarioNames, EnumsHaveTheirFileNames) {
  EXPECT_EQ(to_string(MapKind::Lawn), "lawn");
  EXPECT_EQ(to_string(DistractorKind::Lookalike), "lookalike");
  EXPECT_EQ(to_string(StaticKind::Tree), "tree");
  EXPECT_EQ(to_string(DynamicKind::Dog), "dog");
  EXPECT_EQ(to_string(MotionKind::External), "external");
  EXPECT_EQ(to_string(MotionKind::Wander), "wander");
}

// ---- random scenarios ----

TEST(ScenarioRandom, SameSeedSameScenarioAndEveryOneValid) {
  std::set<std::string> distinct;
  for (std::uint64_t seed = 0; seed < 500; ++seed) {
    const Scenario s = random_scenario(seed);
    std::string why;
    ASSERT_TRUE(s.validate(&why)) << "seed " << seed << ": " << why << "\n" << to_yaml(s);
    EXPECT_TRUE(s == random_scenario(seed)) << seed;
    EXPECT_TRUE(s == random_scenario(seed, s.map)) << seed;
    distinct.insert(to_yaml(s));
  }
  EXPECT_EQ(distinct.size(), 500u);
}

TEST(ScenarioRandom, FixedMapIsKept) {
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    EXPECT_EQ(random_scenario(seed, MapKind::Lawn).map, MapKind::Lawn);
    EXPECT_EQ(random_scenario(seed, MapKind::Ground).map, MapKind::Ground);
  }
}

// The draws look like landing tests: marker near the origin, drone a few
// metres off at approach height, scripted objects, mostly light fog, and
// over many seeds every kind of thing shows up.
TEST(ScenarioRandom, DrawsLookLikeLandingTests) {
  std::set<int> distractor_kinds, static_kinds, dynamic_kinds, motions, maps;
  int light_fog = 0, foggy = 0, with_rain = 0;
  const int n = 500;
  for (int seed = 0; seed < n; ++seed) {
    const Scenario s = random_scenario(static_cast<std::uint64_t>(seed));
    maps.insert(static_cast<int>(s.map));
    EXPECT_LE(s.marker.position.cwiseAbs().maxCoeff(), 3.0);
    const double d = (s.drone.position.head<2>() - s.marker.position).norm();
    EXPECT_GE(d, 5 - 0.01);
    EXPECT_LE(d, 15 + 0.01);
    EXPECT_GE(s.drone.position.z(), 8.0);
    EXPECT_LE(s.drone.gps_error.cwiseAbs().maxCoeff(), 3.0);
    EXPECT_LE(s.distractors.size(), 3u);
    EXPECT_LE(s.static_objects.size(), 6u);
    EXPECT_LE(s.dynamic_objects.size(), 3u);
    for (const auto& x : s.distractors) {
      distractor_kinds.insert(static_cast<int>(x.kind));
      EXPECT_GE((x.position - s.marker.position).norm(), 1.5 - 0.01);
    }
    for (const auto& o : s.static_objects) {
      static_kinds.insert(static_cast<int>(o.kind));
      EXPECT_LE(o.position.cwiseAbs().maxCoeff(), 12.0);
    }
    for (const auto& o : s.dynamic_objects) {
      dynamic_kinds.insert(static_cast<int>(o.kind));
      motions.insert(static_cast<int>(o.motion));
      EXPECT_NE(o.motion, MotionKind::External);
    }
    if (s.weather.fog > 0 && s.weather.fog <= 0.15) ++light_fog;
    if (s.weather.fog > 0.15) ++foggy;
    if (s.weather.rain > 0) ++with_rain;
  }
  EXPECT_EQ(maps.size(), 2u);
  EXPECT_EQ(distractor_kinds.size(), 3u);
  EXPECT_EQ(static_kinds.size(), 4u);
  EXPECT_EQ(dynamic_kinds.size(), 3u);
  EXPECT_EQ(motions.size(), 4u);  // still, line, circle, wander
  EXPECT_GT(light_fog, 2 * foggy);
  EXPECT_GT(foggy, 0);
  EXPECT_GT(with_rain, n / 4);
  EXPECT_LT(with_rain, 3 * n / 4);
}

}  // namespace
}  // namespace touchdown::scenario
