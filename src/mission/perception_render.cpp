// The `render` perception (perception_render.hpp): pose_sim's renderer and
// the real LedTracker in the mission's loop.
#include "touchdown/mission/perception_render.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <utility>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::mission {
namespace {

// data/constellations/quad180_leds.yaml (a test checks that they agree).
constexpr const char* kQuad180Leds = R"(name: quad180_leds
leds:
  - {xyz: [0.060, 0.060, -0.012], color: red, normal: [1, 0, -1], half_angle_deg: 85}
  - {xyz: [0.060, -0.060, -0.012], color: red, normal: [1, 0, -1], half_angle_deg: 85}
  - {xyz: [-0.060, -0.060, -0.012], color: green, normal: [1, 0, -1], half_angle_deg: 85}
  - {xyz: [-0.060, 0.060, -0.012], color: green, normal: [1, 0, -1], half_angle_deg: 85}
  - {xyz: [0.050, -0.030, -0.048], color: blue, normal: [1, 0, -1], half_angle_deg: 85}
  - {xyz: [-0.050, 0.030, -0.048], color: white, normal: [1, 0, -1], half_angle_deg: 85}
)";

// A unit vector turned by a small random rotation of sigma [rad] per axis.
Eigen::Vector3d perturbed(const Eigen::Vector3d& g, double sigma, Rng& rng) {
  const Eigen::Vector3d w = normal_vector3(rng) * sigma;
  return (Eigen::AngleAxisd(w.norm(), w.norm() > 0 ? Eigen::Vector3d(w.normalized()) : Eigen::Vector3d::UnitZ()) * g)
      .normalized();
}

}  // namespace

pose::Constellation quad180_constellation() { return pose::parse_constellation(kQuad180Leds, "built-in quad180_leds"); }

pose::CameraModel d455_camera() {
  pose::CameraModel c;
  c.width = 1280;
  c.height = 720;
  c.fx = c.fy = 674.4;
  c.cx = 639.5;
  c.cy = 359.5;
  c.depth_scale = 0.001;
  return c;
}

pose::RenderOptions RenderPerceptionOptions::default_render() {
  pose::RenderOptions r;
  r.render_marker = false;
  r.body_half_size = 0.04;
  r.body_z_min = -0.0175;
  r.body_z_max = 0.0175;
  return r;
}

bool RenderPerceptionOptions::validate(std::string* why) const {
  std::string w;
  if (!camera.validate(&w)) return invalid(why, "perception.camera: " + w);
  if (!constellation.validate(&w)) return invalid(why, "perception.constellation: " + w);
  if (!tracker.validate(&w)) return invalid(why, "perception.tracker: " + w);
  if (!(attitude_sigma_deg > 0) || !std::isfinite(attitude_sigma_deg)) {
    return invalid(why, "perception.attitude_sigma_deg: must be positive [deg]");
  }
  return errors.validate(why);
}

bool CameraErrors::validate(std::string* why) const {
  const std::array<std::pair<const char*, double>, 7> values{{{"focal_sigma", focal_sigma},
                                                              {"principal_sigma_px", principal_sigma_px},
                                                              {"extrinsic_position_sigma", extrinsic_position_sigma},
                                                              {"extrinsic_angle_sigma_deg", extrinsic_angle_sigma_deg},
                                                              {"clock_offset_sigma", clock_offset_sigma},
                                                              {"clock_jitter_sigma", clock_jitter_sigma},
                                                              {"rolling_shutter_s", rolling_shutter_s}}};
  for (const auto& [key, v] : values) {
    if (!(v >= 0) || !std::isfinite(v)) {
      return invalid(why, std::string("perception.camera_errors.") + key + ": must be finite and >= 0");
    }
  }
  if (!(focal_sigma < 0.2)) return invalid(why, "perception.camera_errors.focal_sigma: must be below 0.2");
  if (!(frame_drop >= 0 && frame_drop < 1))
    return invalid(why, "perception.camera_errors.frame_drop: must be in [0, 1)");
  return true;
}

RenderPerception::RenderPerception(RenderPerceptionOptions options, const Eigen::Isometry3d& T_pad_camera,
                                   const Eigen::Vector3d& com_body, double rate_hz, double latency, std::uint64_t seed)
    : options_(std::move(options)),
      T_pad_camera_(T_pad_camera),
      com_body_(com_body),
      rate_hz_(rate_hz),
      latency_(latency),
      seed_(seed),
      rng_(seed, 1) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument(why);
  options_.render.frame_rate_hz = rate_hz_;
  options_.render.rolling_shutter_s = options_.errors.rolling_shutter_s;
  if (!options_.render.validate(&why)) throw InvalidArgument("perception.camera_errors: " + why);
  // The renderer sees the true camera; the tracker and the pad-frame
  // conversion use the calibration, drawn per mission from its own stream.
  const CameraErrors& err = options_.errors;
  Rng calibration(seed, 3);
  pose::CameraModel calibrated = options_.camera;
  calibrated.fx *= 1 + err.focal_sigma * calibration.normal();
  calibrated.fy *= 1 + err.focal_sigma * calibration.normal();
  calibrated.cx += err.principal_sigma_px * calibration.normal();
  calibrated.cy += err.principal_sigma_px * calibration.normal();
  const Eigen::Vector3d dp = err.extrinsic_position_sigma * normal_vector3(calibration);
  const Eigen::Vector3d dr = deg_to_rad(err.extrinsic_angle_sigma_deg) * normal_vector3(calibration);
  T_pad_camera_calibrated_ = T_pad_camera_;
  T_pad_camera_calibrated_.translation() += dp;
  if (dr.norm() > 0)
    T_pad_camera_calibrated_.linear() = T_pad_camera_.linear() * Eigen::AngleAxisd(dr.norm(), dr.normalized());
  clock_offset_ = err.clock_offset_sigma * calibration.normal();
  renderer_ = std::make_unique<pose::SyntheticCamera>(options_.camera, options_.constellation, options_.render);
  tracker_ = std::make_unique<pose::LedTracker>(calibrated, options_.constellation, options_.tracker);
}

RenderPerception::~RenderPerception() = default;

PoseMeasurement RenderPerception::capture(const PerceptionTruth& truth) {
  PoseMeasurement m;
  m.t_available = truth.t + latency_;
  const std::uint64_t frame = frame_++;
  // The frame's stamp on the camera's clock, and whether it arrives: a
  // stream of their own per frame, so that they shift no other draw.
  Rng timing(seed_ ^ 0x74696d696e67ULL /* "timing" */, frame);
  const double jitter = options_.errors.clock_jitter_sigma * timing.normal();
  m.t_capture = std::min(truth.t + clock_offset_ + jitter, m.t_available);
  const bool dropped = options_.errors.frame_drop > 0 && timing.uniform() < options_.errors.frame_drop;
  const Eigen::Isometry3d T_camera_body = T_pad_camera_.inverse() * truth.T_pad_body;
  const Eigen::Isometry3d previous = have_previous_ ? previous_ : T_camera_body;
  previous_ = T_camera_body;
  have_previous_ = true;
  // The IMUs' noise is drawn whatever happens, so that one frame's outcome
  // does not shift the next frames' draws.
  const double sigma = deg_to_rad(options_.attitude_sigma_deg);
  const Eigen::Vector3d g_camera =
      perturbed(T_pad_camera_.linear().transpose() * -Eigen::Vector3d::UnitZ(), sigma, rng_);
  const Eigen::Vector3d g_body = perturbed(truth.g_body, sigma, rng_);
  // Far beyond the tracker's reach (behind the camera or past 10 m): no
  // frame worth rendering; the track restarts when the drone comes back.
  const Eigen::Vector3d c = T_camera_body.translation();
  if (dropped) return m;  // the tracker keeps its track: the next frame may still follow it
  if (!(c.z() > 0.05) || c.norm() > 10) {
    tracker_->reset();
    return m;
  }
  const auto t0 = std::chrono::steady_clock::now();
  renderer_->render(T_camera_body, previous, seed_, frame, rendered_);
  const auto t1 = std::chrono::steady_clock::now();
  const BgrImageView colour = rendered_.colour.view();
  const DepthImageView depth = rendered_.depth.view();
  const pose::PoseEstimate& e = options_.attitude_prior
                                    ? tracker_->track(colour, &depth, pose::AttitudePrior{g_camera, g_body, sigma})
                                    : tracker_->track(colour, &depth);
  const auto t2 = std::chrono::steady_clock::now();
  render_s_ += std::chrono::duration<double>(t1 - t0).count();
  track_s_ += std::chrono::duration<double>(t2 - t1).count();
  if (e.ok()) {
    const Eigen::Isometry3d T_pad_body = T_pad_camera_calibrated_ * e.T_camera_body;
    m.ok = true;
    m.p_pad = T_pad_body * com_body_;
    m.sigma = e.sigma_position_m;
  }
  if (on_frame_) {
    PerceptionFrame f;
    f.t = truth.t;
    f.state = truth.state;
    f.colour = &rendered_.colour;
    f.estimate = &e;
    f.blobs = &tracker_->blobs();
    if (e.ok()) {
      for (const auto& led : options_.constellation.leds) {
        const Eigen::Vector3d p = e.T_camera_body * led.p_body;
        if (p.z() > 0) f.reprojected.push_back(options_.camera.project(p));
      }
    }
    on_frame_(f);
  }
  return m;
}

}  // namespace touchdown::mission
