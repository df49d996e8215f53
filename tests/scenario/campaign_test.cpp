// Campaigns (campaign.hpp): results identical for any thread count, the
// summary agrees with the entries, bad options are refused; and the
// reference systems' tracking ROI changes what is detected per frame but
// not where the drone lands.
#include "touchdown/scenario/campaign.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>

#include "scenario/clear_scenario.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {
namespace {

/// Short random scenarios (10 s: the shortest time limit allowed, seen at
/// 320×240) so that a campaign stays cheap under the sanitizers.
std::vector<Scenario> campaign_short_scenarios() {
  std::vector<Scenario> s = random_scenarios(40, 2, MapKind::Ground);
  for (auto& x : s) x.time_limit = 10;
  return s;
}

/// Three 10 s Ground scenarios, and options seeing them at 160×120.
std::vector<Scenario> three_short_scenarios() {
  std::vector<Scenario> s = random_scenarios(40, 3, MapKind::Ground);
  for (auto& x : s) x.time_limit = 10;
  return s;
}
CampaignOptions small_camera_options() {
  CampaignOptions o;
  o.run.camera.width = 160;
  o.run.camera.height = 120;
  return o;
}

TEST(Campaign, SameResultsForAnyThreadCount) {
  const std::vector<Scenario> scenarios = campaign_short_scenarios();
  CampaignOptions o;
  o.run.camera.width = 320;
  o.run.camera.height = 240;
  o.threads = 1;
  const CampaignResult one = run_campaign(scenarios, o);
  o.threads = 2;
  std::vector<std::size_t> reported;
  o.progress = [&](const touchdown::Progress& p) { reported.push_back(p.index); };
  const CampaignResult two = run_campaign(scenarios, o);
  ASSERT_EQ(one.entries.size(), scenarios.size());
  ASSERT_EQ(two.entries.size(), scenarios.size());
  EXPECT_EQ(reported.size(), scenarios.size());
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    const ScenarioOutcome& a = one.entries[i].outcome;
    const ScenarioOutcome& b = two.entries[i].outcome;
    EXPECT_EQ(a.status, b.status) << i;
    EXPECT_EQ(a.message, b.message) << i;
    EXPECT_EQ(a.dtl, b.dtl) << i;
    EXPECT_EQ(a.ttl, b.ttl) << i;
    EXPECT_EQ(a.frame_count, b.frame_count) << i;
    EXPECT_EQ(one.entries[i].map, scenarios[i].map);
    EXPECT_GT(a.frame_count, 0);
    EXPECT_LE(a.flight_s, 10.0 + 1e-9);
  }
  // The summary counts what the entries say.
  const CampaignSummary& s = one.summary;
  EXPECT_EQ(s.scenarios, 2);
  int violations = 0, ii = 0;
  for (const auto& entry : one.entries) {
    const ScenarioOutcome& e = entry.outcome;
    violations += e.violation();
    ii += e.status == Violation::TypeII;
    EXPECT_EQ(e.violation(), e.status != Violation::None);
    EXPECT_EQ(e.ok(), !e.violation());
  }
  EXPECT_EQ(s.violations, violations);
  EXPECT_EQ(s.type_ii, ii);
  EXPECT_EQ(s.type_i + s.type_ii + s.type_iii, s.violations);
  EXPECT_DOUBLE_EQ(s.violation_rate(), violations / 2.0);
  EXPECT_GT(s.timing.total_s, 0);
}

// Issue 31 item 11: the progress callback drives the app's progress bar.
// It is called once per scenario, with done counting 1..total (in call
// order, whichever thread finishes), each index once, after that
// scenario's run (its `inspect` came first), with a finite ETA.
TEST(Campaign, ProgressCountsEachScenarioOnceUpToTheTotal) {
  const std::vector<Scenario> scenarios = three_short_scenarios();
  CampaignOptions o = small_camera_options();
  o.threads = 2;
  std::vector<touchdown::Progress> calls;
  std::mutex inspected_mutex;
  std::vector<int> inspected(scenarios.size(), 0);
  std::vector<int> inspected_before(scenarios.size(), -1);
  o.inspect = [&](std::size_t i, const ScenarioResult&) {
    const std::lock_guard lock(inspected_mutex);
    ++inspected[i];
  };
  o.progress = [&](const touchdown::Progress& p) {
    calls.push_back(p);
    const std::lock_guard lock(inspected_mutex);
    inspected_before[p.index] = inspected[p.index];
  };
  const CampaignResult r = run_campaign(scenarios, o);
  ASSERT_EQ(calls.size(), scenarios.size());
  ASSERT_EQ(r.entries.size(), scenarios.size());
  std::vector<int> seen(scenarios.size(), 0);
  for (std::size_t k = 0; k < calls.size(); ++k) {
    EXPECT_EQ(calls[k].done, k + 1);
    EXPECT_EQ(calls[k].total, scenarios.size());
    ASSERT_LT(calls[k].index, scenarios.size());
    ++seen[calls[k].index];
    EXPECT_GE(calls[k].eta_s, 0);
    if (k > 0) {
      EXPECT_GE(calls[k].elapsed_s, calls[k - 1].elapsed_s);
    }
  }
  EXPECT_DOUBLE_EQ(calls.back().eta_s, 0);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i], 1) << "scenario " << i;
    EXPECT_EQ(inspected_before[i], 1) << "scenario " << i << ": progress before its run ended";
  }
}

// Cancelled from its own progress callback after the first scenario, a
// campaign on one thread returns that scenario alone, the same as it is in
// the whole campaign.
TEST(Campaign, ACancelledCampaignReturnsTheScenariosThatRan) {
  const std::vector<Scenario> scenarios = three_short_scenarios();
  CampaignOptions o = small_camera_options();
  std::atomic<bool> cancel{false};
  o.cancel = &cancel;
  o.progress = [&](const touchdown::Progress&) { cancel = true; };
  const CampaignResult part = run_campaign(scenarios, o);
  ASSERT_EQ(part.entries.size(), 1u);
  EXPECT_EQ(part.summary.scenarios, 1);
  o.cancel = nullptr;
  o.progress = nullptr;
  const CampaignResult whole = run_campaign(scenarios, o);
  ASSERT_EQ(whole.entries.size(), 3u);
  EXPECT_EQ(part.entries[0].outcome.message, whole.entries[0].outcome.message);
  EXPECT_EQ(part.entries[0].outcome.frame_count, whole.entries[0].outcome.frame_count);
}

TEST(Campaign, RandomScenariosAreTheSeededOnes) {
  const std::vector<Scenario> lawn = random_scenarios(7, 3, MapKind::Lawn);
  ASSERT_EQ(lawn.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(lawn[i] == random_scenario(7 + i, MapKind::Lawn));
    EXPECT_EQ(lawn[i].map, MapKind::Lawn);
  }
  const std::vector<Scenario> any = random_scenarios(7, 2, std::nullopt);
  EXPECT_TRUE(any[1] == random_scenario(8));
  EXPECT_FALSE(any[0] == any[1]);
}

// The per-scenario controller drives each run's `external` objects (the
// same as handing it to run_scenario), and `inspect` sees each run's whole
// result once, for its own index.
TEST(Campaign, PerScenarioControllerAndInspectionAreThoseOfSingleRuns) {
  std::vector<Scenario> scenarios = campaign_short_scenarios();
  for (auto& s : scenarios) {
    DynamicObject dog;
    dog.kind = DynamicKind::Dog;
    dog.size = {0.8, 0.3, 0.6};
    dog.position = s.marker.position + Eigen::Vector2d(-3, 0);
    dog.speed = 2;
    dog.motion = MotionKind::External;
    s.dynamic_objects = {dog};
  }
  const auto controller_for = [](std::size_t index) {
    return [index](const World&, std::vector<ObjectAction>& actions) {
      for (auto& a : actions) a = index == 0 ? ObjectAction::Right : ObjectAction::Up;
    };
  };
  CampaignOptions o;
  o.run.camera.width = 320;
  o.run.camera.height = 240;
  o.threads = 2;
  o.external_for = controller_for;
  std::vector<int> seen(scenarios.size(), 0);
  std::vector<double> last_t(scenarios.size(), 0);
  std::vector<std::size_t> frames(scenarios.size(), 0);
  o.inspect = [&](std::size_t i, const ScenarioResult& r) {
    ++seen[i];
    frames[i] = r.frames.size();
    last_t[i] = r.trajectory.empty() ? 0.0 : r.trajectory.back().t;
  };
  const CampaignResult campaign = run_campaign(scenarios, o);
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    EXPECT_EQ(seen[i], 1) << i;
    RunOptions run = o.run;
    run.external = controller_for(i);
    auto system = o.system.make(o.mls);
    const ScenarioResult single = run_scenario(scenarios[i], *system, run);
    EXPECT_EQ(campaign.entries[i].outcome.message, single.message) << i;
    EXPECT_EQ(campaign.entries[i].outcome.final_position, single.final_position) << i;
    EXPECT_EQ(frames[i], single.frames.size()) << i;
    EXPECT_EQ(last_t[i], single.trajectory.back().t) << i;
    // The controller does move the dog.
    World w(scenarios[i]);
    std::vector<ObjectAction> actions(1);
    controller_for(i)(w, actions);
    w.step(DroneCommand{}, actions);
    EXPECT_NE(w.dynamic_poses()[0].translation().head<2>(), scenarios[i].dynamic_objects[0].position) << i;
  }
}

TEST(Campaign, RefusesBadOptionsBeforeRunning) {
  std::vector<Scenario> scenarios(2);
  CampaignOptions o;
  o.threads = -1;  // 0 is every core (core/batch.hpp)
  EXPECT_THROW(run_campaign(scenarios, o), InvalidArgument);
  o.threads = 1;
  o.run.on_frame = [](const CameraFrame&, const SystemOutput&, const DroneState&) {};
  EXPECT_THROW(run_campaign(scenarios, o), InvalidArgument);
  o.run.on_frame = nullptr;
  o.system = "no-such-system";
  EXPECT_THROW(run_campaign(scenarios, o), InvalidArgument);
  o.system = "opencv-mls";
  scenarios[1].time_limit = -1;
  try {
    run_campaign(scenarios, o);
    FAIL() << "an invalid scenario was run";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("scenario 1: time_limit"), std::string::npos) << e.what();
  }
}

TEST(DetectionRoi, SameLandingFewerDetectionsOfTheDistractor) {
  // The clear approach with a wrong-id marker 1.5 m from the target: both
  // stay in view from cruise altitude. Whole-frame detection reports both
  // in every frame; the tracking ROI reports the distractor only in the
  // periodic whole-frame passes, and lands exactly the same way (the ROI
  // gives the same target corners: no corner refinement, and the
  // thresholding is local).
  Scenario s = test::clear_scenario(40);
  s.seed = 11;
  s.distractors.push_back({DistractorKind::WrongId, 7, 1, 0.8, Eigen::Vector2d(0, 2.2), 20});
  MlsOptions roi, whole;
  whole.detector.roi = false;
  auto a = make_landing_system("opencv-mls", roi);
  auto b = make_landing_system("opencv-mls", whole);
  const ScenarioResult ra = run_scenario(s, *a);
  const ScenarioResult rb = run_scenario(s, *b);
  EXPECT_FALSE(ra.violation()) << ra.message;
  EXPECT_FALSE(rb.violation()) << rb.message;
  ASSERT_EQ(ra.trajectory.size(), rb.trajectory.size());
  for (std::size_t k = 0; k < ra.trajectory.size(); ++k) {
    ASSERT_EQ(ra.trajectory[k].position, rb.trajectory[k].position) << "step " << k;
  }
  ASSERT_EQ(ra.frames.size(), rb.frames.size());
  int both_whole = 0, both_roi = 0, tracked = 0;
  for (std::size_t k = 0; k < ra.frames.size(); ++k) {
    EXPECT_EQ(ra.frames[k].accepted, rb.frames[k].accepted) << "frame " << k;
    if (rb.frames[k].accepted == 0) continue;
    ++tracked;
    both_whole += rb.frames[k].detections >= 2;
    both_roi += ra.frames[k].detections >= 2;
  }
  ASSERT_GT(tracked, 50);
  EXPECT_GT(both_whole, tracked * 3 / 4);  // whole frame: the distractor is seen too
  EXPECT_LT(both_roi, tracked / 2);        // ROI: mostly the target alone
  EXPECT_GT(both_roi, 0);                  // but the periodic whole-frame pass sees it
}

}  // namespace
}  // namespace touchdown::scenario
