// The reference landing systems under test (landing_system.hpp), after the
// RLaGA paper's OpenCV-MLS (the industry baseline: ArUco detection with
// OpenCV's default detector parameters, approach, a continuous-sighting
// gate before descending, re-centring on the way down, PX4 land mode for
// the last metres) and MM-MLS (the same with obstacle avoidance from the
// depth image).
#include "touchdown/scenario/landing_system.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "pose/aruco_dictionary.hpp"
#include "scenario/marker_detector.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::scenario {

namespace {

bool in_range(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

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

Eigen::Vector2d limit(const Eigen::Vector2d& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Eigen::Vector2d(v * (max_norm / n)) : v;
}

/// OpenCV-MLS and, with `avoid_obstacles`, MM-MLS.
class MarkerLandingSystem final : public LandingSystem {
 public:
  MarkerLandingSystem(const MlsOptions& options, bool avoid_obstacles) : options_(options), avoid_(avoid_obstacles) {}

  std::string_view name() const override { return avoid_ ? "mm-mls" : "opencv-mls"; }

  void reset(const SystemSetup& setup) override {
    std::string why;
    if (!setup.camera.validate(&why)) throw InvalidArgument("landing system: camera: " + why);
    const auto* dict = pose::detail::find_aruco_dictionary(setup.dictionary);
    if (!dict) throw InvalidArgument("landing system: dictionary: unknown " + setup.dictionary);
    setup_ = setup;
    detector_.emplace(cv::aruco::getPredefinedDictionary(dict->id), options_.detection_roi);
    K_inv_ = setup.camera.K().inverse();
    T_body_camera_ = setup.camera.T_body_camera();
    phase_ = Phase::approach;
    have_estimate_ = false;
    seen_since_ = -1;
    last_seen_ = -1e9;
    search_angle_ = 0;
    last_t_ = -1;
    obstacle_points_.clear();
  }

  SystemOutput update(const SystemInput& in) override {
    SystemOutput out;
    const DroneState& s = in.state;
    const double dt = in_dt(s);
    if (in.frame) detect(*in.frame, s, out);
    const double t = s.t;
    const bool seen_recently = t - last_seen_ <= options_.lost_timeout;
    if (!seen_recently) seen_since_ = -1;

    const Eigen::Vector2d p = s.position.head<2>();
    Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
    double v_z = 0;
    const double altitude = s.position.z();
    const auto hold_altitude = [&](double z) { return std::clamp(1.0 * (z - altitude), -1.5, 1.5); };

    switch (phase_) {
      case Phase::approach: {
        // To the GPS target at cruise altitude; a sighting on the way takes over.
        const Eigen::Vector2d to = setup_.gps_target - p;
        v_xy = limit(to * 1.0, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        if (have_estimate_) {
          phase_ = Phase::track;
        } else if (to.norm() < 1.0) {
          phase_ = Phase::search;
          search_start_ = t;
        }
        break;
      }
      case Phase::search: {
        // An expanding spiral about the GPS target until the marker is seen.
        if (have_estimate_) {
          phase_ = Phase::track;
          break;
        }
        const double r = std::min(options_.search_radius, 0.25 * (t - search_start_));
        search_angle_ += 0.4 * (1.0 / std::max(1.0, r)) * dt;
        const Eigen::Vector2d goal =
            setup_.gps_target + r * Eigen::Vector2d(std::cos(search_angle_), std::sin(search_angle_));
        v_xy = limit((goal - p) * 1.0, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        break;
      }
      case Phase::track: {
        // Hover over the estimate until it has been seen for seen_time.
        v_xy = limit((estimate_ - p) * options_.centring_gain, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        if (seen_since_ >= 0 && t - seen_since_ >= options_.seen_time) {
          phase_ = Phase::descend;
          out.descent_started = true;
          out.target = estimate_;
        } else if (!seen_recently && t - last_seen_ > 5.0) {
          phase_ = Phase::search;  // lost it for good
          search_start_ = t;
          have_estimate_ = false;
        }
        break;
      }
      case Phase::descend: {
        v_xy = limit((estimate_ - p) * options_.centring_gain, options_.approach_speed);
        // Committed: re-centre while the marker is in sight, else keep
        // descending on the last estimate (PX4 precision landing's
        // opportunistic fallback: the marker often leaves the view or is
        // occluded near the ground).
        v_z = -options_.descent_speed;
        if (avoid_ && obstacle_below(p, altitude)) v_z = std::max(v_z, 0.5);
        if (altitude < options_.land_altitude) phase_ = Phase::land;
        break;
      }
      case Phase::land: {
        if (seen_recently) v_xy = limit((estimate_ - p) * options_.centring_gain, 0.5);
        out.command.land = true;
        break;
      }
    }
    if (avoid_ && phase_ != Phase::land) v_xy = avoid(p, altitude, v_xy, &v_z);
    out.command.velocity_world = Eigen::Vector3d(v_xy.x(), v_xy.y(), v_z);
    out.phase = phase_name();
    return out;
  }

 private:
  enum class Phase { approach, search, track, descend, land };

  std::string_view phase_name() const {
    switch (phase_) {
      case Phase::approach:
        return "approach";
      case Phase::search:
        return "search";
      case Phase::track:
        return "track";
      case Phase::descend:
        return "descend";
      case Phase::land:
        return "land";
    }
    return "";
  }

  double in_dt(const DroneState& s) {
    const double dt = last_t_ < 0 ? 0.0 : s.t - last_t_;
    last_t_ = s.t;
    return dt;
  }

  void detect(const CameraFrame& f, const DroneState& s, SystemOutput& out) {
    const cv::Mat bgr(f.height, f.width, CV_8UC3, const_cast<std::uint8_t*>(f.image.pixels.data()));
    cv::cvtColor(bgr, gray_, cv::COLOR_BGR2GRAY);
    detector_->detect(gray_, setup_.marker_id, corners_, ids_);
    const Eigen::Isometry3d T_world_camera = s.T_world_body() * T_body_camera_;
    int best = -1;
    std::size_t best_index = 0;
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      Detection d;
      d.id = ids_[i];
      double perimeter = 0;
      for (int k = 0; k < 4; ++k) {
        d.corners[static_cast<std::size_t>(k)] =
            Eigen::Vector2d(corners_[i][static_cast<std::size_t>(k)].x, corners_[i][static_cast<std::size_t>(k)].y);
      }
      for (int k = 0; k < 4; ++k)
        perimeter += (d.corners[static_cast<std::size_t>(k)] - d.corners[static_cast<std::size_t>((k + 1) % 4)]).norm();
      d.quality = perimeter / 4;  // mean side length [px]
      const Eigen::Vector2d centre = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
      const bool on_ground = ground_point(T_world_camera, K_inv_, centre, &d.ground);
      d.accepted = d.id == setup_.marker_id && d.quality >= options_.min_quality_px && on_ground;
      // Several accepted: the baseline follows the largest.
      if (d.accepted && (best < 0 || d.quality > out.detections[static_cast<std::size_t>(best)].quality)) {
        best = static_cast<int>(out.detections.size());
        best_index = i;
      }
      out.detections.push_back(d);
    }
    if (avoid_) map_obstacles(f, T_world_camera);
    detector_->track(best < 0 ? nullptr : &corners_[best_index]);
    if (best < 0) return;
    const Detection& d = out.detections[static_cast<std::size_t>(best)];
    if (seen_since_ < 0 || s.t - last_seen_ > options_.lost_timeout) seen_since_ = s.t;
    last_seen_ = s.t;
    estimate_ = have_estimate_ ? Eigen::Vector2d(0.5 * estimate_ + 0.5 * d.ground) : d.ground;
    have_estimate_ = true;
  }

  // MM-MLS: obstacles are depth pixels clearly above the ground plane, kept
  // as world points with their height (every 8th pixel; the latest frame).
  void map_obstacles(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera) {
    obstacle_points_.clear();
    const Eigen::Matrix3d R = T_world_camera.linear();
    const Eigen::Vector3d o = T_world_camera.translation();
    for (int y = 0; y < f.height; y += 8) {
      for (int x = 0; x < f.width; x += 8) {
        const float z =
            f.depth[static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) + static_cast<std::size_t>(x)];
        if (!std::isfinite(z)) continue;
        const Eigen::Vector3d p = o + R * (K_inv_ * Eigen::Vector3d(x, y, 1.0) * static_cast<double>(z));
        if (p.z() > 0.3) obstacle_points_.push_back(p);
      }
    }
  }

  bool obstacle_below(const Eigen::Vector2d& p, double altitude) const {
    for (const auto& q : obstacle_points_) {
      if ((q.head<2>() - p).norm() < options_.obstacle_clearance && q.z() > altitude - options_.obstacle_clearance)
        return true;
    }
    return false;
  }

  // Repulsion from obstacle points within the clearance, horizontally, and
  // a climb when one is close below.
  Eigen::Vector2d avoid(const Eigen::Vector2d& p, double altitude, const Eigen::Vector2d& v, double* v_z) const {
    Eigen::Vector2d push = Eigen::Vector2d::Zero();
    for (const auto& q : obstacle_points_) {
      if (q.z() < altitude - options_.obstacle_clearance) continue;
      const Eigen::Vector2d d = p - q.head<2>();
      const double n = d.norm();
      if (n < options_.obstacle_clearance && n > 1e-6) push += d / n * (options_.obstacle_clearance - n);
    }
    if (push.norm() > 0) *v_z = std::max(*v_z, 0.0);
    return limit(v + 2.0 * push, options_.approach_speed);
  }

  MlsOptions options_;
  bool avoid_;
  SystemSetup setup_;
  std::optional<detail::MarkerDetector> detector_;
  Eigen::Matrix3d K_inv_ = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d T_body_camera_ = Eigen::Isometry3d::Identity();
  Phase phase_ = Phase::approach;
  Eigen::Vector2d estimate_ = Eigen::Vector2d::Zero();
  bool have_estimate_ = false;
  double seen_since_ = -1;
  double last_seen_ = -1e9;
  double search_start_ = 0;
  double search_angle_ = 0;
  double last_t_ = -1;
  cv::Mat gray_;
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<int> ids_;
  std::vector<Eigen::Vector3d> obstacle_points_;
};

}  // namespace

bool MlsOptions::validate(std::string* why) const {
  if (!in_range(cruise_altitude, 2, 100)) return invalid(why, "cruise_altitude: must be in [2, 100] m");
  if (!in_range(approach_speed, 0.1, 20)) return invalid(why, "approach_speed: must be in [0.1, 20] m/s");
  if (!in_range(seen_time, 0, 60)) return invalid(why, "seen_time: must be in [0, 60] s");
  if (!in_range(min_quality_px, 0, 10000)) return invalid(why, "min_quality_px: must be in [0, 10000] px");
  if (!in_range(lost_timeout, 0, 60)) return invalid(why, "lost_timeout: must be in [0, 60] s");
  if (!in_range(descent_speed, 0.05, 10)) return invalid(why, "descent_speed: must be in [0.05, 10] m/s");
  if (!in_range(land_altitude, 0, 20)) return invalid(why, "land_altitude: must be in [0, 20] m");
  if (!in_range(centring_gain, 0.01, 10)) return invalid(why, "centring_gain: must be in [0.01, 10] 1/s");
  if (!in_range(search_radius, 0, 100)) return invalid(why, "search_radius: must be in [0, 100] m");
  if (!in_range(obstacle_clearance, 0, 20)) return invalid(why, "obstacle_clearance: must be in [0, 20] m");
  return true;
}

std::unique_ptr<LandingSystem> make_landing_system(std::string_view name, const MlsOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("landing system options: " + why);
  if (name == "opencv-mls") return std::make_unique<MarkerLandingSystem>(options, false);
  if (name == "mm-mls") return std::make_unique<MarkerLandingSystem>(options, true);
  throw InvalidArgument("landing system: unknown '" + std::string(name) + "' (known: opencv-mls, mm-mls)");
}

std::vector<std::string> landing_system_names() { return {"opencv-mls", "mm-mls"}; }

}  // namespace touchdown::scenario
