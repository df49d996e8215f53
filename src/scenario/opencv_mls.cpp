// The reference landing system opencv-mls (opencv_mls.hpp).
#include "scenario/opencv_mls.hpp"

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <string>

#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario::detail {

namespace {

/// Ground point (z = 0) seen at pixel `uv`, or false when the ray misses it.
bool ground_point(const Eigen::Isometry3d& T_world_camera, const Eigen::Matrix3d& K_inv, const Eigen::Vector2d& uv,
                  Eigen::Vector2d* out) {
  const Eigen::Vector3d ray = T_world_camera.linear() * (K_inv * Eigen::Vector3d(uv.x(), uv.y(), 1.0));
  const Eigen::Vector3d o = T_world_camera.translation();
  if (ray.z() >= -1e-9) return false;
  const double s = -o.z() / ray.z();
  *out = (o + s * ray).head<2>();
  return true;
}

}  // namespace

OpencvMls::OpencvMls(const MlsOptions& options, std::string_view name)
    : options_(options), detector_(make_marker_detector(options.detector)), name_(name) {}

void OpencvMls::reset(const SystemSetup& setup) {
  std::string why;
  if (!setup.camera.validate(&why)) throw InvalidArgument("landing system: camera: " + why);
  if (!in_range(setup.drone_radius, 0.01, 5))
    throw InvalidArgument("landing system: drone_radius: must be in [0.01, 5] m");
  if (!pose::find_aruco_dictionary(setup.dictionary))
    throw InvalidArgument("landing system: dictionary: unknown " + setup.dictionary);
  setup_ = setup;
  detector_->reset(setup.dictionary, setup.marker_id);
  K_inv_ = setup.camera.K().inverse();
  T_body_camera_ = setup.camera.T_body_camera();
  tan_tilt_ = std::tan(deg_to_rad(setup.camera.tilt_deg));
  phase_ = Phase::Approach;
  have_estimate_ = false;
  track_exact_ = false;
  reacquired_ = false;
  seen_since_ = -1;
  last_seen_ = -1e9;
  search_angle_ = 0;
  last_t_ = -1;
}

SystemOutput OpencvMls::update(const SystemInput& in) {
  SystemOutput out;
  const DroneState& s = in.state;
  const double dt = in_dt(s);
  if (in.frame) detect(*in.frame, s, out);
  const double t = s.t;
  const bool seen_recently = t - last_seen_ <= options_.lost_timeout;
  if (!seen_recently) seen_since_ = -1;
  if (reacquired_) {
    // A descent on the marker it followed before is dropped: back to
    // tracking (at the cruise altitude) until the re-acquired marker has
    // been seen for seen_time. The land mode is committed.
    reacquired_ = false;
    if (phase_ == Phase::Descend) {
      phase_ = Phase::Track;
      drop_descent();
    }
  }

  const Eigen::Vector2d p = s.position.head<2>();
  Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
  double v_z = 0;
  const double altitude = s.position.z();
  const auto hold_altitude = [&](double z) {
    return std::clamp(options_.altitude_gain * (z - altitude), -options_.max_vertical_speed,
                      options_.max_vertical_speed);
  };
  bool descended = false;  // the descend step gave this step's setpoint

  switch (phase_) {
    case Phase::Approach: {
      // To the GPS target at cruise altitude; a sighting on the way takes over.
      const Eigen::Vector2d to = setup_.gps_target - p;
      v_xy = limit(to * options_.approach_gain, options_.approach_speed);
      v_z = hold_altitude(options_.cruise_altitude);
      if (have_estimate_) {
        phase_ = Phase::Track;
      } else if (to.norm() < options_.search_start_distance) {
        phase_ = Phase::Search;
        search_start_ = t;
      }
      break;
    }
    case Phase::Search: {
      // An expanding spiral about the GPS target until the marker is seen.
      if (have_estimate_) {
        phase_ = Phase::Track;
        break;
      }
      const double r = std::min(options_.search_radius, options_.search_growth * (t - search_start_));
      search_angle_ += options_.search_speed * (1.0 / std::max(options_.search_min_radius, r)) * dt;
      const Eigen::Vector2d goal =
          setup_.gps_target + r * Eigen::Vector2d(std::cos(search_angle_), std::sin(search_angle_));
      v_xy = limit((goal - p) * options_.approach_gain, options_.approach_speed);
      v_z = hold_altitude(options_.cruise_altitude);
      break;
    }
    case Phase::Track: {
      // Hover where the camera sees the estimate near the image centre
      // until it has been seen for seen_time.
      v_xy = limit((hover_point(estimate_, s) - p) * options_.centring_gain, options_.approach_speed);
      v_z = hold_altitude(options_.cruise_altitude);
      if (seen_since_ >= 0 && t - seen_since_ >= options_.seen_time) {
        phase_ = Phase::Descend;
        out.descent_started = true;
        out.target = estimate_;
        begin_descent(t);
      } else if (!seen_recently && t - last_seen_ > options_.track_lost_time) {
        phase_ = Phase::Search;  // lost it for good
        search_start_ = t;
        have_estimate_ = false;
      }
      break;
    }
    case Phase::Descend:
      descend(s, &v_xy, &v_z);
      descended = true;
      break;
    case Phase::Land:
      // Over the marker (mm-mls: over its free landing point).
      land(p, seen_recently, &v_xy);
      out.command.land = true;
      break;
  }
  finish(p, altitude, descended, &v_xy, &v_z);
  out.command.velocity_world = Eigen::Vector3d(v_xy.x(), v_xy.y(), v_z);
  out.phase = phase_name();
  return out;
}

bool OpencvMls::gated(const DroneState& /*s*/) const { return false; }

bool OpencvMls::reads_exactly(const cv::Mat& /*gray*/, const MarkerDetection& /*m*/, const Detection& /*d*/,
                              bool /*gated*/) {
  return false;
}

void OpencvMls::see_depth(const CameraFrame& /*f*/, const Eigen::Isometry3d& /*T_world_camera*/) {}

void OpencvMls::begin_descent(double /*t*/) {}

void OpencvMls::drop_descent() {}

void OpencvMls::descend(const DroneState& s, Eigen::Vector2d* v_xy, double* v_z) {
  const Eigen::Vector2d p = s.position.head<2>();
  *v_xy = limit((hover_point(estimate_, s) - p) * options_.centring_gain, options_.approach_speed);
  // Committed: re-centre while the marker is in sight, else keep
  // descending on the last estimate (PX4 precision landing's
  // opportunistic fallback: the marker often leaves the view or is
  // occluded near the ground).
  *v_z = -options_.descent_speed;
  if (s.position.z() < options_.land_altitude) phase_ = Phase::Land;
}

void OpencvMls::land(const Eigen::Vector2d& p, bool seen_recently, Eigen::Vector2d* v_xy) {
  if (seen_recently) *v_xy = limit((estimate_ - p) * options_.centring_gain, options_.land_speed);
}

void OpencvMls::finish(const Eigen::Vector2d& /*p*/, double /*altitude*/, bool /*descended*/, Eigen::Vector2d* /*v_xy*/,
                       double* /*v_z*/) {}

std::string_view OpencvMls::phase_name() const {
  return phase_ == Phase::Descend ? descend_phase_name() : to_string(phase_);
}

double OpencvMls::in_dt(const DroneState& s) {
  const double dt = last_t_ < 0 ? 0.0 : s.t - last_t_;
  last_t_ = s.t;
  return dt;
}

/// tan(tilt)·h behind `target` along the heading, h the height above the
/// land altitude, so that the offset shrinks on the way down and is zero
/// when the land mode takes over (then the marker is below the view
/// anyway). At nadir: the target itself.
Eigen::Vector2d OpencvMls::hover_point(const Eigen::Vector2d& target, const DroneState& s) const {
  if (tan_tilt_ == 0) return target;
  const double yaw = deg_to_rad(s.yaw_deg);
  const double back = tan_tilt_ * std::max(0.0, s.position.z() - options_.land_altitude);
  return target - back * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
}

void OpencvMls::detect(const CameraFrame& f, const DroneState& s, SystemOutput& out) {
  const cv::Mat bgr(f.height, f.width, CV_8UC3, const_cast<std::uint8_t*>(f.image.pixels.data()));
  cv::cvtColor(bgr, gray_, cv::COLOR_BGR2GRAY);
  const DetectorFrame frame{f.image.view(),
                            {gray_.data, gray_.cols, gray_.rows, static_cast<std::ptrdiff_t>(gray_.step)}};
  detector_->detect(frame, found_);
  const Eigen::Isometry3d T_world_camera = s.T_world_body() * T_body_camera_;
  int best = -1;
  std::size_t best_index = 0;
  bool best_exact = false, best_reacquires = false;
  // mm-mls follows the marker it tracks: while the track is alive, a
  // detection of the target id whose ground point is more than the gate
  // from the estimate is another marker (a look-alike the decoder's error
  // correction reads as the target) and is not a sighting. It also reads
  // each sighting's code itself: a track that never read exactly (it may
  // follow a look-alike seen first) gives way to an exact reading of the
  // target outside the gate — the re-acquisition. opencv-mls does neither.
  const bool is_gated = gated(s);
  for (std::size_t i = 0; i < found_.size(); ++i) {
    const MarkerDetection& m = found_[i];
    Detection d;
    d.id = m.id;
    d.confidence = m.confidence;
    if (m.has_corners) {
      d.corners = m.corners;
    } else {
      d.corners = {m.box_min, Eigen::Vector2d(m.box_max.x(), m.box_min.y()), m.box_max,
                   Eigen::Vector2d(m.box_min.x(), m.box_max.y())};
    }
    double perimeter = 0;
    for (int k = 0; k < 4; ++k)
      perimeter += (d.corners[static_cast<std::size_t>(k)] - d.corners[static_cast<std::size_t>((k + 1) % 4)]).norm();
    d.quality = perimeter / 4;  // mean side length [px]
    const Eigen::Vector2d centre = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
    const bool on_ground = ground_point(T_world_camera, K_inv_, centre, &d.ground);
    d.accepted = d.id == setup_.marker_id && d.quality >= options_.min_quality_px &&
                 d.confidence >= options_.min_confidence && on_ground;
    const bool exact = reads_exactly(gray_, m, d, is_gated);
    bool reacquires = false;
    if (is_gated && d.accepted && (d.ground - estimate_).norm() > options_.track_gate)
      d.accepted = reacquires = exact && !track_exact_;
    // Several accepted: the baseline follows the largest; mm-mls a
    // re-acquisition first, else while tracking the one nearest its
    // estimate, else an exact reading before a corrected one, then the
    // largest.
    const auto better = [&](const Detection& o) {
      if (reacquires != best_reacquires) return reacquires;
      if (is_gated && !reacquires) return (d.ground - estimate_).norm() < (o.ground - estimate_).norm();
      if (exact != best_exact) return exact;
      return d.quality > o.quality;
    };
    if (d.accepted && (best < 0 || better(out.detections[static_cast<std::size_t>(best)]))) {
      best = static_cast<int>(out.detections.size());
      best_index = i;
      best_exact = exact;
      best_reacquires = reacquires;
    }
    out.detections.push_back(d);
  }
  see_depth(f, T_world_camera);
  detector_->track(best < 0 ? nullptr : &found_[best_index]);
  if (best < 0) return;
  const Detection& d = out.detections[static_cast<std::size_t>(best)];
  const bool new_track = seen_since_ < 0 || s.t - last_seen_ > options_.lost_timeout;
  if (new_track || best_reacquires) seen_since_ = s.t;
  last_seen_ = s.t;
  const double w = options_.estimate_weight;
  estimate_ = have_estimate_ && !best_reacquires ? Eigen::Vector2d((1 - w) * estimate_ + w * d.ground) : d.ground;
  have_estimate_ = true;
  track_exact_ = (track_exact_ && !new_track) || best_exact;
  reacquired_ = reacquired_ || best_reacquires;
}

}  // namespace touchdown::scenario::detail
