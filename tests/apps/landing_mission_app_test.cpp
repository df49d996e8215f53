// landing_mission end to end: the bundled mission (summary, JSON schema,
// thread-count determinism), the plots and the trace CSV, the envelope, and
// bad input (exit 2, one line naming the key, no output left behind).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.hpp"

namespace td = touchdown;
using td::test::AppRun;
using td::test::TempDir;

namespace {

AppRun run(const std::string& args, const TempDir& dir) { return td::test::run_app(LANDING_MISSION_EXE, args, dir); }

std::string bundled() { return (std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/missions/circle.yaml").string(); }

// The JSON without the wall-time figures (the replans' median and the
// missions' wall time: the only ones that may differ between runs).
nlohmann::json without_timing(nlohmann::json j) {
  j["summary"].erase("replan_ms_median");
  j.erase("seconds");
  return j;
}

}  // namespace

TEST(LandingMissionApp, BundledMissionsLandAndAreTheSameOnAnyThreadCount) {
  TempDir dir;
  const AppRun one = run(bundled() + " --runs 4 --threads 1 --json", dir);
  ASSERT_EQ(one.code, 0) << one.err;
  const auto j = nlohmann::json::parse(one.out);
  EXPECT_EQ(j["summary"]["runs"], 4);
  EXPECT_EQ(j["summary"]["landed"], 4);
  ASSERT_EQ(j["missions"].size(), 4u);
  for (const auto& m : j["missions"]) {
    EXPECT_EQ(m["outcome"], "landed");
    EXPECT_LT(m["touchdown_error_m"].get<double>(), 0.1);
    EXPECT_EQ(m["transitions"].back()["to"], "shutdown");
  }
  const AppRun two = run(bundled() + " --runs 4 --threads 2 --json", dir);
  ASSERT_EQ(two.code, 0) << two.err;
  const auto j2 = nlohmann::json::parse(two.out);
  EXPECT_EQ(without_timing(j), without_timing(j2));
  // The human summary.
  const AppRun text = run(bundled() + " --runs 2", dir);
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("landed 2 (100.0 %)"), std::string::npos) << text.out;
}

TEST(LandingMissionApp, PlotsAndTraceOfRunZero) {
  TempDir dir;
  const auto plots = dir / "plots", log = dir / "run0.csv";
  const AppRun r = run("--runs 1 --plot " + plots.string() + " --log " + log.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* name : {"positions.svg", "velocities.svg", "errors.svg", "top_view.svg"}) {
    const std::string svg = td::test::read_text(plots / name);
    EXPECT_NE(svg.find("<svg"), std::string::npos) << name;
    EXPECT_NE(svg.find("built-in circle mission"), std::string::npos) << name;
  }
  const std::string csv = td::test::read_text(log);
  EXPECT_EQ(csv.rfind("t_s,state,x_m", 0), 0u);
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 500);  // 50 Hz over a ~20 s mission
  EXPECT_NE(csv.find(",shutdown,"), std::string::npos);
}

TEST(LandingMissionApp, EnvelopeOverSpeedAndWind) {
  TempDir dir;
  const auto svg = dir / "envelope.svg";
  const AppRun r = run("envelope --speeds 1:2:1 --winds 0:2:2 --runs 2 --json --plot " + svg.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["cells"].size(), 4u);
  for (const auto& c : j["cells"]) {
    EXPECT_EQ(c["runs"], 2);
    EXPECT_GE(c["landed"].get<int>(), 0);
  }
  EXPECT_EQ(j["cells"][0]["speed_mps"], 1.0);
  // Each cell's reasons add up to the runs that did not land.
  for (const auto& c : j["cells"]) {
    int why = 0;
    for (const auto& reason : c["reasons"]) why += reason["runs"].get<int>();
    EXPECT_EQ(why, c["runs"].get<int>() - c["landed"].get<int>()) << c;
  }
  EXPECT_NE(td::test::read_text(svg).find("Landing envelope"), std::string::npos);
}

// Issue 56 item 6: one envelope per path x turbulence level, each with its
// plot; the landed cells carry their touchdown error and speed.
TEST(LandingMissionApp, EnvelopeOverPathsAndTurbulenceLevels) {
  TempDir dir;
  const auto svg = dir / "env.svg";
  const AppRun r =
      run("envelope --speeds 1:1:1 --winds 0:0:1 --runs 2 --paths circle,line --turbulence none,light "
          "--json --plot " +
              svg.string(),
          dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["envelopes"].size(), 4u);
  std::vector<std::string> seen;
  for (const auto& e : j["envelopes"]) {
    seen.push_back(e["path"].get<std::string>() + "/" + e["turbulence"].get<std::string>());
    ASSERT_EQ(e["cells"].size(), 1u);
    const auto& c = e["cells"][0];
    if (c["landed"].get<int>() > 0) {
      EXPECT_GE(c["touchdown_error_m"]["p95"].get<double>(), c["touchdown_error_m"]["median"].get<double>());
      EXPECT_GT(c["touchdown_speed_mps"]["median"].get<double>(), 0.0);
    } else {
      EXPECT_TRUE(c["touchdown_error_m"].is_null());
    }
    EXPECT_TRUE(std::filesystem::exists(
        dir / ("env_" + e["path"].get<std::string>() + "_" + e["turbulence"].get<std::string>() + ".svg")));
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"circle/none", "circle/light", "line/none", "line/light"}));
  EXPECT_FALSE(std::filesystem::exists(svg));
  const AppRun bad = run("envelope --paths circle,nowhere", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("--paths"), std::string::npos) << bad.err;
  // A grid no one reads and no run ends: refused before anything flies.
  const AppRun huge = run("envelope --winds 0:8:0.0001", dir);
  EXPECT_EQ(huge.code, 2);
  EXPECT_NE(huge.err.find("at most 10000"), std::string::npos) << huge.err;
  // The road's bends on the built-in 8 m circle mission: nothing flown, and said so.
  const AppRun none = run("envelope --speeds 1:1:1 --winds 0:0:1 --runs 1 --paths road", dir);
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_NE(none.out.find("no mission flown"), std::string::npos) << none.out;
  EXPECT_EQ(none.out.find("every mission flown landed"), std::string::npos) << none.out;
}

// Issue 58 item 8: the summary says why missions did not land, not only
// "timeout"; the JSON has the reason per mission and the counts.
TEST(LandingMissionApp, TheSummaryNamesWhyMissionsDidNotLand) {
  TempDir dir;
  const std::string airframe = (std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/quad180.yaml").string();
  const auto path = dir / "short.yaml";
  td::test::write_text(path,
                       td::test::replace(td::test::replace(td::test::read_text(bundled()), "timeout: 90", "timeout: 4"),
                                         "../airframes/quad180.yaml", airframe));
  const AppRun text = run(path.string() + " --runs 2", dir);
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("timeout 2\n  why not landed: timeout in "), std::string::npos) << text.out;
  const AppRun js = run(path.string() + " --runs 2 --json", dir);
  ASSERT_EQ(js.code, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  ASSERT_EQ(j["summary"]["reasons"].size(), 1U) << j["summary"];
  EXPECT_EQ(j["summary"]["reasons"][0]["runs"], 2);
  const std::string why = j["summary"]["reasons"][0]["reason"];
  EXPECT_EQ(why.rfind("timeout in ", 0), 0U) << why;
  for (const auto& m : j["missions"]) EXPECT_EQ(m["reason"], why);
  // A landing has no reason.
  const AppRun ok = run(bundled() + " --runs 1 --json", dir);
  EXPECT_TRUE(nlohmann::json::parse(ok.out)["missions"][0]["reason"].is_null());
}

TEST(LandingMissionApp, BadInputIsOneLineAndExitTwo) {
  TempDir dir;
  const auto bad = dir / "bad.yaml";
  const std::string airframe = (std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/quad180.yaml").string();
  td::test::write_text(
      bad, td::test::replace(td::test::replace(td::test::read_text(bundled()), "  radius: 8.0 ", "  radius: -1 "),
                             "../airframes/quad180.yaml", airframe));
  const auto log = dir / "out.csv";
  AppRun r = run(bad.string() + " --log " + log.string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("bad.yaml:15: vehicle.radius"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(log));
  r = run("--runs 0", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--runs"), std::string::npos) << r.err;
  r = run("--perception sonar", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("model, render"), std::string::npos) << r.err;
  // A missing file reads as every reader of the library says it (issue
  // 58 item 9: CLI11's "File does not exist" was a shape of its own).
  const std::string missing = (dir / "nowhere.yaml").string();
  r = run(missing, dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "landing_mission: mission: " + missing + ": cannot open: no such file (see --help)\n");
  r = run("envelope " + dir.path().string(), dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(dir.path().string() + ": cannot open: is a directory"), std::string::npos) << r.err;
  r = run("envelope --speeds 2:1:0.5", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--speeds"), std::string::npos) << r.err;
  r = run("--help", dir);
  EXPECT_EQ(r.code, 0);
  td::test::expect_help_shows_defaults(r.out);
}
