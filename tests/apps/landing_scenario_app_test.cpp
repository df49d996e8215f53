// landing_scenario end to end: the bundled scenario lands, --json/--log/
// --snapshot outputs, random scenarios are valid and replay, bad input is
// one line naming the key with exit 2 and no output file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <string>

#include "test_util.hpp"

namespace td = touchdown;
using td::test::AppRun;
using td::test::TempDir;

namespace {

AppRun scenario_app(const std::string& args, const TempDir& dir) {
  return td::test::run_app(LANDING_SCENARIO_EXE, args, dir);
}

std::string bundled_scenario() {
  return (std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/scenarios/clear_ground.yaml").string();
}

TEST(LandingScenarioApp, BundledScenarioLandsWithJsonLogAndSnapshot) {
  TempDir dir;
  const auto log = dir / "run.csv", png = dir / "frame.png";
  const AppRun r = scenario_app("run " + bundled_scenario() + " --json --log " + log.string() + " --snapshot " +
                                    png.string() + " --snapshot-t 12",
                                dir);
  ASSERT_EQ(r.code, 0) << r.err;
  td::test::expect_one_json_line(r.out);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["system"], "opencv-mls");
  EXPECT_EQ(j["violation"], false) << j["message"];
  EXPECT_EQ(j["type"], "none");
  EXPECT_EQ(j["landed"], true);
  EXPECT_LT(j["dtl"].get<double>(), 1.5);
  EXPECT_GT(j["frames"].size(), 50u);
  // eq. 5 inputs: with nothing over the marker, visible ≈ true area.
  for (const auto& f : j["frames"]) {
    const double truth = f["marker_area_truth_px"].get<double>();
    if (truth > 500) {
      EXPECT_NEAR(f["marker_area_visible_px"].get<double>(), truth, 0.1 * truth) << f.dump();
    }
  }
  const std::string csv = td::test::read_text(log);
  EXPECT_EQ(csv.rfind("t,x,y,z,vx,vy,vz,yaw_deg,phase,", 0), 0u);
  EXPECT_NE(csv.find(",land,"), std::string::npos);
  EXPECT_GT(std::filesystem::file_size(png), 10000u);
  // Not a terminal: no progress bar, nothing at all on stderr.
  EXPECT_TRUE(r.err.empty()) << r.err;
}

// The outcome banner's colour (BGR) at the frame's bottom-left corner, where
// the banner has no text; the camera image there is never exactly that.
bool has_outcome_banner(const std::filesystem::path& png) {
  const cv::Mat img = cv::imread(png.string(), cv::IMREAD_COLOR);
  if (img.empty()) return false;
  for (int row = img.rows - 38; row < img.rows - 2; ++row) {
    for (int col = 0; col < 6; ++col) {
      if (img.at<cv::Vec3b>(row, col) != cv::Vec3b(0, 140, 0)) return false;
    }
  }
  return true;
}

// Issue 31 item 10: a snapshot at 9 s (mid-descent, 7.9 m up) showed
// "LANDED (no violation)", and one past the end of the flight silently gave
// the last frame. The banner is only on frames after the outcome; a time
// past the end is refused, leaving no output.
TEST(LandingScenarioApp, OutcomeBannerOnlyOnFramesAfterTheOutcome) {
  TempDir dir;
  const auto mid = dir / "mid.png", last = dir / "last.png";
  const AppRun r =
      scenario_app("run " + bundled_scenario() + " --json --snapshot " + mid.string() + " --snapshot-t 9", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(nlohmann::json::parse(r.out)["violation"], false);
  ASSERT_TRUE(std::filesystem::exists(mid));
  EXPECT_FALSE(has_outcome_banner(mid));
  const AppRun d = scenario_app("run " + bundled_scenario() + " --snapshot " + last.string(), dir);
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_TRUE(has_outcome_banner(last));  // by default: the last frame, after the outcome

  // Past the end of the flight (known after the run): exit 2, one line with
  // the requested time and the flight's end, no file.
  TempDir out;
  const auto late = out / "late.png", log = out / "late.csv";
  const AppRun e = scenario_app(
      "run " + bundled_scenario() + " --snapshot " + late.string() + " --snapshot-t 50 --log " + log.string(), out);
  EXPECT_EQ(e.code, 2) << e.err;
  EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << e.err;
  const std::string key = "--snapshot-t 50: after the end of the flight at ";
  const auto at = e.err.find(key);
  ASSERT_NE(at, std::string::npos) << e.err;
  EXPECT_TRUE(e.out.empty()) << e.out;
  EXPECT_TRUE(out.files().empty()) << out.files().front();
  // Exactly at the end: the outcome frame, with the banner.
  const double end = std::stod(e.err.substr(at + key.size()));
  EXPECT_GT(end, 10.0);
  EXPECT_LT(end, 50.0);
  const auto at_end = dir / "end.png";
  const AppRun f = scenario_app(
      "run " + bundled_scenario() + " --snapshot " + at_end.string() + " --snapshot-t " + std::to_string(end), dir);
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_TRUE(has_outcome_banner(at_end));

  // Past the scenario's own time limit (60 s): refused before the run.
  const AppRun g = scenario_app("run " + bundled_scenario() + " --snapshot " + late.string() + " --snapshot-t 61", out);
  EXPECT_EQ(g.code, 2);
  EXPECT_NE(g.err.find("--snapshot-t 61: after the time limit of "), std::string::npos) << g.err;
  EXPECT_NE(g.err.find("clear_ground.yaml (60 s)"), std::string::npos) << g.err;
  EXPECT_TRUE(out.files().empty()) << out.files().front();
}

TEST(LandingScenarioApp, RandomScenariosAreValidAndRunIdentically) {
  TempDir dir;
  const auto yaml = dir / "random.yaml", json = dir / "random.json";
  ASSERT_EQ(scenario_app("random --seed 5 --map lawn -o " + yaml.string(), dir).code, 0);
  ASSERT_EQ(scenario_app("random --seed 5 --map lawn -o " + json.string(), dir).code, 0);
  const AppRun a = scenario_app("run " + yaml.string() + " --json", dir);
  const AppRun b = scenario_app("run " + json.string() + " --json", dir);
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  for (auto* j : {&ja, &jb}) {
    j->erase("timing");
    j->erase("scenario");
  }
  EXPECT_EQ(ja, jb);
  EXPECT_EQ(ja["frames"].size(), jb["frames"].size());
}

TEST(LandingScenarioApp, CampaignOverFilesWritesSummaryAndCsv) {
  TempDir dir;
  const auto csv = dir / "campaign.csv";
  const AppRun r = scenario_app(
      "campaign " + bundled_scenario() + " " + bundled_scenario() + " --threads 2 --json --csv " + csv.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // not a terminal: no progress bar
  td::test::expect_one_json_line(r.out);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["count"], 2);
  EXPECT_EQ(j["violations"], 0);
  EXPECT_EQ(j["type_i"].get<int>() + j["type_ii"].get<int>() + j["type_iii"].get<int>(), 0);
  EXPECT_GT(j["flight_s"].get<double>(), 30.0);
  const std::string text = td::test::read_text(csv);
  EXPECT_EQ(text.rfind("scenario,map,violation,type,landed,dtl,ttl,", 0), 0u);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3);
  EXPECT_NE(text.find(",ground,0,none,1,"), std::string::npos) << text;

  // A bad file among them: exit 2 naming it, no CSV, nothing on stdout.
  const auto bad = dir / "bad.yaml";
  td::test::write_text(bad, td::test::replace(td::test::read_text(bundled_scenario()), "map: ground", "map: moon"));
  const auto csv2 = dir / "c2.csv";
  const AppRun b = scenario_app("campaign " + bundled_scenario() + " " + bad.string() + " --csv " + csv2.string(), dir);
  EXPECT_EQ(b.code, 2);
  EXPECT_NE(b.err.find("bad.yaml"), std::string::npos) << b.err;
  EXPECT_TRUE(b.out.empty());
  EXPECT_FALSE(std::filesystem::exists(csv2));
  // Random-campaign options do not mix with files.
  EXPECT_EQ(scenario_app("campaign " + bundled_scenario() + " --seed 3", dir).code, 2);
  EXPECT_EQ(scenario_app("campaign --count 0", dir).code, 2);
}

// The contract from the command line (issue 55): a system that keeps it
// passes every clause; one that keeps state across reset() and one whose
// objects share state fail the clause that says so, with exit 1; a spec
// that does not resolve is bad input.
TEST(LandingScenarioApp, ContractCommandPassesASoundSystemAndNamesTheBrokenClause) {
  TempDir dir;
  const std::string plugin = std::string("plugin:") + TOUCHDOWN_TEST_PLUGIN + ":";
  const AppRun sound = scenario_app("contract --max-time 6 --system " + plugin + "test-gps-lander", dir);
  EXPECT_EQ(sound.code, 0) << sound.out << sound.err;
  EXPECT_NE(sound.out.find("reset          ok"), std::string::npos) << sound.out;
  EXPECT_NE(sound.out.find("result     every clause holds"), std::string::npos) << sound.out;

  const AppRun stateful = scenario_app("contract --max-time 6 --system " + plugin + "test-stateful", dir);
  EXPECT_EQ(stateful.code, 1) << stateful.out << stateful.err;
  EXPECT_NE(stateful.out.find("reset          FAILED"), std::string::npos) << stateful.out;
  EXPECT_NE(stateful.out.find("the second run of one object differs from its first at step 0"), std::string::npos)
      << stateful.out;
  EXPECT_NE(stateful.out.find("deterministic  ok"), std::string::npos) << stateful.out;

  const AppRun shared = scenario_app("contract --max-time 6 --system " + plugin + "test-shared --json", dir);
  EXPECT_EQ(shared.code, 1) << shared.out << shared.err;
  std::istringstream lines(shared.out);
  std::set<std::string> failed;
  for (std::string line; std::getline(lines, line);) {
    const auto j = nlohmann::json::parse(line);
    if (!j.at("ok").get<bool>()) failed.insert(j.at("clause").get<std::string>());
  }
  EXPECT_TRUE(failed.count("deterministic")) << shared.out;
  EXPECT_TRUE(failed.count("independent")) << shared.out;
  EXPECT_FALSE(failed.count("name")) << shared.out;

  const AppRun faulty = scenario_app("contract --max-time 6 --system " + plugin + "test-gps-lander-faulty", dir);
  EXPECT_EQ(faulty.code, 1);
  EXPECT_NE(faulty.out.find("the system failed: update() threw at t = 3.00 s"), std::string::npos) << faulty.out;
  // A run of it says it failed, not "ok", and gives no DTL/TTL (they would be the time limit's).
  const AppRun failed_run =
      scenario_app("run " + bundled_scenario() + " --system " + plugin + "test-gps-lander-faulty", dir);
  EXPECT_NE(failed_run.out.find("outcome    SYSTEM FAILED (no verdict): "), std::string::npos) << failed_run.out;
  EXPECT_EQ(failed_run.out.find("DTL"), std::string::npos) << failed_run.out;

  const AppRun unknown = scenario_app("contract --system plugin:/nonexistent.so", dir);
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("plugin:/nonexistent.so: no such file"), std::string::npos) << unknown.err;
  EXPECT_TRUE(unknown.out.empty());
}

// Interrupted, a campaign on a process system leaves none of its processes
// behind (issue 55): the children get SIGKILL when their thread ends.
TEST(LandingScenarioApp, AnInterruptedExecCampaignLeavesNoProcess) {
  TempDir dir;
  const std::string tag = dir.path().filename().string();  // marks this test's children
  // Children that hang at their 5th step: only their SIGKILL on the host thread's end stops them.
  const std::string spec = std::string("'exec:") + TOUCHDOWN_EXEC_CHILD + " sleep 5 " + tag + "'";
  const AppRun r = td::test::run_app("timeout -s INT 3 " + std::string(LANDING_SCENARIO_EXE),
                                     "campaign --system " + spec + " --count 50 --map ground --threads 2", dir);
  EXPECT_NE(r.code, 0);  // interrupted
  // "[x]yz" matches "xyz" but not the shell's own command line, which holds "[x]yz".
  const AppRun left = td::test::run_app("pgrep", "-f 'sleep 5 [" + tag.substr(0, 1) + "]" + tag.substr(1) + "'", dir);
  EXPECT_EQ(left.code, 1) << "still running: " << left.out;  // pgrep: 1 = no process matched
  // A system behind a wrapper that started something of its own: that goes too.
  const std::string stamp = "41." + std::to_string(::getpid());
  const std::string wrapped =
      std::string("\"exec:sh -c 'sleep ") + stamp + " & exec " + TOUCHDOWN_EXEC_CHILD + " sleep 5 " + tag + "'\"";
  const AppRun w = td::test::run_app("timeout -s INT 3 " + std::string(LANDING_SCENARIO_EXE),
                                     "campaign --system " + wrapped + " --count 50 --map ground --threads 2", dir);
  EXPECT_NE(w.code, 0);
  const std::string pattern = "sleep " + stamp.substr(0, 2) + "[.]" + stamp.substr(3);
  const AppRun stray = td::test::run_app("pgrep", "-f '" + pattern + "'", dir);
  EXPECT_EQ(stray.code, 1) << "still running: " << stray.out;
}

TEST(LandingScenarioApp, BadInputIsOneLineNamingTheKey) {
  TempDir dir;
  const std::string base = td::test::read_text(bundled_scenario());
  struct Case {
    std::string from, to, expect;
  };
  const std::vector<Case> cases{
      {"  size: 1.0 ", "  size: 9.0 ", "marker.size"},
      {"  id: 0", "  id: 77", "marker.id"},
      {"map: ground", "map: moon", "map"},
      {"  ambient: 1.0", "  ambient: .nan", "weather.ambient"},
      {"  ambient: 1.0", "  ambient: 1.0\n  hail: 0.3", "weather.hail"},
      {"  sun_elevation_deg: 50", "  sun_elevation_deg: 120", "weather.sun_elevation_deg"},
  };
  for (const auto& c : cases) {
    const auto path = dir / "bad.yaml";
    td::test::write_text(path, td::test::replace(base, c.from, c.to));
    const auto log = dir / "out.csv";
    const AppRun r = scenario_app("run " + path.string() + " --log " + log.string(), dir);
    EXPECT_EQ(r.code, 2) << c.to;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
    EXPECT_TRUE(r.out.empty());
    EXPECT_FALSE(std::filesystem::exists(log));
  }
  EXPECT_EQ(scenario_app("run " + bundled_scenario() + " --system px4", dir).code, 2);
  // Issue 31, item 9: the option's name once ("--video: --video: must end...").
  const AppRun gif = scenario_app("run " + bundled_scenario() + " --video x.gif", dir);
  EXPECT_EQ(gif.code, 2);
  EXPECT_NE(gif.err.find("--video: must end in .mp4 or .avi, got 'x.gif'"), std::string::npos) << gif.err;
  EXPECT_EQ(gif.err.find("--video: --video"), std::string::npos) << gif.err;
  const AppRun txt = scenario_app("random --seed 1 -o x.txt", dir);
  EXPECT_EQ(txt.code, 2);
  EXPECT_NE(txt.err.find("--output: must end in .yaml, .yml or .json, got 'x.txt'"), std::string::npos) << txt.err;
  EXPECT_EQ(txt.err.find("--output: --output"), std::string::npos) << txt.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.txt"));
  // An option that would be ignored is refused.
  const AppRun lone_t = scenario_app("run " + bundled_scenario() + " --snapshot-t 3", dir);
  EXPECT_EQ(lone_t.code, 2);
  EXPECT_NE(lone_t.err.find("--snapshot"), std::string::npos) << lone_t.err;
  // Issue 31, item 9: a negative seed was taken as 2^64 - 1, and campaign
  // seeds wrapped past it.
  for (const std::string& args :
       {std::string("random --seed -1 -o s.yaml"), std::string("campaign --seed -1 --count 2")}) {
    const AppRun neg = scenario_app(args, dir);
    EXPECT_EQ(neg.code, 2) << args;
    EXPECT_NE(neg.err.find("--seed: must be >= 0, got -1"), std::string::npos) << neg.err;
    EXPECT_EQ(neg.err.find('\n'), neg.err.size() - 1) << "one line: " << neg.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "s.yaml"));
  const AppRun wrap = scenario_app("campaign --seed 18446744073709551615 --count 2", dir);
  EXPECT_EQ(wrap.code, 2);
  EXPECT_NE(wrap.err.find("--seed 18446744073709551615 with --count 2: the seeds would pass"), std::string::npos)
      << wrap.err;
  EXPECT_TRUE(wrap.out.empty()) << wrap.out;
  // A map name is refused listing the accepted ones (from the names table).
  const AppRun bad_map = scenario_app("random --map moon -o x.yaml", dir);
  EXPECT_EQ(bad_map.code, 2);
  EXPECT_NE(bad_map.err.find("--map: expected one of ground, lawn, any; got 'moon'"), std::string::npos) << bad_map.err;
  EXPECT_EQ(scenario_app("run /nonexistent.yaml", dir).code, 2);
}

}  // namespace

// Issue 31 item 11: a campaign (minutes) and a run showed nothing while
// they worked. On a terminal (a pseudo-terminal from script(1)) a progress
// bar with the time left is drawn on stderr and completed before the
// results; the tests above check that stderr stays empty otherwise.
TEST(LandingScenarioApp, ProgressBarOnATerminal) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1) for a pseudo-terminal";
  TempDir dir;
  const auto on_tty = [&](const std::string& args) {
    const auto out = dir / "tty.txt";
    const std::string cmd =
        "script -qec \"" + std::string(LANDING_SCENARIO_EXE) + " " + args + "\" /dev/null > " + out.string() + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return td::test::read_text(out);
  };
  const std::string campaign =
      on_tty("campaign " + bundled_scenario() + " " + bundled_scenario() + " --threads 2 --json");
  const auto first = campaign.find("] 1/2  "), done = campaign.find("] 2/2  "), json = campaign.find('{');
  ASSERT_NE(first, std::string::npos) << campaign;
  EXPECT_NE(campaign.find(" s left", first), std::string::npos) << campaign;
  ASSERT_NE(done, std::string::npos) << campaign;
  ASSERT_NE(json, std::string::npos) << campaign;
  EXPECT_LT(first, done);
  EXPECT_LT(done, json);  // the bar is finished before the results
  // run: camera frames of the 60 s time limit at 10 Hz; completed at the
  // frames flown when it lands.
  const std::string run = on_tty("run " + bundled_scenario());
  EXPECT_NE(run.find("/600  "), std::string::npos) << run;
  EXPECT_NE(run.find(" s left"), std::string::npos) << run;
  const auto outcome = run.find("outcome    ok");
  ASSERT_NE(outcome, std::string::npos) << run;
  const auto last_bar = run.rfind("] ", outcome);
  ASSERT_NE(last_bar, std::string::npos) << run;
  const std::string counts = run.substr(last_bar + 2, run.find(' ', last_bar + 2) - last_bar - 2);
  const auto slash = counts.find('/');
  ASSERT_NE(slash, std::string::npos) << counts;
  EXPECT_EQ(counts.substr(0, slash), counts.substr(slash + 1)) << counts;  // complete: n/n
}

// Issue 31 item 2: a bad output path used to be found after the whole
// simulation, leaving the finished video behind. Every path is now checked
// before the run and a failed run leaves no file.
TEST(LandingScenarioApp, ABadOutputPathLeavesNoOtherOutput) {
  for (const std::string bad : {"--snapshot nope/a.png", "--log nope/l.csv", "--video nope/v.avi"}) {
    SCOPED_TRACE(bad);
    TempDir dir;
    const std::string good =
        bad.rfind("--video", 0) == 0 ? " --log " + (dir / "ok.csv").string() : " --video " + (dir / "ok.avi").string();
    const AppRun r = scenario_app("run " + bundled_scenario() + good + " " + bad, dir);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(bad.substr(0, bad.find(' ')) + ": nope/"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
    EXPECT_TRUE(dir.files().empty()) << dir.files().front();
  }
}

// detect-bench against the labels it reads: the "all" group's targets are
// the labels' taught targets counted here by the documented rule, every
// group is a subset of the frames, the oracle's sight groups partition the
// frames, and "clear, observable" is exactly those frames.
TEST(LandingScenarioApp, DetectBenchGroupsAgreeWithTheLabels) {
  TempDir dir;
  const auto ds = dir / "ds";
  ASSERT_EQ(scenario_app("dataset --out " + ds.string() + " --count 40 --seed 3 --threads 2", dir).code, 0);
  const AppRun r =
      scenario_app("detect-bench " + ds.string() + " --detectors aruco --json --plot " + (dir / "b.svg").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  int taught = 0, working = 0, with_sight = 0;
  std::set<std::string> weathers;
  std::istringstream labels(td::test::read_text(ds / "labels.jsonl"));
  std::string line;
  while (std::getline(labels, line)) {
    const nlohmann::json l = nlohmann::json::parse(line);
    weathers.insert(l.at("weather").get<std::string>());
    const auto& t = l.at("target");
    if (l.at("weather") == "clear" && t.at("sight") == "observable") ++working;
    ++with_sight;
    if (!t.at("in_view").get<bool>() || t.at("corners").size() != 4) continue;
    double side = 1e9;
    for (std::size_t k = 0; k < 4; ++k) {
      const auto& a = t.at("corners")[k];
      const auto& b = t.at("corners")[(k + 1) % 4];
      side =
          std::min(side, std::hypot(a[0].get<double>() - b[0].get<double>(), a[1].get<double>() - b[1].get<double>()));
    }
    if (t.at("inside_fraction").get<double>() >= 0.85 && t.at("visible_fraction").get<double>() >= 0.6 && side >= 8)
      ++taught;
  }
  const auto& groups = j.at("groups");
  EXPECT_EQ(groups.at("all").at("aruco").at("frames").get<int>(), 40);
  EXPECT_EQ(groups.at("all").at("aruco").at("targets").get<int>(), taught);
  int sight_frames = 0;
  for (const auto& [name, g] : groups.items()) {
    EXPECT_LE(g.at("aruco").at("targets").get<int>(), g.at("aruco").at("frames").get<int>()) << name;
    EXPECT_LE(g.at("aruco").at("hits").get<int>(), g.at("aruco").at("targets").get<int>()) << name;
    if (name.rfind("sight ", 0) == 0) sight_frames += g.at("aruco").at("frames").get<int>();
  }
  EXPECT_EQ(sight_frames, with_sight);
  if (working > 0) {
    EXPECT_EQ(groups.at("clear, observable").at("aruco").at("frames").get<int>(), working);
  } else {
    EXPECT_FALSE(groups.contains("clear, observable"));
  }
  // The plot: one panel (a bold title) per weather kind of the frames.
  const std::string svg = td::test::read_text(dir / "b.svg");
  std::size_t panels = 0;
  for (std::size_t at = svg.find("font-weight='bold'"); at != std::string::npos;
       at = svg.find("font-weight='bold'", at + 1))
    ++panels;
  EXPECT_EQ(panels, weathers.size());
  for (const std::string& w : weathers) EXPECT_NE(svg.find(">" + w + "<"), std::string::npos) << w;
  // A broken line is one line naming the file and the line, exit 2.
  std::string text = td::test::read_text(ds / "labels.jsonl");
  text.insert(text.find('\n') + 1, "{\"image\": 3}\n");
  td::test::write_text(ds / "labels.jsonl", text);
  const AppRun bad = scenario_app("detect-bench " + ds.string() + " --detectors aruco", dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("labels.jsonl:2: image"), std::string::npos) << bad.err;
  EXPECT_EQ(bad.err.find('\n'), bad.err.size() - 1) << "one line: " << bad.err;
  EXPECT_TRUE(bad.out.empty()) << bad.out;
}

// Issue 58 item 1: killed while the video was being written, the run used
// to leave .int.mp4.tmp-PID-0.mp4 behind.
TEST(LandingScenarioApp, ATerminatedRunLeavesNoVideo) {
  TempDir dir;
  const AppRun r = td::test::interrupt_app(
      LANDING_SCENARIO_EXE,
      "run " + bundled_scenario() + " --video " + (dir / "int.mp4").string() + " --log " + (dir / "int.csv").string(),
      dir, ".int.mp4.tmp-", "TERM");
  EXPECT_EQ(r.code, 128 + 15) << r.err;  // ended by SIGTERM
  EXPECT_NE(r.err.find("landing_scenario: interrupted (SIGTERM): removed "), std::string::npos) << r.err;
  EXPECT_TRUE(dir.files().empty()) << dir.files().front();
}
