#pragma once
/// \file
/// The `render` perception: the vehicle's camera renders colour and depth
/// frames of the drone's LED constellation (pose_sim's SyntheticCamera, the
/// D455-like camera of data/cameras/d455_1280x720.yaml by default) and the
/// real LedTracker estimates the pose, with the attitude prior from both
/// IMUs (the camera's gravity direction and the drone's, each with noise).
/// The measurement is the drone's centre of mass in the pad frame, with the
/// tracker's σ. OpenCV stays behind pose_sim.
///
/// Thread-safety: one instance per mission. Deterministic: frames are drawn
/// from (seed, frame index).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "touchdown/core/image.hpp"
#include "touchdown/mission/perception.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

namespace touchdown::mission {

/// The built-in constellation of the 180 mm quadrotor (the LEDs of
/// data/constellations/quad180_leds.yaml) and the D455-like camera (the
/// numbers of data/cameras/d455_1280x720.yaml).
pose::Constellation quad180_constellation();
pose::CameraModel d455_camera();

/// One rendered frame, for a video.
struct PerceptionFrame {
  double t = 0;
  MissionState state = MissionState::Searching;
  const BgrImage* colour = nullptr;
  const pose::PoseEstimate* estimate = nullptr;
  const std::vector<pose::Blob>* blobs = nullptr;
  /// The constellation's LEDs projected at the estimated pose (when ok).
  std::vector<Eigen::Vector2d> reprojected;
};

/// A real camera's errors (issue 56 item 5), all 0 = the ideal camera.
/// Calibration errors are drawn once per mission: the renderer uses the
/// true camera, the tracker and the pad-frame conversion the calibrated
/// (wrong) one. Timing errors shift the frames' capture stamps against the
/// drone's clock; dropped frames never reach the ground station.
struct CameraErrors {
  double focal_sigma = 0;                ///< relative error of fx and fy (one draw each), per mission
  double principal_sigma_px = 0;         ///< of cx and cy [px], per mission
  double extrinsic_position_sigma = 0;   ///< of the camera's position on the pad, per axis [m], per mission
  double extrinsic_angle_sigma_deg = 0;  ///< of its orientation, per axis [deg], per mission
  double clock_offset_sigma = 0;         ///< the camera's clock against the drone's [s], per mission
  double clock_jitter_sigma = 0;         ///< of each frame's stamp [s]
  double frame_drop = 0;                 ///< probability a frame never arrives, [0, 1)
  double rolling_shutter_s = 0;          ///< readout from the first row to the last [s] (pose::RenderOptions)
  /// False (with "perception.camera_errors.key: what") for a negative or
  /// non-finite value.
  [[nodiscard]] bool validate(std::string* why) const;
};

struct RenderPerceptionOptions {
  pose::CameraModel camera = d455_camera();
  pose::Constellation constellation = quad180_constellation();
  pose::RenderOptions render = default_render();
  pose::TrackerOptions tracker{};
  bool attitude_prior = true;       ///< give the tracker both IMUs' gravity directions
  double attitude_sigma_deg = 1.0;  ///< each IMU's tilt noise, 1-σ per axis [deg], > 0
  CameraErrors errors;
  /// The renderer's options for the mission: no ArUco card, the 180 mm
  /// quadrotor's body (8 cm square) in the depth image.
  static pose::RenderOptions default_render();
  [[nodiscard]] bool validate(std::string* why) const;
};

class RenderPerception final : public Perception {
 public:
  /// `T_pad_camera`: the camera in the pad frame (OpenCV axes);
  /// `com_body`: the drone's centre of mass in its body frame; `latency`:
  /// capture → estimate [s]. Throws InvalidArgument for invalid options.
  RenderPerception(RenderPerceptionOptions options, const Eigen::Isometry3d& T_pad_camera,
                   const Eigen::Vector3d& com_body, double rate_hz, double latency, std::uint64_t seed);
  ~RenderPerception() override;
  PoseMeasurement capture(const PerceptionTruth& truth) override;
  [[nodiscard]] double rate_hz() const override { return rate_hz_; }
  /// Called with every rendered frame (a video writer); empty: none.
  void on_frame(std::function<void(const PerceptionFrame&)> callback) { on_frame_ = std::move(callback); }
  /// Time spent rendering and tracking so far [s] (wall clock).
  [[nodiscard]] double render_seconds() const { return render_s_; }
  [[nodiscard]] double track_seconds() const { return track_s_; }

 private:
  RenderPerceptionOptions options_;
  Eigen::Isometry3d T_pad_camera_;
  Eigen::Isometry3d T_pad_camera_calibrated_;  ///< what the ground station believes (errors drawn per mission)
  double clock_offset_ = 0;                    ///< [s], drawn per mission
  Eigen::Vector3d com_body_;
  double rate_hz_, latency_;
  std::uint64_t seed_;
  std::uint64_t frame_ = 0;
  std::unique_ptr<pose::SyntheticCamera> renderer_;
  std::unique_ptr<pose::LedTracker> tracker_;
  pose::RenderedFrame rendered_;
  Eigen::Isometry3d previous_ = Eigen::Isometry3d::Identity();
  bool have_previous_ = false;
  Rng rng_;
  std::function<void(const PerceptionFrame&)> on_frame_;
  double render_s_ = 0, track_s_ = 0;
};

}  // namespace touchdown::mission
