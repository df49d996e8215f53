#pragma once
// A small landing system for the plug-in tests (system_registry_test.cpp):
// it ignores the camera, flies to the GPS target at 10 m, descends there
// and lands. The same source is built into a plug-in library and into the
// test program, so a campaign through the plug-in can be compared with the
// one built in, bit for bit. `throw_after` > 0 makes it throw from update()
// once the run passes that time (a faulty system under test).
#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <string_view>

#include "touchdown/scenario/landing_system.hpp"

namespace touchdown::test_plugin {

class GpsLander final : public scenario::LandingSystem {
 public:
  explicit GpsLander(std::string name, double throw_after = 0) : name_(std::move(name)), throw_after_(throw_after) {}
  [[nodiscard]] std::string_view name() const override { return name_; }
  void reset(const scenario::SystemSetup& setup) override {
    target_ = setup.gps_target;
    descending_ = false;
  }
  scenario::SystemOutput update(const scenario::SystemInput& input) override {
    const DroneState& s = input.state;
    if (throw_after_ > 0 && s.t > throw_after_) throw std::runtime_error("gps-lander: planted fault");
    scenario::SystemOutput out;
    Eigen::Vector2d v = target_ - s.position.head<2>();
    const double distance = v.norm();
    if (v.norm() > 3) v *= 3 / v.norm();
    double vz = std::clamp(10 - s.position.z(), -1.5, 1.5);
    if (!descending_ && distance < 0.3) {
      descending_ = true;
      out.descent_started = true;
      out.target = target_;
    }
    if (descending_) vz = -0.8;
    out.command.velocity_world = {v.x(), v.y(), vz};
    out.command.land = descending_ && s.position.z() < 1.5;
    out.phase = descending_ ? "descend" : "approach";
    return out;
  }

 private:
  std::string name_;
  double throw_after_;
  Eigen::Vector2d target_ = Eigen::Vector2d::Zero();
  bool descending_ = false;
};

}  // namespace touchdown::test_plugin
