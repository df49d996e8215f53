#pragma once
// One comparison for "the same system by another route gives the same
// campaign, bit for bit" (a plug-in, a process, another thread count).
#include <gtest/gtest.h>

#include <cstddef>

#include "touchdown/scenario/campaign.hpp"

namespace touchdown::scenario::test {

/// Expects every entry's outcome of `a` to equal `b`'s exactly (status,
/// message, final position, descent target, flight time, DTL, TTL) and
/// returns how many of them landed, so that a caller can check the
/// comparison was not of runs that never flew to the marker.
inline int expect_same_outcomes(const CampaignResult& a, const CampaignResult& b) {
  EXPECT_EQ(a.entries.size(), b.entries.size());
  int landed = 0;
  for (std::size_t i = 0; i < a.entries.size() && i < b.entries.size(); ++i) {
    const ScenarioOutcome& x = a.entries[i].outcome;
    const ScenarioOutcome& y = b.entries[i].outcome;
    EXPECT_EQ(x.status, y.status) << i << ": " << x.message;
    EXPECT_EQ(x.message, y.message) << i;
    EXPECT_EQ(x.final_position, y.final_position) << i;
    EXPECT_EQ(x.descent_target, y.descent_target) << i;
    EXPECT_EQ(x.flight_s, y.flight_s) << i;
    EXPECT_EQ(x.dtl, y.dtl) << i;
    EXPECT_EQ(x.ttl, y.ttl) << i;
    landed += x.landed ? 1 : 0;
  }
  return landed;
}

}  // namespace touchdown::scenario::test
