// The ground vehicle (vehicle.hpp): skid-steer kinematics, pure pursuit and
// a rate-limited speed controller.
#include "touchdown/mission/vehicle.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/checks.hpp"
#include "touchdown/core/error.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::positive;

constexpr double kPi = std::numbers::pi;

double wrap_pi(double a) { return std::remainder(a, 2 * kPi); }

constexpr double kRoadStep = 0.1;   // [m] between the road table's points
constexpr double kClothoid = 20.0;  // [m] a bend's curvature ramps in and out over this

// One stretch of the road: curvature linear from k0 to k1 along it, or a
// lane change of `lane` metres (sideways offset lane/2 (1 - cos(π u / L)),
// so curvature lane/2 (π/L)² cos(π u / L)).
struct RoadPiece {
  double length, k0, k1, lane;
  [[nodiscard]] double curvature(double u) const {
    if (lane != 0) return 0.5 * lane * (kPi / length) * (kPi / length) * std::cos(kPi * u / length);
    return k0 + (k1 - k0) * u / length;
  }
};

std::vector<RoadPiece> road_pieces(const VehicleOptions& o) {
  const double S = o.road_straight, k = 1 / o.radius, arc = 0.5 * kPi * o.radius - kClothoid;
  const auto bend = [&](double sign, std::vector<RoadPiece>& out) {
    out.push_back({kClothoid, 0, sign * k, 0});
    out.push_back({arc, sign * k, sign * k, 0});
    out.push_back({kClothoid, sign * k, 0, 0});
  };
  std::vector<RoadPiece> p{{S, 0, 0, 0}, {o.lane_change_length, 0, 0, o.lane_width}, {0.5 * S, 0, 0, 0}};
  bend(1, p);
  p.push_back({S, 0, 0, 0});
  p.push_back({o.lane_change_length, 0, 0, -o.lane_width});
  p.push_back({0.5 * S, 0, 0, 0});
  bend(-1, p);
  return p;
}

// The road table's point at arc length s (periodic, each period shifted by
// where the one before ended), linear between its points: x, y, curvature.
std::array<double, 3> road_at(const std::vector<std::array<double, 5>>& road, const Eigen::Vector2d& shift, double s) {
  const double period = road.back()[0];
  const double turns = std::floor(s / period), u = s - turns * period;
  const auto it =
      std::upper_bound(road.begin(), road.end(), u, [](double v, const std::array<double, 5>& r) { return v < r[0]; });
  const std::size_t i =
      std::min<std::size_t>(static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - road.begin(), 1)), road.size() - 1) -
      1;
  const auto &a = road[i], &b = road[i + 1];
  const double f = (u - a[0]) / (b[0] - a[0]);
  return {a[1] + f * (b[1] - a[1]) + turns * shift.x(), a[2] + f * (b[2] - a[2]) + turns * shift.y(),
          a[4] + f * (b[4] - a[4])};
}

}  // namespace

bool VehicleOptions::validate(std::string* why) const {
  if (path == VehiclePath::Log) {
    if (!log) return invalid(why, "vehicle.log: path log needs a log (a CSV file)");
    if (!pad_position.allFinite() || !(pad_position.z() > 0)) {
      return invalid(why, "vehicle.pad_position: must be finite with z (height above the ground) > 0");
    }
    return true;
  }
  if (!positive(speed)) return invalid(why, "vehicle.speed: must be positive [m/s]");
  if (!positive(radius)) return invalid(why, "vehicle.radius: must be positive [m]");
  if (!positive(max_acceleration)) return invalid(why, "vehicle.max_acceleration: must be positive [m/s^2]");
  if (!positive(max_wheel_speed)) return invalid(why, "vehicle.max_wheel_speed: must be positive [m/s]");
  if (!positive(track_width)) return invalid(why, "vehicle.track_width: must be positive [m]");
  if (!(radius > track_width)) return invalid(why, "vehicle.radius: must exceed the track width");
  if (!positive(drive_time_constant)) return invalid(why, "vehicle.drive_time_constant: must be positive [s]");
  if (!positive(lookahead)) return invalid(why, "vehicle.lookahead: must be positive [m]");
  if (model == VehicleModel::Bicycle) {
    if (!positive(wheelbase)) return invalid(why, "vehicle.wheelbase: must be positive [m]");
    if (!(max_steer > 0 && max_steer < 1.4)) return invalid(why, "vehicle.max_steer_deg: must be in (0, 80) [deg]");
    if (!positive(max_steer_rate)) return invalid(why, "vehicle.max_steer_rate_deg: must be positive [deg/s]");
    const double tightest = wheelbase / std::tan(max_steer);
    if (path != VehiclePath::Line && radius < tightest) {
      return invalid(why, "vehicle.radius: tighter than the car turns (wheelbase / tan(max_steer) = " +
                              std::to_string(tightest) + " m)");
    }
  }
  if (path == VehiclePath::Road) {
    if (!positive(road_straight)) return invalid(why, "vehicle.road_straight: must be positive [m]");
    if (!(lane_width >= 0) || !std::isfinite(lane_width)) return invalid(why, "vehicle.lane_width: must be >= 0 [m]");
    if (!positive(lane_change_length) || lane_change_length < 4 * lane_width) {
      return invalid(why, "vehicle.lane_change_length: must be positive and at least 4 lane widths [m]");
    }
    if (!(0.5 * kPi * radius > 2 * kClothoid)) {
      return invalid(why, "vehicle.radius: a road's 90-degree bend needs a radius above 25.5 m (its 20 m clothoids)");
    }
  }
  if (!(random_speed_sigma >= 0) || !std::isfinite(random_speed_sigma)) {
    return invalid(why, "vehicle.random_speed_sigma: must be >= 0 [m/s]");
  }
  if (!positive(random_change_time)) return invalid(why, "vehicle.random_change_time: must be positive [s]");
  if (!pad_position.allFinite() || !(pad_position.z() > 0)) {
    return invalid(why, "vehicle.pad_position: must be finite with z (height above the ground) > 0");
  }
  // The outer track on the tightest turn at full speed (a car has no tracks).
  const double top = speed + (path == VehiclePath::Random ? 2 * random_speed_sigma : 0.0);
  const double outer = path == VehiclePath::Line ? top : top * (1 + 0.5 * track_width / radius);
  if (model == VehicleModel::SkidSteer && outer > max_wheel_speed) {
    return invalid(why, "vehicle.speed: the outer track would need " + std::to_string(outer) +
                            " m/s on this path, above max_wheel_speed");
  }
  return true;
}

Eigen::Vector2d VehicleState::world_acceleration() const {
  const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw)), left(-std::sin(yaw), std::cos(yaw));
  return acceleration * forward + speed * yaw_rate * left;
}

Eigen::Isometry3d VehicleState::T_world_vehicle() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(position.x(), position.y(), 0);
  return T;
}

GroundVehicle::GroundVehicle(const VehicleOptions& options, std::uint64_t seed) : options_(options), rng_(seed) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument(why);
  random_speed_ = options_.speed;
  if (options_.path == VehiclePath::Road) {
    // One period of the road, its heading and position integrated at the
    // midpoint of every step.
    double x = 0, y = 0, heading = 0, arc = 0;
    for (const RoadPiece& p : road_pieces(options_)) {
      const int n = std::max(1, static_cast<int>(std::lround(p.length / kRoadStep)));
      const double ds = p.length / n;
      for (int i = 0; i < n; ++i) {
        road_.push_back({arc + i * ds, x, y, heading, p.curvature(i * ds)});
        const double mid = heading + 0.5 * ds * p.curvature((i + 0.5) * ds);
        x += ds * std::cos(mid);
        y += ds * std::sin(mid);
        heading += ds * p.curvature((i + 0.5) * ds);
      }
      arc += p.length;
    }
    road_.push_back({arc, x, y, heading, 0});
    road_shift_ = {x, y};
  }
  if (options_.path == VehiclePath::Log) {
    replay();
  } else if (options_.start_at_speed) {
    const double v = options_.speed, k = path_curvature(0);
    state_.speed = speed_command_ = v;
    state_.yaw_rate = k * v;
    state_.wheel_left = v * (1 - 0.5 * k * options_.track_width);
    state_.wheel_right = v * (1 + 0.5 * k * options_.track_width);
    if (options_.model == VehicleModel::Bicycle) {
      steer_ = std::atan(k * options_.wheelbase);
      state_.wheel_left = state_.wheel_right = v;
    }
  }
}

Eigen::Vector2d GroundVehicle::path_point(double s) const {
  const double R = options_.radius, sense = options_.counter_clockwise ? 1.0 : -1.0;
  switch (options_.path) {
    case VehiclePath::Line:
      return {s, 0};
    case VehiclePath::Circle:
      return {R * std::sin(s / R), sense * R * (1 - std::cos(s / R))};
    case VehiclePath::FigureEight: {
      // Two circles tangent at the origin, the first lobe left of +x.
      const double lobe = 2 * kPi * R;
      const double u = std::fmod(std::fmod(s, 2 * lobe) + 2 * lobe, 2 * lobe);
      const double side = u < lobe ? sense : -sense;
      const double a = (u < lobe ? u : u - lobe) / R;
      return {R * std::sin(a), side * R * (1 - std::cos(a))};
    }
    case VehiclePath::Road: {
      const auto r = road_at(road_, road_shift_, s);
      return {r[0], r[1]};
    }
    case VehiclePath::Random:
    case VehiclePath::Log:
      return state_.position;
  }
  return state_.position;
}

double GroundVehicle::path_curvature(double s) const {
  const double sense = options_.counter_clockwise ? 1.0 : -1.0, R = options_.radius;
  switch (options_.path) {
    case VehiclePath::Line:
      return 0;
    case VehiclePath::Circle:
      return sense / R;
    case VehiclePath::FigureEight: {
      const double lobe = 2 * kPi * R;
      const double u = std::fmod(std::fmod(s, 2 * lobe) + 2 * lobe, 2 * lobe);
      return (u < lobe ? sense : -sense) / R;
    }
    case VehiclePath::Random:
      return random_curvature_;
    case VehiclePath::Log:
      return std::abs(state_.speed) > 1e-6 ? state_.yaw_rate / state_.speed : 0.0;
    case VehiclePath::Road:
      return road_at(road_, road_shift_, s)[2];
  }
  return 0;
}

// The speed and yaw-rate commands of this step: the speed target ramped at
// max_acceleration; the curvature from pure pursuit (κ = 2 sin α / L,
// Coulter 1992) on the path, or the random drive's curvature.
void GroundVehicle::commands(double dt, double* v_cmd, double* w_cmd) {
  const VehicleOptions& o = options_;
  double target = o.speed;
  double curvature = 0;
  if (o.path == VehiclePath::Random) {
    // Ornstein–Uhlenbeck walks of the speed and the curvature (time scale
    // random_change_time), bounded by the options.
    const double a = std::exp(-dt / o.random_change_time), b = std::sqrt(1 - a * a);
    random_speed_ = o.speed + a * (random_speed_ - o.speed) + b * o.random_speed_sigma * rng_.normal();
    random_speed_ = std::clamp(random_speed_, 0.25 * o.speed, o.speed + 2 * o.random_speed_sigma);
    random_curvature_ = a * random_curvature_ + b * (0.5 / o.radius) * rng_.normal();
    random_curvature_ = std::clamp(random_curvature_, -1 / o.radius, 1 / o.radius);
    target = random_speed_;
    curvature = random_curvature_;
  } else {
    // The closest path point, by projection from the last one (the path is
    // followed forward; a few Gauss–Newton steps).
    for (int i = 0; i < 3; ++i) {
      const double h = 1e-3;
      const Eigen::Vector2d tangent = (path_point(s_ + h) - path_point(s_ - h)) / (2 * h);
      s_ += (state_.position - path_point(s_)).dot(tangent) / std::max(tangent.squaredNorm(), 1e-9);
    }
    const Eigen::Vector2d goal = path_point(s_ + o.lookahead) - state_.position;
    const double alpha = wrap_pi(std::atan2(goal.y(), goal.x()) - state_.yaw);
    curvature = 2 * std::sin(alpha) / std::max(goal.norm(), 1e-6);
  }
  speed_command_ += std::clamp(target - speed_command_, -o.max_acceleration * dt, o.max_acceleration * dt);
  *v_cmd = speed_command_;
  *w_cmd = curvature * *v_cmd;
}

void GroundVehicle::step(double dt) {
  if (!(dt > 0) || !std::isfinite(dt)) throw InvalidArgument("vehicle step: dt must be positive");
  if (options_.path == VehiclePath::Log) {
    state_.t += dt;
    replay();
    return;
  }
  const VehicleOptions& o = options_;
  double v_cmd = 0, w_cmd = 0;
  commands(dt, &v_cmd, &w_cmd);
  const double k = 1 - std::exp(-dt / o.drive_time_constant);
  VehicleState& s = state_;
  double v = 0, w = 0;
  if (o.model == VehicleModel::Bicycle) {
    // A car: the front wheels turn towards the pursuit's curvature
    // (δ = atan(κ L)) within the angle and rate limits; the speed follows
    // the ramped command through the drive's lag; ψ' = v tan δ / L.
    const double curvature = v_cmd != 0 ? w_cmd / v_cmd : 0.0;
    const double wanted = std::clamp(std::atan(curvature * o.wheelbase), -o.max_steer, o.max_steer);
    steer_ += std::clamp(wanted - steer_, -o.max_steer_rate * dt, o.max_steer_rate * dt);
    v = s.speed + k * (v_cmd - s.speed);
    w = v * std::tan(steer_) / o.wheelbase;
    s.wheel_left = s.wheel_right = v;
  } else {
    // Skid-steer: the two tracks' speeds, scaled together (keeping the
    // curvature) to the wheel limit, each through its first-order drive.
    double left = v_cmd - 0.5 * w_cmd * o.track_width, right = v_cmd + 0.5 * w_cmd * o.track_width;
    const double top = std::max(std::abs(left), std::abs(right));
    if (top > o.max_wheel_speed) {
      left *= o.max_wheel_speed / top;
      right *= o.max_wheel_speed / top;
    }
    s.wheel_left += k * (left - s.wheel_left);
    s.wheel_right += k * (right - s.wheel_right);
    v = 0.5 * (s.wheel_left + s.wheel_right);
    w = (s.wheel_right - s.wheel_left) / o.track_width;
  }
  s.acceleration = (v - s.speed) / dt;
  // Exact integration of a constant speed and yaw rate over the step.
  const double yaw_mid = s.yaw + 0.5 * w * dt;
  const double chord = std::abs(w * dt) > 1e-9 ? 2 * v / w * std::sin(0.5 * w * dt) : v * dt;
  s.position += chord * Eigen::Vector2d(std::cos(yaw_mid), std::sin(yaw_mid));
  s.yaw = wrap_pi(s.yaw + w * dt);
  s.speed = v;
  s.yaw_rate = w;
  s.t += dt;
}

void GroundVehicle::replay() {
  const LogSample m = options_.log->sample(state_.t);
  state_.position = m.position;
  state_.yaw = m.yaw;
  state_.speed = m.speed;
  state_.yaw_rate = m.yaw_rate;
  state_.acceleration = m.acceleration;
  state_.wheel_left = state_.wheel_right = m.speed;  // no drives: the log is what the vehicle did
}

Eigen::Isometry3d GroundVehicle::T_world_pad() const {
  Eigen::Isometry3d T = state_.T_world_vehicle();
  T.translation() += T.linear() * options_.pad_position;
  return T;
}

Eigen::Vector3d GroundVehicle::pad_velocity() const {
  const Eigen::Matrix3d R = state_.T_world_vehicle().linear();
  const Eigen::Vector3d omega(0, 0, state_.yaw_rate);
  return R * Eigen::Vector3d(state_.speed, 0, 0) + omega.cross(R * options_.pad_position);
}

}  // namespace touchdown::mission
