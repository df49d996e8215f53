// Faults of the system under test are results, not crashes (issue 55): a
// system that throws from reset() or update(), or answers a non-finite
// command, ends its run with status SystemFailed, the reason and the step;
// a campaign goes on.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "plugins/gps_lander.hpp"
#include "touchdown/scenario/campaign.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/testing/scenarios.hpp"

namespace touchdown::scenario {
namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Answers a NaN velocity from `bad_after` seconds on, or throws a non-std
// exception from reset() when asked to.
class Garbage final : public LandingSystem {
 public:
  explicit Garbage(double bad_after, bool throw_in_reset = false)
      : bad_after_(bad_after), throw_in_reset_(throw_in_reset) {}
  [[nodiscard]] std::string_view name() const override { return "garbage"; }
  void reset(const SystemSetup&) override {
    if (throw_in_reset_) throw 42;  // NOLINT(hicpp-exception-baseclass): a fault a foreign system may have
  }
  SystemOutput update(const SystemInput& in) override {
    SystemOutput out;
    out.command.velocity_world = {0, 0, 0.5};
    if (in.state.t >= bad_after_) out.command.velocity_world.x() = std::numeric_limits<double>::quiet_NaN();
    return out;
  }

 private:
  double bad_after_;
  bool throw_in_reset_;
};

TEST(SystemFault, AThrowingUpdateEndsTheRunAsSystemFailedWithTheStep) {
  test_plugin::GpsLander faulty("faulty", 3.0);
  const ScenarioResult r = run_scenario(contract::clear_scenario(30), faulty, {});
  EXPECT_EQ(r.status, Violation::SystemFailed);
  EXPECT_FALSE(r.violation());
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.landed);
  EXPECT_TRUE(has(r.failure, "update() threw at t = 3.0")) << r.failure;
  EXPECT_TRUE(has(r.failure, "(step 151)")) << r.failure;  // 50 Hz steps: t = 3.00 s is the 151st
  EXPECT_TRUE(has(r.failure, ": gps-lander: planted fault")) << r.failure;
  EXPECT_EQ(r.message, "system failed: " + r.failure);
  // The run stopped there: nothing flown after the fault.
  ASSERT_FALSE(r.trajectory.empty());
  EXPECT_LE(r.trajectory.back().t, 3.02);
  // The same lander without the fault flies on and lands.
  test_plugin::GpsLander sound("sound");
  const ScenarioResult ok = run_scenario(contract::clear_scenario(30), sound, {});
  EXPECT_TRUE(ok.landed) << ok.message;
  EXPECT_NE(ok.status, Violation::SystemFailed);
  EXPECT_TRUE(ok.failure.empty());
}

TEST(SystemFault, ANonFiniteCommandIsNeverFlown) {
  Garbage nan_after_2s(2.0);
  const ScenarioResult r = run_scenario(contract::clear_scenario(20), nan_after_2s, {});
  EXPECT_EQ(r.status, Violation::SystemFailed);
  EXPECT_TRUE(has(r.failure, "update() answered a non-finite command (velocity setpoint) at t = 2.0")) << r.failure;
  for (const TrajectorySample& s : r.trajectory) ASSERT_TRUE(s.position.allFinite()) << s.t;
  EXPECT_TRUE(r.final_position.allFinite());
}

TEST(SystemFault, AThrowingResetFailsBeforeTheFirstStep) {
  Garbage throws_in_reset(100, true);
  const Scenario scenario = contract::clear_scenario(20);  // a ScenarioRun holds a reference to it
  ScenarioRun run(scenario, throws_in_reset, {});
  EXPECT_TRUE(run.over());
  EXPECT_FALSE(run.step());
  EXPECT_EQ(run.failure(), "reset() threw (not a std::exception)");
  const ScenarioResult r = run.finish();
  EXPECT_EQ(r.status, Violation::SystemFailed);
  EXPECT_TRUE(r.trajectory.empty());
}

TEST(SystemFault, ACampaignGoesOnAndCountsTheFailuresApart) {
  std::vector<Scenario> scenarios = random_scenarios(3, 3, MapKind::Ground);
  for (Scenario& s : scenarios) s.time_limit = 20;
  CampaignOptions o;
  o.threads = 2;
  o.system = SystemFactory("faulty",
                           [](const MlsOptions&) { return std::make_unique<test_plugin::GpsLander>("faulty", 1.0); });
  const CampaignResult c = run_campaign(scenarios, o);
  ASSERT_EQ(c.entries.size(), 3U);
  EXPECT_EQ(c.summary.system_failed, 3);
  EXPECT_EQ(c.summary.violations, 0);
  for (const CampaignEntry& e : c.entries) EXPECT_EQ(e.outcome.status, Violation::SystemFailed) << e.outcome.message;
  EXPECT_EQ(to_string(Violation::SystemFailed), "system-failed");
  EXPECT_EQ(from_string<Violation>("system-failed"), Violation::SystemFailed);
}

}  // namespace
}  // namespace touchdown::scenario
