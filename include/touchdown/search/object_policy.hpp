#pragma once
/// \file
/// The trained DQN in the full landing world: drives every dynamic object
/// with motion `external` (RunOptions::external) by the same network, as the
/// RLaGA source does (one policy for all objects).
#include <memory>
#include <vector>

#include "touchdown/scenario/world.hpp"
#include "touchdown/search/dqn.hpp"

namespace touchdown::search {

/// Drives every External dynamic object of a run with the same network (the
/// source: one policy for all objects): eq. 3 state from the world (the
/// object's position from World::dynamic_poses() minus the marker's, the
/// drone's minus the marker's), greedy action (eq. 4), decided every
/// `decision_period` s and held in between (the first call decides). One per
/// run (keeps per-run state; a world whose time went back, i.e. a new run,
/// starts over); the network is shared read-only. Use as
/// `RunOptions::external = ObjectPolicy(net)`.
class ObjectPolicy {
 public:
  /// Throws InvalidArgument for a null network or decision_period ≤ 0.
  explicit ObjectPolicy(std::shared_ptr<const QNetwork> network, double decision_period = 0.1);
  /// Fills one action per External object (in the scenario's order).
  void operator()(const scenario::World& world, std::vector<scenario::ObjectAction>& actions);

  [[nodiscard]] double decision_period() const { return period_; }

 private:
  std::shared_ptr<const QNetwork> network_;
  double period_;
  double next_decision_ = 0;
  double last_time_ = -1;
  std::vector<scenario::ObjectAction> held_;
};

}  // namespace touchdown::search
