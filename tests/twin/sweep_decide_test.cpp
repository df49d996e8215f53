// Issue 57: the sweep's decision mode (SweepOptions::decide) gives the full
// sweep's decision, chosen heading and S of it, bit for bit, on terrains
// whose answer is known, for any thread count, flying fewer landings; the
// deadline mode settles nothing on a tiny deadline and says "do not land".
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/sweep.hpp"
#include "twin_test_util.hpp"

namespace td = touchdown;
namespace tw = touchdown::twin;

namespace {

using touchdown::kRadPerDeg;

tw::SweepOptions options(int headings, int runs, bool decide, int threads = 0) {
  tw::SweepOptions o;
  o.headings = headings;
  o.runs = runs;
  o.decide = decide;
  o.threads = threads;
  return o;
}

// The decision mode against the full sweep: the same decision, heading and
// S; every run it flew is the full sweep's run (same conditions, same
// result); the chosen heading complete; fewer landings or as many.
tw::SweepResult expect_same_decision(const std::shared_ptr<const tw::TerrainModel>& terrain, int headings, int runs,
                                     const std::string& what) {
  SCOPED_TRACE(what);
  const tw::SweepResult full = tw::run_sweep(tw::Airframe::f450(), terrain, options(headings, runs, false));
  tw::SweepResult last;
  for (const int threads : {1, 2}) {
    const tw::SweepResult d = tw::run_sweep(tw::Airframe::f450(), terrain, options(headings, runs, true, threads));
    EXPECT_TRUE(d.decided);
    EXPECT_EQ(d.safe, full.safe);
    EXPECT_EQ(d.best, full.best);
    if (full.best >= 0 && d.best == full.best) {
      const auto& a = d.headings[static_cast<std::size_t>(d.best)];
      const auto& b = full.headings[static_cast<std::size_t>(full.best)];
      EXPECT_EQ(a.score, b.score);  // bit for bit
      EXPECT_EQ(a.runs, runs);
      EXPECT_EQ(a.flown, tw::HeadingFlown::All);
    }
    EXPECT_LE(d.runs.size(), full.runs.size());
    for (const auto& r : d.runs) {
      const auto& f = full.runs[static_cast<std::size_t>(r.heading) * runs + static_cast<std::size_t>(r.run)];
      EXPECT_EQ(f.heading, r.heading);
      EXPECT_EQ(f.run, r.run);
      EXPECT_EQ(f.result.nutation, r.result.nutation);
      EXPECT_EQ(f.result.steps, r.result.steps);
    }
    // A heading the decision mode calls safe is safe in the full sweep.
    for (std::size_t j = 0; j < d.headings.size(); ++j) {
      if (d.headings[j].safe) {
        EXPECT_TRUE(full.headings[j].safe) << j;
      }
      if (d.headings[j].flown == tw::HeadingFlown::UntilUnsafe) {
        EXPECT_FALSE(full.headings[j].safe) << j;
      }
    }
    if (threads == 2) {
      // The same for any thread count, run by run.
      EXPECT_EQ(last.runs.size(), d.runs.size());
      for (std::size_t k = 0; k < std::min(d.runs.size(), last.runs.size()); ++k) {
        EXPECT_EQ(last.runs[k].result.nutation, d.runs[k].result.nutation);
      }
    }
    last = d;
  }
  return last;
}

}  // namespace

TEST(SweepDecision, FlatPadIsSafeWithTheFullSweepsHeadingAndScore) {
  const auto r = expect_same_decision(td::test::flat_terrain(0.0), 12, 6, "flat");
  EXPECT_TRUE(r.safe);
  EXPECT_LT(r.runs.size(), 12u * 6u);  // it pruned
}

TEST(SweepDecision, StepOnlyTheAlignedHeadingsClear) {
  // A 10 cm ledge 0.12 m from the landing point (sweep_test.cpp): only the
  // headings across it are safe.
  const auto step = td::test::analytic_terrain([](double x, double) { return x > -0.12 ? 0.1 : 0.0; }, 1.0, 0.01);
  const auto r = expect_same_decision(step, 8, 5, "ledge");
  EXPECT_TRUE(r.safe);
  EXPECT_LT(r.runs.size(), 8u * 5u);
  int unsafe = 0;
  for (const auto& h : r.headings) unsafe += h.flown == tw::HeadingFlown::UntilUnsafe ? 1 : 0;
  EXPECT_GT(unsafe, 0);  // the headings along the ledge stopped at their first bad run
}

TEST(SweepDecision, SlopeBeyondTheThresholdDoesNotLandAndReportsTheFullSweepsHeading) {
  // No heading safe: the full sweep reports the lowest S among the scored
  // headings; the decision mode finds the same one and its S.
  const auto r = expect_same_decision(td::test::incline_terrain(32 * kRadPerDeg), 6, 3, "incline 32");
  EXPECT_FALSE(r.safe);
  const auto m = expect_same_decision(td::test::incline_terrain(14 * kRadPerDeg), 6, 4, "incline 14");
  (void)m;
}

TEST(SweepDecision, ATinyDeadlineSettlesNothingAndSaysDoNotLand) {
  auto o = options(8, 5, true);
  o.deadline = 1e-9;
  const auto r = tw::run_sweep(tw::Airframe::f450(), td::test::flat_terrain(0.0), o);
  EXPECT_FALSE(r.decided);
  EXPECT_FALSE(r.safe);
  EXPECT_TRUE(r.runs.empty());
  for (const auto& h : r.headings) {
    EXPECT_EQ(h.flown, tw::HeadingFlown::UntilDeadline);
    EXPECT_FALSE(h.safe);
  }
  // A deadline long enough decides as the full sweep does.
  o.deadline = 600;
  const auto later = tw::run_sweep(tw::Airframe::f450(), td::test::flat_terrain(0.0), o);
  EXPECT_TRUE(later.decided);
  EXPECT_TRUE(later.safe);
}

TEST(SweepDecision, OptionsThatConflictAreRefused) {
  auto o = options(4, 2, false);
  o.deadline = 1;
  std::string why;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("decision mode"), std::string::npos) << why;
  o = options(4, 2, true);
  o.time_budget = 1;
  EXPECT_FALSE(o.validate(&why));
  o = options(4, 2, true);
  o.deadline = -1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_THROW(tw::run_sweep(tw::Airframe::f450(), td::test::flat_terrain(), o), td::InvalidArgument);
}
