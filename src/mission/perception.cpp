// The mission's `model` perception (perception.hpp).
#include "touchdown/mission/perception.hpp"

#include <cmath>

#include "core/checks.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random_vector.hpp"

namespace touchdown::mission {
namespace {

using touchdown::detail::non_negative;

}  // namespace

bool PerceptionModelOptions::validate(std::string* why) const {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) return invalid(why, "perception.rate_hz: must be positive");
  if (!non_negative(latency)) return invalid(why, "perception.latency: must be >= 0 [s]");
  if (!non_negative(sigma_a)) return invalid(why, "perception.sigma_a: must be >= 0 [m]");
  if (!non_negative(sigma_b)) return invalid(why, "perception.sigma_b: must be >= 0 [m/m^2]");
  if (!non_negative(bias_sigma)) return invalid(why, "perception.bias_sigma: must be >= 0 [m]");
  if (!(dropout >= 0 && dropout < 1)) return invalid(why, "perception.dropout: must be in [0, 1)");
  if (!non_negative(dropout_b)) return invalid(why, "perception.dropout_b: must be >= 0 [1/m^2]");
  if (!(dropout + dropout_b * max_range * max_range < 1)) {
    return invalid(why, "perception.dropout_b: dropout + dropout_b * max_range^2 must be below 1");
  }
  if (!non_negative(min_range)) return invalid(why, "perception.min_range: must be >= 0 [m]");
  if (!(max_range > min_range) || !std::isfinite(max_range)) {
    return invalid(why, "perception.max_range: must be finite and above min_range [m]");
  }
  if (!non_negative(fov_margin)) return invalid(why, "perception.fov_margin: must be >= 0 [m]");
  if (!(camera.horizontal_fov_rad > 0 && camera.horizontal_fov_rad < 3.14 && camera.vertical_fov_rad > 0 &&
        camera.vertical_fov_rad < 3.14)) {
    return invalid(why, "perception.camera: field of view must be in (0, 180) degrees");
  }
  return true;
}

PerceptionModel::PerceptionModel(PerceptionModelOptions options, std::uint64_t seed)
    : options_(std::move(options)), rng_(seed) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument(why);
  plan::CameraFov cone = options_.camera;
  cone.near_m = 0;
  cone.far_m = 1e6;
  fov_ = cone.pyramid();
  fov_.shrink(options_.fov_margin);
  bias_ = normal_vector3(rng_) * options_.bias_sigma;
}

bool PerceptionModel::visible(const Eigen::Vector3d& p_pad) const {
  const double r = (p_pad - options_.camera.T_pad_camera.translation()).norm();
  return r >= options_.min_range && r <= options_.max_range && fov_.contains(p_pad, 0);
}

PoseMeasurement PerceptionModel::capture(const PerceptionTruth& truth) {
  PoseMeasurement m;
  m.t_capture = truth.t;
  m.t_available = truth.t + options_.latency;
  // Draw every number whatever the outcome, so that one frame's visibility
  // does not shift the next frames' noise.
  const Eigen::Vector3d n = normal_vector3(rng_);
  const double drop = rng_.uniform();
  const double r = (truth.p_pad_com - options_.camera.T_pad_camera.translation()).norm();
  if (!visible(truth.p_pad_com) || drop < options_.dropout + options_.dropout_b * r * r) return m;
  m.sigma = options_.sigma_a + options_.sigma_b * r * r;
  m.p_pad = truth.p_pad_com + bias_ + m.sigma * n;
  m.ok = true;
  return m;
}

}  // namespace touchdown::mission
