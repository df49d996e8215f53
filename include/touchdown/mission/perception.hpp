#pragma once
/// \file
/// Perception in the mission's loop: the vehicle's camera watches the
/// drone's LED constellation and reports the drone's position relative to
/// the pad. A plug-in interface (the mission calls capture() once per camera
/// frame with the truth, the perception answers what the ground station
/// would have measured) and `model`: measurements with range-dependent
/// noise, a per-mission bias, latency, drop-outs and the camera's field of
/// view and range, fitted to what `led_pose` achieves on the independent
/// renderer's sequences (docs/benchmarks.md, "Landing mission" → "The
/// perception model's fit").
///
/// A user's own perception runs the contract tests in
/// tests/mission/perception_contract.hpp. Thread-safety: one instance per
/// mission; deterministic given its Rng.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "touchdown/core/random.hpp"
#include "touchdown/mission/state_machine.hpp"
#include "touchdown/plan/corridor.hpp"

namespace touchdown::mission {

/// One camera frame's answer.
struct PoseMeasurement {
  double t_capture = 0;    ///< exposure time [s]
  double t_available = 0;  ///< when the ground station has it (t_capture + processing latency) [s]
  bool ok = false;         ///< a pose was found
  /// The drone's centre of mass relative to the pad (pad frame) [m].
  Eigen::Vector3d p_pad = Eigen::Vector3d::Zero();
  double sigma = 0;  ///< its 1-σ per axis [m], as the tracker reports it
};

/// What the mission gives the perception at each camera frame.
struct PerceptionTruth {
  double t = 0;
  Eigen::Isometry3d T_pad_body = Eigen::Isometry3d::Identity();  ///< the drone's body frame in the pad frame
  Eigen::Vector3d p_pad_com = Eigen::Vector3d::Zero();           ///< its centre of mass, pad frame
  /// The drone's gravity direction in its body frame from its IMU (unit,
  /// down), for trackers that take an attitude prior: as the ground station
  /// has it, link.latency old (the render perception adds the IMU's noise).
  Eigen::Vector3d g_body = -Eigen::Vector3d::UnitZ();
  MissionState state = MissionState::Searching;  ///< for overlays (a video)
};

class Perception {
 public:
  virtual ~Perception() = default;
  /// The measurement of the frame exposed at truth.t.
  virtual PoseMeasurement capture(const PerceptionTruth& truth) = 0;
  /// Frames per second.
  [[nodiscard]] virtual double rate_hz() const = 0;
};

struct PerceptionModelOptions {
  double rate_hz = 30;    ///< camera frames per second, > 0
  double latency = 0.04;  ///< capture → estimate at the ground station [s], ≥ 0
  /// Per-axis σ of the position: sigma_a + sigma_b · r² at range r from the
  /// camera [m], [m/m²] (a depth-camera-and-LED error grows with r²). The
  /// defaults are the fit to led_pose (attitude prior) on the independent
  /// renderer's sequences (tests/bench/mission_perception_fit.py).
  double sigma_a = 0.0004;
  double sigma_b = 0.0003;
  double bias_sigma = 0.0003;  ///< per-mission constant bias, σ per axis [m]
  /// Probability that a visible frame has no pose: dropout + dropout_b · r²,
  /// below 1.
  double dropout = 0.0;
  double dropout_b = 0.0069;  ///< [1/m²]
  double min_range = 0.3;     ///< [m] closer: no pose (the LEDs blur and leave the image)
  double max_range = 4.0;     ///< [m] farther: no pose
  /// The camera (pad frame) and its field of view; the drone's centre must
  /// be inside, shrunk by `fov_margin` [m].
  plan::CameraFov camera;
  double fov_margin = 0.05;
  /// False (with "perception.key: problem" in *why) for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The `model` perception.
class PerceptionModel final : public Perception {
 public:
  /// Throws InvalidArgument for invalid options.
  PerceptionModel(PerceptionModelOptions options, std::uint64_t seed);
  PoseMeasurement capture(const PerceptionTruth& truth) override;
  [[nodiscard]] double rate_hz() const override { return options_.rate_hz; }
  /// Whether the camera can see a pad-frame point (field of view and range).
  [[nodiscard]] bool visible(const Eigen::Vector3d& p_pad) const;

 private:
  PerceptionModelOptions options_;
  plan::Polytope fov_;
  Rng rng_;
  Eigen::Vector3d bias_;
};

}  // namespace touchdown::mission
