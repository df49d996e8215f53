#pragma once
/// \file
/// The contract every LandingSystem keeps (landing_system.hpp), as checks
/// that run against any system — built in, a plug-in or a process — with no
/// test framework: `landing_scenario contract --system SPEC` runs them from
/// the command line, and the GoogleTest suite of
/// touchdown/scenario/testing/landing_system_contract.hpp wraps the same
/// checks for a test program.
///
/// The clauses, each a check function that returns a Verdict naming the
/// first violation:
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
/// clauses() lists them with their names; run_contract() runs them all.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <exception>
#include <functional>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/landing_system.hpp"
#include "touchdown/scenario/run.hpp"
#include "touchdown/scenario/scenario.hpp"
#include "touchdown/scenario/testing/scenarios.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::scenario::contract {

/// A clause's verdict: ok, or what broke it (the first violation found,
/// with the step that shows it).
struct Verdict {
  bool ok = true;
  std::string message;  ///< empty when ok
  explicit operator bool() const { return ok; }
};

namespace detail {

/// Builds a failed Verdict from streamed text: `return Failure() << "step " << k;`.
class Failure {
 public:
  template <typename T>
  Failure& operator<<(const T& value) {
    text_ << value;
    return *this;
  }
  operator Verdict() const { return Verdict{false, text_.str()}; }  // NOLINT(google-explicit-constructor)

 private:
  std::ostringstream text_;
};

}  // namespace detail

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

/// The shortest text that reads back as `v` (two outputs that differ in the
/// last bit print differently).
inline std::string exact(double v) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), r.ptr);
}

inline std::string describe(const StepRecord& r) {
  std::ostringstream os;
  const SystemOutput& o = r.output;
  const Eigen::Vector3d& v = o.command.velocity_world;
  os << "{t " << exact(r.t) << (r.frame ? ", frame" : ", no frame") << ", velocity (" << exact(v.x()) << ", "
     << exact(v.y()) << ", " << exact(v.z()) << "), yaw rate " << exact(o.command.yaw_rate_deg)
     << (o.command.land ? ", land" : "") << ", phase \"" << r.phase << "\", " << o.detections.size() << " detections"
     << (o.descent_started ? ", descent started" : "") << "}";
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
Verdict guarded(const char* what, Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    return detail::Failure() << what << " threw: " << e.what();
  } catch (...) {
    return detail::Failure() << what << " threw a non-standard exception";
  }
}

}  // namespace detail

inline Verdict check_name(const Factory& f) {
  return detail::guarded("name", [&]() -> Verdict {
    const auto system = f.make();
    const std::string first(system->name());
    if (first.empty()) return detail::Failure() << "name() is empty";
    if (!f.expected_name.empty() && first != f.expected_name)
      return detail::Failure() << "name() is \"" << first << "\", made as \"" << f.expected_name << "\"";
    const auto same = [&](const char* when) -> Verdict {
      if (system->name() == first) return Verdict{};
      return detail::Failure() << "name() was \"" << first << "\", " << when << " \"" << system->name() << "\"";
    };
    system->reset(system_setup(f.script.scenario, f.script.run));
    if (auto r = same("after reset()"); !r) return r;
    (void)run(*system, f.script.other, f.script.run, f.script.max_time);
    if (auto r = same("after a run"); !r) return r;
    const auto second = f.make();
    if (second->name() != first)
      return detail::Failure() << "two objects of one factory are named \"" << first << "\" and \"" << second->name()
                               << "\"";
    return Verdict{};
  });
}

inline Verdict check_frameless(const Factory& f) {
  return detail::guarded("a step without a frame", [&]() -> Verdict {
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
        return detail::Failure() << "step " << k << " without a frame: " << bad;
    }
    return Verdict{};
  });
}

inline Verdict check_outputs(const Factory& f) {
  return detail::guarded("a closed-loop run", [&]() -> Verdict {
    const auto system = f.make();
    const Record r = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    for (std::size_t i = 0; i < r.size(); ++i) {
      if (const std::string bad = detail::invalid_output(r[i].output, r[i].frame); !bad.empty())
        return detail::Failure() << "step " << i << ": " << bad << " " << detail::describe(r[i]);
    }
    return Verdict{};
  });
}

inline Verdict check_deterministic(const Factory& f) {
  return detail::guarded("two runs", [&]() -> Verdict {
    const auto a = f.make(), b = f.make();
    const Record ra = run(*a, f.script.scenario, f.script.run, f.script.max_time);
    const Record rb = run(*b, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(ra, rb); !d.empty())
      return detail::Failure() << "two fresh objects, same setup and inputs, differ at " << d;
    return Verdict{};
  });
}

inline Verdict check_reset(const Factory& f) {
  return detail::guarded("runs after reset()", [&]() -> Verdict {
    const auto system = f.make();
    const Record first = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    const Record again = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(first, again); !d.empty())
      return detail::Failure() << "the second run of one object differs from its first at " << d;
    (void)run(*system, f.script.other, f.script.run, f.script.max_time);
    const Record after_other = run(*system, f.script.scenario, f.script.run, f.script.max_time);
    if (const std::string d = detail::first_difference(first, after_other); !d.empty())
      return detail::Failure() << "after a different run, a run differs from the object's first at " << d;
    return Verdict{};
  });
}

inline Verdict check_independent(const Factory& f) {
  return detail::guarded("two objects in turn", [&]() -> Verdict {
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
        return detail::Failure() << "stepped in turn, the system failed: " << lane->failure();
    }
    if (const std::string d = detail::first_difference(alone_a, lane_a.record()); !d.empty())
      return detail::Failure() << "stepped in turn with another object, a run differs from its run alone at " << d;
    if (const std::string d = detail::first_difference(alone_b, lane_b.record()); !d.empty())
      return detail::Failure() << "stepped in turn with another object, the other run differs from its run alone at "
                               << d;
    return Verdict{};
  });
}

/// One clause of the contract: its name, what it promises (one line) and
/// its check.
struct Clause {
  std::string_view name;
  std::string_view promise;
  Verdict (*check)(const Factory&);
};

/// Every clause, in the order run_contract() runs them.
inline const std::array<Clause, 6>& clauses() {
  static const std::array<Clause, 6> kAll{{
      {"name", "name() is non-empty and never changes", &check_name},
      {"frameless", "a step without a camera frame is accepted, also the first after reset()", &check_frameless},
      {"outputs", "finite commands and targets; detections only with a frame", &check_outputs},
      {"deterministic", "two fresh objects, same setup and inputs: the same outputs, bit for bit",
       &check_deterministic},
      {"reset", "reset() starts a fresh run: nothing of an earlier run carries over", &check_reset},
      {"independent", "objects share no state: two stepped in turn give what each gives alone", &check_independent},
  }};
  return kAll;
}

struct ClauseResult {
  const Clause* clause = nullptr;
  Verdict verdict;
  double seconds = 0;  ///< wall time of the check
};

/// Runs every clause on `f`, in order; `on_clause` (may be empty) is called
/// after each, for progress.
inline std::vector<ClauseResult> run_contract(const Factory& f,
                                              const std::function<void(const ClauseResult&)>& on_clause = {}) {
  std::vector<ClauseResult> out;
  for (const Clause& c : clauses()) {
    const auto t0 = std::chrono::steady_clock::now();
    ClauseResult r{&c, c.check(f), 0};
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (on_clause) on_clause(r);
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace touchdown::scenario::contract
