#pragma once
/// \file
/// The contract of a landing system (touchdown/scenario/contract.hpp) as a
/// GoogleTest suite that runs against any system: the reference systems
/// (tests/scenario/landing_system_test.cpp instantiates it for every name
/// in landing_system_names()) and a user's own.
///
/// Use from a test program (GoogleTest, linking touchdown::scenario):
///
///   #include <touchdown/scenario/testing/landing_system_contract.hpp>
///   using touchdown::scenario::contract::LandingSystemContract;
///   namespace contract = touchdown::scenario::contract;
///   INSTANTIATE_TEST_SUITE_P(MySystem, LandingSystemContract,
///       ::testing::Values(contract::Factory{"my_system", [] { return std::make_unique<MySystem>(); }}),
///       contract::factory_label);
///
/// This is the one public header that needs GoogleTest (the library does
/// not: nothing in it includes this file). It defines the suite's tests, so
/// include it in one translation unit per test program.
#include <gtest/gtest.h>

#include <ostream>
#include <string>

#include "touchdown/scenario/contract.hpp"

namespace touchdown::scenario::contract {

/// A Verdict as GoogleTest's assertion result (its message kept).
inline ::testing::AssertionResult assertion(const Verdict& v) {
  if (v.ok) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << v.message;
}

/// GoogleTest prints a Factory by its label.
inline void PrintTo(const Factory& f, std::ostream* os) { *os << f.label; }

/// The test-name suffix of a Factory (INSTANTIATE_TEST_SUITE_P's last argument).
inline std::string factory_label(const ::testing::TestParamInfo<Factory>& info) {
  std::string s = info.param.label.empty() ? "system" : info.param.label;
  for (char& c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) c = '_';
  }
  return s;
}

/// The suite: instantiate it with one Factory per system (see the file comment).
class LandingSystemContract : public ::testing::TestWithParam<Factory> {};

TEST_P(LandingSystemContract, NameIsNonEmptyAndStable) { EXPECT_TRUE(assertion(check_name(GetParam()))); }
TEST_P(LandingSystemContract, AcceptsAStepWithoutAFrame) { EXPECT_TRUE(assertion(check_frameless(GetParam()))); }
TEST_P(LandingSystemContract, OutputsAreFiniteAndDetectionsComeWithFrames) {
  EXPECT_TRUE(assertion(check_outputs(GetParam())));
}
TEST_P(LandingSystemContract, SameSetupAndInputsGiveTheSameOutputs) {
  EXPECT_TRUE(assertion(check_deterministic(GetParam())));
}
TEST_P(LandingSystemContract, ResetStartsAFreshRun) { EXPECT_TRUE(assertion(check_reset(GetParam()))); }
TEST_P(LandingSystemContract, ObjectsShareNoState) { EXPECT_TRUE(assertion(check_independent(GetParam()))); }
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(LandingSystemContract);

}  // namespace touchdown::scenario::contract
