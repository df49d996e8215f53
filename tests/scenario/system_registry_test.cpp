// The landing-system registry, spec strings and plug-in libraries
// (system_registry.hpp, plugin.hpp), with the plug-ins of tests/scenario/plugins/.
#include "touchdown/scenario/system_registry.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "plugins/gps_lander.hpp"
#include "same_campaign.hpp"
#include "touchdown/core/registry.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/marker_detector.hpp"
#include "touchdown/scenario/plugin.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no InvalidArgument)";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Registry, RefusesDuplicatesAndBadNamesAndListsTheKnownOnes) {
  Registry<int> r("widget");
  r.add("b-1", "the second", 2);
  r.add("a.0", "the first", 1);
  EXPECT_EQ(r.names(), (std::vector<std::string>{"a.0", "b-1"}));  // sorted
  EXPECT_EQ(r.get("b-1").factory, 2);
  EXPECT_EQ(r.get("a.0").description, "the first");
  EXPECT_FALSE(r.find("c").has_value());
  EXPECT_EQ(message_of([&] { r.add("a.0", "again", 3); }), "widget 'a.0' is already registered");
  EXPECT_EQ(r.get("a.0").factory, 1);  // the first one stays
  EXPECT_EQ(message_of([&] { (void)r.get("zz"); }), "widget: unknown 'zz' (known: a.0, b-1)");
  EXPECT_EQ(r.known(), "a.0, b-1");
  EXPECT_TRUE(contains(message_of([&] { r.add("", "x", 0); }), "empty name"));
  EXPECT_TRUE(contains(message_of([&] { r.add("a:b", "x", 0); }), "names use only"));
  EXPECT_TRUE(contains(message_of([&] { r.add("c", "two\nlines", 0); }), "one line"));
  EXPECT_TRUE(contains(message_of([&] { r.add("c", "one line", "options\non two", 0); }), "options must be one line"));
  EXPECT_EQ(r.get("b-1").options, "");  // added without options
  EXPECT_EQ(r.names().size(), 2U);
  EXPECT_TRUE(r.remove("a.0"));
  EXPECT_FALSE(r.remove("a.0"));
  EXPECT_EQ(r.known(), "b-1");
  r.add("a.0", "back again", 4);  // a removed name may be registered anew
  EXPECT_EQ(r.get("a.0").factory, 4);
}

TEST(SystemRegistry, HoldsTheBuiltInsWithDescriptions) {
  const auto entries = system_registry().entries();
  std::vector<std::string> names;
  for (const auto& e : entries) {
    names.push_back(e.name);
    EXPECT_FALSE(e.description.empty()) << e.name;
  }
  EXPECT_TRUE(contains(system_registry().get("opencv-mls").options, "--detector"))
      << "the built-ins list their options";
  for (const char* builtin : {"learned-mls", "mm-mls", "opencv-mls"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), builtin), names.end()) << builtin;
  }
  EXPECT_EQ(SystemFactory("mm-mls").make()->name(), "mm-mls");
  EXPECT_EQ(SystemFactory().make()->name(), "opencv-mls");
  const std::string unknown = message_of([] { (void)SystemFactory("mm-msl").make(); });
  EXPECT_TRUE(contains(unknown, "landing system: unknown 'mm-msl' (known: ")) << unknown;
  EXPECT_TRUE(contains(unknown, "mm-mls")) << unknown;
  EXPECT_THROW((void)make_landing_system("no-such"), InvalidArgument);
}

// A detector that sees nothing and counts the frames it was shown.
class CountingDetector final : public MarkerDetector {
 public:
  explicit CountingDetector(int* frames) : frames_(frames) {}
  [[nodiscard]] std::string_view name() const override { return "test-counting"; }
  void reset(std::string_view /*dictionary*/, int /*marker_id*/) override {}
  void detect(const DetectorFrame& /*frame*/, std::vector<MarkerDetection>& out) override {
    out.clear();
    ++*frames_;
  }

 private:
  int* frames_;
};

TEST(DetectorRegistry, ADetectorYouAddIsTheOneAReferenceSystemUses) {
  EXPECT_EQ(marker_detector_names(), (std::vector<std::string>{"aruco", "learned"}));
  static int frames = 0;
  detector_registry().add("test-counting", "counts frames, sees nothing",
                          [](const DetectorOptions&) { return std::make_unique<CountingDetector>(&frames); });
  // Process-wide: taken out again however this test ends.
  struct Unregister {
    ~Unregister() { detector_registry().remove("test-counting"); }
  } unregister;
  MlsOptions o;
  o.detector.kind = "test-counting";
  std::string why;
  EXPECT_TRUE(o.detector.validate(&why)) << why;
  auto system = make_landing_system("opencv-mls", o);
  Scenario s;
  s.time_limit = 10;
  const ScenarioResult r = run_scenario(s, *system, RunOptions{});
  // 10 Hz for 10 s: the frames went to the registered detector.
  EXPECT_EQ(frames, static_cast<int>(r.frames.size()));
  EXPECT_GT(frames, 80);
  o.detector.kind = "yolo";
  EXPECT_FALSE(o.detector.validate(&why));
  EXPECT_EQ(why, "detector: unknown 'yolo' (known: aruco, learned, test-counting)");
  EXPECT_TRUE(detector_registry().remove("test-counting"));
  EXPECT_EQ(marker_detector_names(), (std::vector<std::string>{"aruco", "learned"}));
}

TEST(SystemRegistry, AFactoryOfYourOwnIsUsedAndNamed) {
  int made = 0;
  SystemFactory own("my-lander", [&made](const MlsOptions&) {
    ++made;
    return std::make_unique<test_plugin::GpsLander>("my-lander");
  });
  EXPECT_EQ(own.name(), "my-lander");
  EXPECT_TRUE(own == "my-lander");
  EXPECT_EQ(own.make()->name(), "my-lander");
  EXPECT_EQ(made, 1);
  SystemFactory null_maker("null", [](const MlsOptions&) { return std::unique_ptr<LandingSystem>(); });
  EXPECT_TRUE(contains(message_of([&] { (void)null_maker.make(); }), "returned no system"));
  EXPECT_THROW(SystemFactory("empty", MakeSystem{}), InvalidArgument);
}

// ---- plug-in libraries -------------------------------------------------------------------

const std::string kGood = TOUCHDOWN_TEST_PLUGIN;
std::string bad_plugin(int kind) { return std::string(TOUCHDOWN_BAD_PLUGIN_PREFIX) + std::to_string(kind) + ".so"; }

TEST(Plugin, LoadsItsSystemsOnceAndResolvesSpecs) {
  const std::vector<std::string> names = load_system_plugin(kGood);
  EXPECT_EQ(names,
            (std::vector<std::string>{"test-gps-lander", "test-gps-lander-faulty", "test-stateful", "test-shared"}));
  EXPECT_EQ(load_system_plugin(kGood), names);  // loaded once: no "already registered"
  EXPECT_TRUE(system_registry().find("test-gps-lander").has_value());
  EXPECT_EQ(system_registry().get("test-gps-lander").options, "none: fixed gains");
  EXPECT_EQ(system_registry().get("test-stateful").options, "");  // the registrar's add without options
  EXPECT_EQ(SystemFactory("plugin:" + kGood + ":test-gps-lander").make()->name(), "test-gps-lander");
  EXPECT_EQ(SystemFactory("test-gps-lander-faulty").make()->name(), "test-gps-lander-faulty");  // registered now
  const std::string which = message_of([] { (void)resolve_system("plugin:" + kGood); });
  EXPECT_TRUE(contains(
      which, "registers 4 systems (test-gps-lander, test-gps-lander-faulty, test-stateful, test-shared): name one"))
      << which;
  const std::string none = message_of([] { (void)resolve_system("plugin:" + kGood + ":opencv-mls"); });
  EXPECT_TRUE(contains(none, "registers no 'opencv-mls'")) << none;
}

TEST(Plugin, RefusesAnotherVersionOrAbiBeforeRunningItsCode) {
  // Their register functions abort: reaching them would end the test program.
  const std::string version = message_of([] { (void)load_system_plugin(bad_plugin(1)); });
  EXPECT_TRUE(contains(version, "built against touchdown 0.0.1")) << version;
  EXPECT_TRUE(contains(version, "this is touchdown " TOUCHDOWN_VERSION)) << version;
  EXPECT_TRUE(contains(version, "rebuild it against this touchdown")) << version;
  const std::string abi = message_of([] { (void)load_system_plugin(bad_plugin(2)); });
  EXPECT_TRUE(contains(abi, "plug-in ABI " + std::to_string(kPluginAbiVersion + 41) + ", this touchdown loads ABI " +
                                std::to_string(kPluginAbiVersion)))
      << abi;
}

TEST(Plugin, RefusesWhatIsNotAPluginOrRegistersBadly) {
  const std::string taken = message_of([] { (void)load_system_plugin(bad_plugin(3)); });
  EXPECT_TRUE(contains(taken, "system 'opencv-mls' is already registered")) << taken;
  EXPECT_EQ(SystemFactory("opencv-mls").make()->name(), "opencv-mls");  // the built-in stays
  EXPECT_TRUE(contains(message_of([] { (void)load_system_plugin(bad_plugin(4)); }), "registers no landing system"));
  const std::string threw = message_of([] { (void)load_system_plugin(bad_plugin(5)); });
  EXPECT_TRUE(contains(threw, "registering its systems failed: no licence file")) << threw;
  const std::string entry = message_of([] { (void)load_system_plugin(bad_plugin(6)); });
  EXPECT_TRUE(contains(entry, "not a touchdown plug-in (it has no touchdown_plugin_info entry point")) << entry;
  EXPECT_TRUE(contains(message_of([] { (void)load_system_plugin("/nonexistent/libx.so"); }), "no such file"));
  // A file that is not a shared library at all.
  const std::string text = message_of([] { (void)load_system_plugin(TOUCHDOWN_SOURCE_DIR "/README.md"); });
  EXPECT_TRUE(contains(text, "plugin:" TOUCHDOWN_SOURCE_DIR "/README.md: cannot load: ")) << text;
}

TEST(Plugin, CampaignEqualsTheSameCodeBuiltIn) {
  std::vector<Scenario> scenarios = random_scenarios(7, 4, MapKind::Ground);
  for (Scenario& s : scenarios) s.time_limit = 30;
  CampaignOptions o;
  o.threads = 2;
  o.system = "plugin:" + kGood + ":test-gps-lander";
  const CampaignResult via_plugin = run_campaign(scenarios, o);
  o.system = SystemFactory(
      "built-in", [](const MlsOptions&) { return std::make_unique<test_plugin::GpsLander>("test-gps-lander"); });
  o.threads = 1;
  const CampaignResult built_in = run_campaign(scenarios, o);
  EXPECT_GT(test::expect_same_outcomes(via_plugin, built_in), 0);  // bit for bit, and the lander does land
}

}  // namespace
}  // namespace touchdown::scenario
