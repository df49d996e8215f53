#pragma once
/// \file
/// The contract every LandingSystem keeps (landing_system.hpp), as a
/// GoogleTest suite that runs against any system: the two reference
/// systems (tests/scenario/landing_system_test.cpp instantiates it for every
/// name in landing_system_names()) and a user's own.
///
/// The clauses, each a test of the suite and a check function that returns
/// a ::testing::AssertionResult naming the first violation:
///   check_name         name() is non-empty and the same all through an
///                      object's life and across objects of one factory
///                      (and equal to Factory::expected_name when given);
///   check_frameless    a step without a camera frame (SystemInput::frame
///                      == nullptr), also as the very first step after
///                      reset(), is accepted: no exception, a valid output;
///   check_outputs      over a closed-loop run: commands and targets are
///                      finite, detections come only with a frame ("empty
///                      when no frame") and their corners, quality and
///                      ground points are finite;
///   check_deterministic  two fresh objects given the same setup and the
///                      same inputs give the same outputs, bit for bit;
///   check_reset        reset() starts a fresh run: on one object, a second
///                      run of a scenario repeats the first, and so does a
///                      run after a different one (a campaign reuses one
///                      object per worker thread);
///   check_independent  objects share no state: two objects stepped in
///                      turn on different scenarios give what each gives
///                      alone (a campaign runs one object per thread).
/// The runs are closed loop, driven as run_scenario() drives a system (the
/// world steps at the flight rate, frames arrive at the camera rate, the
/// system's command moves the drone), on the scenarios of a Script.
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

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/landing_system.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/testing/scenarios.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::scenario::contract {

/// The runs the contract drives a system through.
struct Script {
  Scenario scenario;         ///< the run every clause compares
  Scenario other;            ///< a different run: before `scenario` (reset), beside it (independence)
  RunOptions run;            ///< camera and flight (on_frame and external are not used)
  int frameless_steps = 25;  ///< steps without a frame in check_frameless
  /// Runs stop at the scenario's time limit, or after this long when it is
  /// shorter and positive (a scenario lasts at least 10 s) [s].
  double max_time = 0;
};

/// The clear scenario with a 1 m cube beside the marker, 35 s; the other
/// run: marker id 5 at (2, -3) and a 2 m box where the first run's marker
/// lies (seen on the way, so a map kept across reset() shows), 12 s.
inline Script default_script() {
  Script s;
  Scenario& a = s.scenario;
  a = clear_scenario(35);
  StaticObject cube;
  cube.kind = StaticKind::Box;
  cube.position = {1.0, 0.0};
  cube.size = {1, 1, 1};
  a.static_objects = {cube};
  Scenario& b = s.other;
  b = a;
  b.seed = 11;
  b.time_limit = 12;
  b.marker.id = 5;
  b.marker.position = {2, -3};
  StaticObject box;
  box.kind = StaticKind::Box;
  box.position = {0, 0};
  box.size = {1, 1, 2};
  b.static_objects = {box};
  return s;
}

/// How to make the system under test, and what to run it on.
struct Factory {
  using Make = std::function<std::unique_ptr<LandingSystem>()>;
  Factory() = default;
  Factory(std::string label_text, Make make_system, std::string expected = {})
      : label(std::move(label_text)), make(std::move(make_system)), expected_name(std::move(expected)) {}

  std::string label;  ///< names the instantiation in test names (other characters than [A-Za-z0-9_] become '_')
  Make make;
  std::string expected_name;  ///< when not empty, name() must equal it
  Script script = default_script();
};

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

/// One step of a run: what the system was given and what it answered.
struct StepRecord {
  double t = 0;
  bool frame = false;
  SystemOutput output;  ///< its phase is cleared (a view valid only until the next step)...
  std::string phase;    ///< ...and kept here
};
using Record = std::vector<StepRecord>;

/// One closed-loop run stepped from outside (ScenarioRun, as run_scenario()
/// steps it, so that two runs can advance in turn), recording every step.
class Lane {
 public:
  Lane(LandingSystem& system, const Scenario& scenario, const RunOptions& options, double max_time = 0)
      : run_(scenario, system, options, max_time) {}

  /// One step; false once the run is over (time limit, collision, landing).
  bool step() {
    if (!run_.step()) return false;
    StepRecord r;
    r.t = run_.last_input().state.t;
    r.frame = run_.last_input().frame != nullptr;
    r.output = run_.last_output();
    r.phase = std::string(r.output.phase);
    r.output.phase = {};
    record_.push_back(std::move(r));
    return true;
  }

  [[nodiscard]] const Record& record() const { return record_; }
  /// Why the system failed (ScenarioRun::failure(): it threw, or answered
  /// a non-finite command, and the run ended there); empty: it did not.
  [[nodiscard]] const std::string& failure() const { return run_.failure(); }

 private:
  ScenarioRun run_;
  Record record_;
};

/// A whole run of `scenario` on `system` (reset() included). A run the
/// system failed (ScenarioRun ends it at a throw or a non-finite command)
/// throws std::runtime_error with the reason, so that every clause fails
/// on it, naming the step.
inline Record run(LandingSystem& system, const Scenario& scenario, const RunOptions& options, double max_time = 0) {
  Lane lane(system, scenario, options, max_time);
  while (lane.step()) {
  }
  if (!lane.failure().empty()) throw std::runtime_error("the system failed: " + lane.failure());
  return lane.record();
}

namespace detail {

inline bool same_bits(const double* a, const double* b, std::size_t n) {
  return std::memcmp(a, b, n * sizeof(double)) == 0;
}

inline bool same_output(const SystemOutput& a, const SystemOutput& b) {
  if (!same_bits(a.command.velocity_world.data(), b.command.velocity_world.data(), 3) ||
      !same_bits(&a.command.yaw_rate_deg, &b.command.yaw_rate_deg, 1) || a.command.land != b.command.land ||
      a.descent_started != b.descent_started || !same_bits(a.target.data(), b.target.data(), 2) ||
      a.detections.size() != b.detections.size())
    return false;
  for (std::size_t i = 0; i < a.detections.size(); ++i) {
    const Detection &x = a.detections[i], &y = b.detections[i];
    if (x.id != y.id || x.accepted != y.accepted || !same_bits(&x.quality, &y.quality, 1) ||
        !same_bits(x.ground.data(), y.ground.data(), 2))
      return false;
    for (std::size_t k = 0; k < 4; ++k) {
      if (!same_bits(x.corners[k].data(), y.corners[k].data(), 2)) return false;
    }
  }
  return true;
}

inline std::string describe(const StepRecord& r) {
  std::ostringstream os;
  os.precision(17);
  const SystemOutput& o = r.output;
  os << "{t " << r.t << (r.frame ? ", frame" : ", no frame") << ", velocity (" << o.command.velocity_world.transpose()
     << "), yaw rate " << o.command.yaw_rate_deg << (o.command.land ? ", land" : "") << ", phase \"" << r.phase
     << "\", " << o.detections.size() << " detections" << (o.descent_started ? ", descent started" : "") << "}";
  return os.str();
}

/// "" when the records are equal bit for bit, else where they first differ.
inline std::string first_difference(const Record& a, const Record& b) {
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if (a[i].t != b[i].t || a[i].frame != b[i].frame || a[i].phase != b[i].phase ||
        !same_output(a[i].output, b[i].output))
      return "step " + std::to_string(i) + ": " + describe(a[i]) + " vs " + describe(b[i]);
  }
  if (a.size() != b.size()) return std::to_string(a.size()) + " steps vs " + std::to_string(b.size());
  return "";
}

template <typename Vector>
bool finite(const Vector& v) {
  return v.allFinite();
}

/// "" when the output keeps the clauses of check_outputs, else what it breaks.
inline std::string invalid_output(const SystemOutput& o, bool frame) {
  if (!finite(o.command.velocity_world) || !std::isfinite(o.command.yaw_rate_deg)) return "a non-finite command";
  if (o.descent_started && !finite(o.target)) return "a descent towards a non-finite target";
  if (!frame && !o.detections.empty()) return "detections without a frame";
  for (const Detection& d : o.detections) {
    for (const Eigen::Vector2d& c : d.corners) {
      if (!finite(c)) return "a detection with non-finite corners";
    }
    if (!std::isfinite(d.quality) || !finite(d.ground)) return "a detection with a non-finite quality or ground point";
  }
  return "";
}

/// Runs `body`, turning an exception into a failure that names `what`.
template <typename Body>
::testing::AssertionResult guarded(const char* what, Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    return ::testing::AssertionFailure() << what << ": threw " << e.what();
  } catch (...) {
    return ::testing::AssertionFailure() << what << ": threw a non-standard exception";
  }
}

}  // namespace detail

inline ::testing::AssertionResult check_name(const Factory& f) {
  return detail::guarded("name", [&]() -> ::testing::AssertionResult {
    const auto system = f.make();
    const std::string first(system->name());
    if (first.empty()) return ::testing::AssertionFailure() << "name() is empty";
    if (!f.expected_name.empty() && first != f.expected_name)
      return ::testing::AssertionFailure() << "name() is \"" << first << "\", made as \"" << f.expected_name << "\"";
    const auto same = [&](const char* when) -> ::testing::AssertionResult {
      if (system->name() == first) return ::testing::AssertionSuccess();
      return ::testing::AssertionFailure()
             << "name() was \"" << first << "\", " << when << " \"" << system->name() << "\"";
    };
    system->reset(system_setup(f.script.scenario, f.script.run));
    if (auto r = same("after reset()"); !r) return r;
    (void)run(*system, f.script.other, f.script.run, f.script.max_time);
    if (auto r = same("after a run"); !r) return r;
    const auto second = f.make();
    if (second->name() != first)
      return ::testing::AssertionFailure()
             << "two objects of one factory are named \"" << first << "\" and \"" << second->name() << "\"";
    return ::testing::AssertionSuccess();
  });
}

inline ::testing::AssertionResult check_frameless(const Factory& f) {
  return detail::guarded("a step without a frame", [&]() -> ::testing::AssertionResult {
    const auto system = f.make();
    system->reset(system_setup(f.script.scenario, f.script.run));
    SystemInput in;  // frame == nullptr
    in.state.position = f.script.scenario.drone.position;
    in.state.yaw_deg = f.script.scenario.drone.yaw_deg;
    const double dt = 1.0 / f.script.run.flight.rate_hz;
    for (int k = 0; k < f.script.frameless_steps; ++k) {
      in.state.t = k * dt;
      const SystemOutput out = system->update(in);
      if (const std::string bad = detail::invalid_output(out, false); !bad.empty())
        return ::testing::AssertionFailure() << "step " << k << " without a frame: " << bad;
    }
    return ::testing::AssertionSuccess();
  });
}

inline ::testing::AssertionResult check_outputs(const Factory& f) {
  return detail::guarded("a closed-loop run", [&]() -> ::testing::AssertionResult {
    const auto system = f.make();
    const Record r = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (const std::string bad = detail::invalid_output(r[i].output, r[i].frame); !bad.empty())
        return ::testing::AssertionFailure() << "step " << i << ": " << bad << " " << detail::describe(r[i]);
    }
    return ::testing::AssertionSuccess();
  });
}

inline ::testing::AssertionResult check_deterministic(const Factory& f) {
  return detail::guarded("two runs", [&]() -> ::testing::AssertionResult {
    const auto a = f.make(), b = f.make();
    const Record ra = run(*a, f.script.scenario, f.script.run, f.script.max_time);
    const Record rb = run(*b, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(ra, rb); !d.empty())
      return ::testing::AssertionFailure() << "two fresh objects, same setup and inputs, differ at " << d;
    return ::testing::AssertionSuccess();
  });
}

inline ::testing::AssertionResult check_reset(const Factory& f) {
  return detail::guarded("runs after reset()", [&]() -> ::testing::AssertionResult {
    const auto system = f.make();
    const Record first = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    const Record again = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(first, again); !d.empty())
      return ::testing::AssertionFailure() << "the second run of one object differs from its first at " << d;
    (void)run(*system, f.script.other, f.script.run, f.script.max_time);
    const Record after_other = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(first, after_other); !d.empty())
      return ::testing::AssertionFailure() << "after a different run, a run differs from the object's first at " << d;
    return ::testing::AssertionSuccess();
  });
}

inline ::testing::AssertionResult check_independent(const Factory& f) {
  return detail::guarded("two objects in turn", [&]() -> ::testing::AssertionResult {
    Record alone_a, alone_b;
    {
      const auto a = f.make();
      alone_a = run(*a, f.script.scenario, f.script.run, f.script.max_time);
      const auto b = f.make();
      alone_b = run(*b, f.script.other, f.script.run, f.script.max_time);
    }
    const auto a = f.make(), b = f.make();
    Lane lane_a(*a, f.script.scenario, f.script.run, f.script.max_time);
    Lane lane_b(*b, f.script.other, f.script.run, f.script.max_time);
    for (bool more_a = true, more_b = true; more_a || more_b;) {
      if (more_a) more_a = lane_a.step();
      if (more_b) more_b = lane_b.step();
    }
    for (const Lane* lane : {&lane_a, &lane_b}) {
      if (!lane->failure().empty())
        return ::testing::AssertionFailure() << "stepped in turn, the system failed: " << lane->failure();
    }
    if (const std::string d = detail::first_difference(alone_a, lane_a.record()); !d.empty())
      return ::testing::AssertionFailure()
             << "stepped in turn with another object, a run differs from its run alone at " << d;
    if (const std::string d = detail::first_difference(alone_b, lane_b.record()); !d.empty())
      return ::testing::AssertionFailure()
             << "stepped in turn with another object, the other run differs from its run alone at " << d;
    return ::testing::AssertionSuccess();
  });
}

/// The suite: instantiate it with one Factory per system (see the file comment).
class LandingSystemContract : public ::testing::TestWithParam<Factory> {};

TEST_P(LandingSystemContract, NameIsNonEmptyAndStable) { EXPECT_TRUE(check_name(GetParam())); }
TEST_P(LandingSystemContract, AcceptsAStepWithoutAFrame) { EXPECT_TRUE(check_frameless(GetParam())); }
TEST_P(LandingSystemContract, OutputsAreFiniteAndDetectionsComeWithFrames) { EXPECT_TRUE(check_outputs(GetParam())); }
TEST_P(LandingSystemContract, SameSetupAndInputsGiveTheSameOutputs) { EXPECT_TRUE(check_deterministic(GetParam())); }
TEST_P(LandingSystemContract, ResetStartsAFreshRun) { EXPECT_TRUE(check_reset(GetParam())); }
TEST_P(LandingSystemContract, ObjectsShareNoState) { EXPECT_TRUE(check_independent(GetParam())); }
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(LandingSystemContract);

}  // namespace touchdown::scenario::contract
