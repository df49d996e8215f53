#pragma once
/// \file
/// The RLaGA paper's surrogate environment for pre-training the DQN: one
/// object that jumps to its next grid cell per action (eq. 4), a fixed
/// marker, no take-off, and no rendering beyond what eq. 5 needs. Our
/// miniature of the landing world: a downward camera (the world's 90°
/// horizontal field of view, 160 × 120 pixels) on a drone that descends from
/// 10 m to 3 m while it closes in on the marker (positions with noise), the
/// marker a square on the ground at the origin, the object a person-sized
/// box on a grid of 1 m cells. Per step the masks of the marker's projected
/// area as if unoccluded (S_gt) and visible past the object (S_d) give the
/// reward eq. 5 (evaluation.hpp's frame_reward).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "touchdown/core/batch.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/search/dqn.hpp"

namespace touchdown::search {

struct SurrogateOptions {
  int image_width = 160;  ///< [px] (the world camera's 640 × 480, scaled by 1/4)
  int image_height = 120;
  double hfov_deg = 90;                         ///< horizontal field of view (the world camera's)
  double marker_size = 1;                       ///< edge of the square marker at the origin [m]
  double cell = 1;                              ///< grid cell edge: one action moves the object this far [m]
  int grid_half_cells = 6;                      ///< the object stays within ± this many cells of the marker (clamped)
  Eigen::Vector3d object_size{0.5, 0.4, 1.75};  ///< x, y, height [m] (a person)
  double start_height = 10;                     ///< drone height at the episode's start [m]
  double end_height = 3;                        ///< at its last step [m]
  double start_radius = 3;      ///< the drone starts uniformly within this horizontal distance of the marker [m]
  double position_noise = 0.2;  ///< σ of the drone's position noise per step, each axis [m]
  int steps = 30;               ///< steps (actions) per episode

  /// False (with "key: what") when a value is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// The two marker masks of one frame, row-major, 1 = marker pixel.
struct MarkerMasks {
  int width = 0, height = 0;
  std::vector<std::uint8_t> truth;    ///< the marker's projected area as if nothing hid it (S_gt)
  std::vector<std::uint8_t> visible;  ///< of which not hidden by the object (S_d)
};

/// Rasterises the masks for a downward camera at `camera` (x, y, height
/// [m], image x along world +x, image up along world +y) and the object's
/// box centred on `object` (x, y) on the ground. A pixel counts when the
/// ray through its centre meets the marker (truth), and the ground before
/// the box (visible).
void render_marker_masks(const SurrogateOptions& options, const Eigen::Vector3d& camera, const Eigen::Vector2d& object,
                         MarkerMasks& masks);
/// (S_gt, S_d) in pixels from hand-made or rendered masks: the truth
/// pixels, and the pixels set in both. Throws InvalidArgument when the
/// sizes differ.
std::pair<double, double> mask_areas(std::span<const std::uint8_t> truth, std::span<const std::uint8_t> visible);
/// eq. 5 (frame_reward) of mask_areas().
double mask_reward(std::span<const std::uint8_t> truth, std::span<const std::uint8_t> visible);

class SurrogateEnv {
 public:
  /// Throws InvalidArgument for invalid options.
  explicit SurrogateEnv(const SurrogateOptions& options);

  /// A new episode: the object on a uniform random cell, the drone's noisy
  /// descent path drawn whole from `rng`. Returns the eq. 3 state.
  DqnState reset(Rng& rng);

  struct Step {
    DqnState state{};   ///< eq. 3, after the move
    double reward = 0;  ///< eq. 5 of the frame after the move
    bool done = false;  ///< the episode's last step
    double area_truth_px = 0, area_visible_px = 0;
  };
  /// Moves the object one cell by eq. 4 action `action` (0..4; clamped to
  /// the grid), the drone to its next position, and renders the frame.
  /// Throws InvalidArgument for a bad action or before reset().
  Step step(int action);

  [[nodiscard]] const SurrogateOptions& options() const { return options_; }
  [[nodiscard]] Eigen::Vector2d object() const { return object_; }
  [[nodiscard]] Eigen::Vector3d drone() const;

 private:
  [[nodiscard]] DqnState state() const;
  SurrogateOptions options_;
  Eigen::Vector2d object_ = Eigen::Vector2d::Zero();
  std::vector<Eigen::Vector3d> path_;  // drone position per step, 0..steps
  int k_ = -1;
  MarkerMasks masks_;
};

struct DqnTraining {
  QNetwork network;
  std::vector<double> episode_returns;  ///< eq. 5 summed over each training episode
};

/// Pre-training: `episodes` surrogate episodes, one training step per
/// environment step, ε by DqnOptions::epsilon(episode); progress(done,
/// total) after each episode (may be empty). Deterministic for a seed.
/// Throws InvalidArgument for invalid options or episodes < 0.
DqnTraining train_dqn(const DqnOptions& options, const SurrogateOptions& env, int episodes, std::uint64_t seed,
                      const ProgressCallback& progress = {});

/// Mean eq. 5 return of `policy` (state, rng → action) over `episodes`
/// fresh surrogate episodes drawn from `seed`.
double surrogate_mean_return(const SurrogateOptions& env, const std::function<int(const DqnState&, Rng&)>& policy,
                             int episodes, std::uint64_t seed);

}  // namespace touchdown::search
