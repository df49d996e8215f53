#pragma once
// The reference landing system opencv-mls (landing_system.hpp), after the
// RLaGA paper's OpenCV-MLS: the industry baseline of ArUco detection with
// OpenCV's default detector parameters, approach, a continuous-sighting
// gate before descending, re-centring on the way down, PX4 land mode for
// the last metres. mm-mls (mm_mls.hpp) extends it: the steps it changes are
// the protected virtual hooks below, each of whose defaults is opencv-mls's
// own step. Private to the scenario module.
//
// Thread-safety: one instance per thread; instances share nothing.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <opencv2/core.hpp>
#include <string_view>
#include <vector>

#include "core/checks.hpp"
#include "scenario/aruco_detector.hpp"
#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/landing_system.hpp"
#include "touchdown/scenario/marker_detector.hpp"

namespace touchdown::scenario::detail {

using touchdown::detail::in_range;

/// `v` shortened to at most `max_norm`.
inline Eigen::Vector2d limit(const Eigen::Vector2d& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Eigen::Vector2d(v * (max_norm / n)) : v;
}

/// The phases of both reference systems, as SystemOutput::phase and the run
/// logs name them (mm-mls names its descent's steps itself).
enum class MlsPhase { Approach, Search, Track, Descend, Land };

}  // namespace touchdown::scenario::detail

template <>
struct touchdown::EnumNames<touchdown::scenario::detail::MlsPhase> {
  static constexpr std::array<std::string_view, 5> names{"approach", "search", "track", "descend", "land"};
};

namespace touchdown::scenario::detail {

inline std::string_view to_string(MlsPhase phase) { return enum_name(phase); }

class OpencvMls : public LandingSystem {
 public:
  /// `name`: "opencv-mls", or "learned-mls" for the same system on the
  /// learned detector. Builds options.detector (throws for a missing model).
  OpencvMls(const MlsOptions& options, std::string_view name);

  [[nodiscard]] std::string_view name() const override { return name_; }
  void reset(const SystemSetup& setup) override;
  SystemOutput update(const SystemInput& input) override;

 protected:
  using Phase = MlsPhase;

  // ---- the steps mm-mls overrides (defaults: opencv-mls) ----

  /// Whether detections of the target id far from the tracked estimate are
  /// look-alikes (mm-mls's track gate). opencv-mls: never.
  [[nodiscard]] virtual bool gated(const DroneState& s) const;
  /// Whether an accepted detection reads the target's code exactly (no
  /// cell corrected). opencv-mls does not read codes: false.
  virtual bool reads_exactly(const cv::Mat& gray, const MarkerDetection& m, const Detection& d, bool gated);
  /// Every frame after its detections (mm-mls maps the depth image).
  virtual void see_depth(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera);
  /// The descent was committed at time t / abandoned for a re-acquired
  /// marker (mm-mls forgets its landing point and plan).
  virtual void begin_descent(double t);
  virtual void drop_descent();
  /// The descend phase's velocity setpoint (may move on to the land phase):
  /// re-centre over the estimate and descend at descent_speed.
  virtual void descend(const DroneState& s, Eigen::Vector2d* v_xy, double* v_z);
  /// The land phase's horizontal setpoint: over the marker while it is in
  /// sight, else none.
  virtual void land(const Eigen::Vector2d& p, bool seen_recently, Eigen::Vector2d* v_xy);
  /// A last say on the step's setpoint; `descended` when descend() gave it.
  virtual void finish(const Eigen::Vector2d& p, double altitude, bool descended, Eigen::Vector2d* v_xy, double* v_z);
  [[nodiscard]] virtual std::string_view descend_phase_name() const { return to_string(Phase::Descend); }

  // ---- shared by both ----

  /// Where to hold the drone so that a forward-tilted camera sees `target`
  /// near the image centre (landing_system.hpp).
  [[nodiscard]] Eigen::Vector2d hover_point(const Eigen::Vector2d& target, const DroneState& s) const;

  MlsOptions options_;
  SystemSetup setup_;
  std::unique_ptr<MarkerDetector> detector_;
  Eigen::Matrix3d K_inv_ = Eigen::Matrix3d::Identity();
  Phase phase_ = Phase::Approach;
  Eigen::Vector2d estimate_ = Eigen::Vector2d::Zero();
  bool have_estimate_ = false;
  bool track_exact_ = false;  // the track has read the target's code exactly (mm-mls)
  double last_seen_ = -1e9;

 private:
  [[nodiscard]] std::string_view phase_name() const;
  double in_dt(const DroneState& s);
  void detect(const CameraFrame& f, const DroneState& s, SystemOutput& out);

  Eigen::Isometry3d T_body_camera_ = Eigen::Isometry3d::Identity();
  double tan_tilt_ = 0;
  bool reacquired_ = false;  // it moved to an exact reading outside the gate (mm-mls)
  double seen_since_ = -1;
  double search_start_ = 0;
  double search_angle_ = 0;
  double last_t_ = -1;
  std::string_view name_;
  cv::Mat gray_;
  std::vector<MarkerDetection> found_;
};

}  // namespace touchdown::scenario::detail
