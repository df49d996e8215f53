// Shrinking a violating scenario to the genes its failure needs (shrink.hpp).
#include "touchdown/search/shrink.hpp"

#include <chrono>
#include <utility>

namespace touchdown::search {

namespace {

// One group of genes and how to reset it in a scenario.
struct Group {
  std::string name;
  std::function<void(scenario::Scenario&)> reset;
};

// A group per object: removals are marked first and applied by index from
// the back, so that every group names its object's index in the original.
struct Removals {
  std::vector<bool> statics, dynamics, distractors;
};

scenario::Scenario with_removals(scenario::Scenario s, const Removals& r) {
  const auto apply = [](auto& list, const std::vector<bool>& removed) {
    for (std::size_t i = list.size(); i-- > 0;) {
      if (removed[i]) list.erase(list.begin() + static_cast<std::ptrdiff_t>(i));
    }
  };
  apply(s.static_objects, r.statics);
  apply(s.dynamic_objects, r.dynamics);
  apply(s.distractors, r.distractors);
  return s;
}

std::vector<Group> weather_groups(const scenario::Scenario& s) {
  const scenario::Weather clear;
  std::vector<Group> out;
  const auto add = [&](const char* name, double scenario::Weather::*field) {
    if (s.weather.*field != clear.*field) {
      out.push_back(
          {std::string("weather.") + name, [field, clear](scenario::Scenario& x) { x.weather.*field = clear.*field; }});
    }
  };
  add("fog", &scenario::Weather::fog);
  add("rain", &scenario::Weather::rain);
  add("snow", &scenario::Weather::snow);
  add("dust", &scenario::Weather::dust);
  add("leaves", &scenario::Weather::leaves);
  add("ground_wetness", &scenario::Weather::ground_wetness);
  add("ground_snow", &scenario::Weather::ground_snow);
  add("ground_leaves", &scenario::Weather::ground_leaves);
  // The sun's position and the light level together: one lighting gene.
  if (s.weather.sun_elevation_deg != clear.sun_elevation_deg || s.weather.sun_azimuth_deg != clear.sun_azimuth_deg) {
    out.push_back({"weather.sun", [clear](scenario::Scenario& x) {
                     x.weather.sun_elevation_deg = clear.sun_elevation_deg;
                     x.weather.sun_azimuth_deg = clear.sun_azimuth_deg;
                   }});
  }
  add("ambient", &scenario::Weather::ambient);
  return out;
}

}  // namespace

ShrinkResult shrink(const scenario::Scenario& original, const scenario::Scenario& base, Evaluator& evaluator,
                    const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::string why;
  if (!original.validate(&why)) throw InvalidArgument("shrink: scenario: " + why);
  ShrinkResult result;
  const auto run = [&](const scenario::Scenario& s) { return evaluator.evaluate({s}, {}).front(); };

  // The object groups (removals), then weather, seed and marker (resets).
  Removals removed{std::vector<bool>(original.static_objects.size()),
                   std::vector<bool>(original.dynamic_objects.size()), std::vector<bool>(original.distractors.size())};
  struct Try {
    std::string name;
    std::vector<bool>* list = nullptr;  // a removal ...
    std::size_t index = 0;
    std::function<void(scenario::Scenario&)> reset;  // ... or a reset
  };
  std::vector<Try> tries;
  for (std::size_t i = 0; i < original.static_objects.size(); ++i) {
    tries.push_back({"static_objects[" + std::to_string(i) + "] (" +
                         std::string(scenario::to_string(original.static_objects[i].kind)) + ")",
                     &removed.statics,
                     i,
                     {}});
  }
  for (std::size_t i = 0; i < original.dynamic_objects.size(); ++i) {
    tries.push_back({"dynamic_objects[" + std::to_string(i) + "] (" +
                         std::string(scenario::to_string(original.dynamic_objects[i].kind)) + ")",
                     &removed.dynamics,
                     i,
                     {}});
  }
  for (std::size_t i = 0; i < original.distractors.size(); ++i) {
    tries.push_back({"distractors[" + std::to_string(i) + "] (" +
                         std::string(scenario::to_string(original.distractors[i].kind)) + ")",
                     &removed.distractors,
                     i,
                     {}});
  }
  for (Group& g : weather_groups(original)) tries.push_back({g.name, nullptr, 0, std::move(g.reset)});
  if (original.seed != base.seed) {
    tries.push_back({"seed", nullptr, 0, [seed = base.seed](scenario::Scenario& x) { x.seed = seed; }});
  }
  if (original.marker.position != base.marker.position) {
    tries.push_back(
        {"marker.position", nullptr, 0, [p = base.marker.position](scenario::Scenario& x) { x.marker.position = p; }});
  }
  const int total = 1 + static_cast<int>(tries.size());

  const Evaluation first = run(original);
  const auto report = [&](int done) {
    if (progress) {
      progress(progress_since(start, static_cast<std::size_t>(done), static_cast<std::size_t>(total),
                              static_cast<std::size_t>(done - 1)));
    }
  };
  report(1);
  result.violation = first.violation;
  result.message = first.message;
  result.smallest = original;
  if (!first.violation_found()) return result;
  result.status = ShrinkStatus::Shrunk;

  scenario::Scenario resets = original;  // the kept resets (objects still all present)
  for (const Try& t : tries) {
    scenario::Scenario candidate_resets = resets;
    if (t.list) {
      (*t.list)[t.index] = true;
    } else {
      t.reset(candidate_resets);
    }
    const scenario::Scenario candidate = with_removals(candidate_resets, removed);
    ShrinkStep step;
    step.gene = t.name;
    bool kept = false, tried = false;
    if (candidate.validate(&why)) {
      tried = true;  // a reset that makes the scenario invalid is not tried
      const Evaluation e = run(candidate);
      step.outcome = e.violation;
      step.message = e.message;
      kept = e.violation == result.violation;
    } else {
      step.message = "not tried: " + why;
    }
    step.kept = kept;
    step.tried = tried;
    if (kept) {
      resets = std::move(candidate_resets);
    } else {
      if (t.list) (*t.list)[t.index] = false;
      if (tried) result.necessary.push_back(t.name);
    }
    result.steps.push_back(std::move(step));
    report(result.runs());
  }
  result.smallest = with_removals(resets, removed);
  return result;
}

}  // namespace touchdown::search
