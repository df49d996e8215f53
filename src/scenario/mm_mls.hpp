#pragma once
// The reference landing system mm-mls (landing_system.hpp), after the RLaGA
// paper's multi-module MM-MLS: opencv-mls (opencv_mls.hpp) plus a tracked
// marker with a code check, an obstacle map from the depth image
// (obstacle_grid.hpp), a free landing point near the marker and a descent
// planned and replanned around the mapped obstacles with touchdown::plan.
// Private to the scenario module.
//
// Thread-safety: one instance per thread; instances share nothing.
#include <cstdint>
#include <string_view>
#include <vector>

#include "scenario/obstacle_grid.hpp"
#include "scenario/opencv_mls.hpp"
#include "touchdown/plan/bezier.hpp"
#include "touchdown/plan/corridor.hpp"

namespace touchdown::scenario::detail {

class MmMls final : public OpencvMls {
 public:
  explicit MmMls(const MlsOptions& options) : OpencvMls(options, "mm-mls") {}

  void reset(const SystemSetup& setup) override;

 private:
  [[nodiscard]] bool gated(const DroneState& s) const override;
  bool reads_exactly(const cv::Mat& gray, const MarkerDetection& m, const Detection& d, bool gated) override;
  void see_depth(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera) override;
  void begin_descent(double t) override;
  void drop_descent() override;
  void descend(const DroneState& s, Eigen::Vector2d* v_xy, double* v_z) override;
  void land(const Eigen::Vector2d& p, bool seen_recently, Eigen::Vector2d* v_xy) override;
  void finish(const Eigen::Vector2d& p, double altitude, bool descended, Eigen::Vector2d* v_xy, double* v_z) override;
  [[nodiscard]] std::string_view descend_phase_name() const override { return mm_phase_; }

  void keep_clear(const Eigen::Vector2d& p, double altitude, Eigen::Vector2d* v_xy, double* v_z) const;
  bool choose_landing_point();
  Eigen::Vector3d planned_descent(const DroneState& s);
  [[nodiscard]] bool plan_blocked(double t) const;
  void replan(const DroneState& s);

  CodeReader reader_;
  ObstacleGrid map_;
  std::string_view mm_phase_ = "descend";
  bool have_landing_ = false;
  Eigen::Vector2d landing_ = Eigen::Vector2d::Zero();
  bool have_plan_ = false;
  plan::PiecewiseBezier trajectory_;
  Eigen::Vector3d c3_plan_ = Eigen::Vector3d::Zero();  // the plan's origin: its landing point on the ground
  double plan_t0_ = 0;
  double plan_duration_ = 0;
  double next_plan_try_ = 0;
  std::uint64_t plan_changes_ = 0;
  std::vector<plan::Box> boxes_;
};

}  // namespace touchdown::scenario::detail
