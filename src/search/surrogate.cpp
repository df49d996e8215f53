// The surrogate environment and the DQN's pre-training (surrogate.hpp):
// RLaGA paper eq. 3 (state), eq. 4 (actions, one cell per step), eq. 5
// (reward, frame_reward of the two marker masks).
#include "touchdown/search/surrogate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "touchdown/core/error.hpp"
#include "touchdown/search/evaluation.hpp"

namespace touchdown::search {

bool SurrogateOptions::validate(std::string* why) const {
  if (image_width < 2 || image_width > 4096) return invalid(why, "image_width: must be in 2..4096");
  if (image_height < 2 || image_height > 4096) return invalid(why, "image_height: must be in 2..4096");
  if (!(hfov_deg > 1 && hfov_deg < 170)) return invalid(why, "hfov_deg: must be in (1, 170)");
  if (!(marker_size > 0 && marker_size < 100)) return invalid(why, "marker_size: must be in (0, 100) m");
  if (!(cell > 0 && cell < 100)) return invalid(why, "cell: must be in (0, 100) m");
  if (grid_half_cells < 0 || grid_half_cells > 1000) return invalid(why, "grid_half_cells: must be in 0..1000");
  if (!(object_size.minCoeff() > 0 && object_size.maxCoeff() < 100))
    return invalid(why, "object_size: every extent must be in (0, 100) m");
  if (!(end_height > 0 && end_height < 1000)) return invalid(why, "end_height: must be in (0, 1000) m");
  if (!(start_height >= end_height && start_height < 1000))
    return invalid(why, "start_height: must be in [end_height, 1000) m");
  if (!(start_radius >= 0 && start_radius < 1000)) return invalid(why, "start_radius: must be in [0, 1000) m");
  if (!(position_noise >= 0 && position_noise < 100)) return invalid(why, "position_noise: must be in [0, 100) m");
  if (steps < 1 || steps > 100000) return invalid(why, "steps: must be in 1..100000");
  return true;
}

namespace {

// Whether the ray camera + t d, t in (0, t_max), meets the axis-aligned box
// [lo, hi] (slab test).
bool ray_hits_box(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t_max, const Eigen::Vector3d& lo,
                  const Eigen::Vector3d& hi) {
  double t0 = 0, t1 = t_max;
  for (int i = 0; i < 3; ++i) {
    if (d(i) == 0) {
      if (o(i) < lo(i) || o(i) > hi(i)) return false;
      continue;
    }
    double a = (lo(i) - o(i)) / d(i), b = (hi(i) - o(i)) / d(i);
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace

void render_marker_masks(const SurrogateOptions& o, const Eigen::Vector3d& camera, const Eigen::Vector2d& object,
                         MarkerMasks& masks) {
  const int w = o.image_width, h = o.image_height;
  masks.width = w;
  masks.height = h;
  masks.truth.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0);
  masks.visible.assign(masks.truth.size(), 0);
  if (!(camera.z() > 0)) return;  // at or below the ground: no view
  const double f = 0.5 * w / std::tan(0.5 * o.hfov_deg * std::numbers::pi / 180.0);
  const double half = 0.5 * o.marker_size;
  const Eigen::Vector3d lo(object.x() - 0.5 * o.object_size.x(), object.y() - 0.5 * o.object_size.y(), 0.0);
  const Eigen::Vector3d hi(object.x() + 0.5 * o.object_size.x(), object.y() + 0.5 * o.object_size.y(),
                           o.object_size.z());
  // Only the pixels whose rays can meet the marker: its image bounding box
  // (u + 0.5 = (g_x - c_x) f / z + w / 2, v + 0.5 = (c_y - g_y) f / z + h / 2).
  const double k = f / camera.z();
  const auto clamp_px = [](double p, int n) { return static_cast<int>(std::clamp(p, 0.0, n - 1.0)); };
  const int u0 = clamp_px(std::floor((-half - camera.x()) * k + 0.5 * w - 0.5), w);
  const int u1 = clamp_px(std::ceil((half - camera.x()) * k + 0.5 * w - 0.5), w);
  const int v0 = clamp_px(std::floor((camera.y() - half) * k + 0.5 * h - 0.5), h);
  const int v1 = clamp_px(std::ceil((camera.y() + half) * k + 0.5 * h - 0.5), h);
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      // The ray through the pixel's centre; t = 1 on the ground.
      const Eigen::Vector3d d((u + 0.5 - 0.5 * w) / f * camera.z(), -(v + 0.5 - 0.5 * h) / f * camera.z(), -camera.z());
      const double gx = camera.x() + d.x(), gy = camera.y() + d.y();
      if (std::abs(gx) > half || std::abs(gy) > half) continue;
      const auto i = static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
      masks.truth[i] = 1;
      masks.visible[i] = ray_hits_box(camera, d, 1.0, lo, hi) ? 0 : 1;
    }
  }
}

std::pair<double, double> mask_areas(std::span<const std::uint8_t> truth, std::span<const std::uint8_t> visible) {
  if (truth.size() != visible.size())
    throw InvalidArgument("mask_areas: masks of " + std::to_string(truth.size()) + " and " +
                          std::to_string(visible.size()) + " pixels");
  double s_gt = 0, s_d = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i]) continue;
    s_gt += 1;
    if (visible[i]) s_d += 1;
  }
  return {s_gt, s_d};
}

double mask_reward(std::span<const std::uint8_t> truth, std::span<const std::uint8_t> visible) {
  const auto [s_gt, s_d] = mask_areas(truth, visible);
  return frame_reward(s_gt, s_d);  // eq. 5
}

SurrogateEnv::SurrogateEnv(const SurrogateOptions& options) : options_(options) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument("SurrogateOptions: " + why);
}

Eigen::Vector3d SurrogateEnv::drone() const {
  if (k_ < 0) throw InvalidArgument("SurrogateEnv: reset() first");
  return path_[static_cast<std::size_t>(k_)];
}

DqnState SurrogateEnv::state() const {
  // eq. 3 with the marker at the origin.
  const Eigen::Vector3d d = drone();
  return {object_.x(), object_.y(), d.x(), d.y()};
}

DqnState SurrogateEnv::reset(Rng& rng) {
  const SurrogateOptions& o = options_;
  const int n = 2 * o.grid_half_cells + 1;
  auto cell = [&] { return (std::min(n - 1, static_cast<int>(rng.uniform() * n)) - o.grid_half_cells) * o.cell; };
  object_.x() = cell();
  object_.y() = cell();
  // The drone closes in on the marker along a straight line while it
  // descends, as a landing system centring on it would.
  const double r = o.start_radius * std::sqrt(rng.uniform());
  const double a = rng.uniform(0.0, 2.0 * std::numbers::pi);
  const Eigen::Vector2d start(r * std::cos(a), r * std::sin(a));
  path_.resize(static_cast<std::size_t>(o.steps) + 1);
  for (int k = 0; k <= o.steps; ++k) {
    const double s = static_cast<double>(k) / o.steps;
    const Eigen::Vector2d xy = (1.0 - s) * start;
    const double z = o.start_height + s * (o.end_height - o.start_height);
    const double nx = rng.normal(0.0, o.position_noise), ny = rng.normal(0.0, o.position_noise);
    const double nz = rng.normal(0.0, o.position_noise);
    path_[static_cast<std::size_t>(k)] = Eigen::Vector3d(xy.x() + nx, xy.y() + ny, std::max(0.5, z + nz));
  }
  k_ = 0;
  return state();
}

SurrogateEnv::Step SurrogateEnv::step(int action) {
  if (k_ < 0) throw InvalidArgument("SurrogateEnv: reset() first");
  if (k_ >= options_.steps) throw InvalidArgument("SurrogateEnv: the episode is over; reset() first");
  // eq. 4: the object jumps to its next cell (up = +y), clamped to the grid.
  Eigen::Vector2d move = Eigen::Vector2d::Zero();
  switch (dqn_action(action)) {
    case scenario::ObjectAction::Up:
      move = {0, 1};
      break;
    case scenario::ObjectAction::Down:
      move = {0, -1};
      break;
    case scenario::ObjectAction::Left:
      move = {-1, 0};
      break;
    case scenario::ObjectAction::Right:
      move = {1, 0};
      break;
    case scenario::ObjectAction::Stay:
      break;
  }
  const double lim = options_.grid_half_cells * options_.cell;
  object_ = (object_ + options_.cell * move).cwiseMax(-lim).cwiseMin(lim);
  ++k_;
  render_marker_masks(options_, drone(), object_, masks_);
  Step s;
  std::tie(s.area_truth_px, s.area_visible_px) = mask_areas(masks_.truth, masks_.visible);
  s.reward = frame_reward(s.area_truth_px, s.area_visible_px);  // eq. 5
  s.state = state();
  s.done = k_ >= options_.steps;
  return s;
}

DqnTraining train_dqn(const DqnOptions& options, const SurrogateOptions& env_options, int episodes, std::uint64_t seed,
                      const ProgressCallback& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (episodes < 0) throw InvalidArgument("train_dqn: episodes must be >= 0");
  SurrogateEnv env(env_options);
  Rng init(seed, 0), rng(seed, 1);
  Dqn dqn(options, init);
  DqnTraining out{QNetwork(options.hidden), {}};
  out.episode_returns.reserve(static_cast<std::size_t>(episodes));
  for (int e = 0; e < episodes; ++e) {
    const double epsilon = options.epsilon(e);
    DqnState s = env.reset(rng);
    double ret = 0;
    for (;;) {
      const int a = dqn.act(s, epsilon, rng);
      const SurrogateEnv::Step st = env.step(a);
      dqn.remember(s, a, st.reward, st.state, st.done);
      dqn.train_step(rng);
      ret += st.reward;
      s = st.state;
      if (st.done) break;
    }
    out.episode_returns.push_back(ret);
    if (progress) {
      const auto done = static_cast<std::size_t>(e + 1);
      progress(progress_since(start, done, static_cast<std::size_t>(episodes), done - 1));
    }
  }
  out.network = dqn.network();
  return out;
}

double surrogate_mean_return(const SurrogateOptions& env_options,
                             const std::function<int(const DqnState&, Rng&)>& policy, int episodes,
                             std::uint64_t seed) {
  if (episodes < 1) throw InvalidArgument("surrogate_mean_return: episodes must be >= 1");
  SurrogateEnv env(env_options);
  Rng rng(seed, 2);
  double total = 0;
  for (int e = 0; e < episodes; ++e) {
    DqnState s = env.reset(rng);
    for (;;) {
      const SurrogateEnv::Step st = env.step(policy(s, rng));
      total += st.reward;
      s = st.state;
      if (st.done) break;
    }
  }
  return total / episodes;
}

}  // namespace touchdown::search
