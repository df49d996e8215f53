// The DQN driving the world's external objects (object_policy.hpp): RLaGA
// paper eq. 3 (state) and eq. 4 (greedy action).
#include "touchdown/search/object_policy.hpp"

#include "touchdown/core/error.hpp"

namespace touchdown::search {

ObjectPolicy::ObjectPolicy(std::shared_ptr<const QNetwork> network, double decision_period)
    : network_(std::move(network)), period_(decision_period) {
  if (!network_) throw InvalidArgument("ObjectPolicy: no network");
  if (!(period_ > 0)) throw InvalidArgument("ObjectPolicy: decision_period must be > 0");
}

void ObjectPolicy::operator()(const scenario::World& world, std::vector<scenario::ObjectAction>& actions) {
  const double t = world.time();
  if (t < last_time_) held_.clear();  // a new run
  last_time_ = t;
  const bool decide = held_.size() != actions.size() || t >= next_decision_ - 1e-9;
  if (decide) {
    const scenario::Scenario& sc = world.scenario();
    const Eigen::Vector2d marker = sc.marker.position;
    const Eigen::Vector3d& drone = world.drone().position;
    const auto& poses = world.dynamic_poses();
    held_.assign(actions.size(), scenario::ObjectAction::Stay);
    std::size_t k = 0;
    for (std::size_t i = 0; i < sc.dynamic_objects.size() && k < held_.size(); ++i) {
      if (sc.dynamic_objects[i].motion != scenario::MotionKind::External) continue;
      const Eigen::Vector3d p = poses[i].translation();
      // eq. 3: (object − marker, drone − marker) in x, y.
      const DqnState s{p.x() - marker.x(), p.y() - marker.y(), drone.x() - marker.x(), drone.y() - marker.y()};
      held_[k++] = dqn_action(network_->greedy(s));  // eq. 4
    }
    next_decision_ = t + period_;
  }
  std::copy(held_.begin(), held_.end(), actions.begin());
}

}  // namespace touchdown::search
