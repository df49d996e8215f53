#pragma once
/// \file
/// The RLaGA paper's online agent, our own on Eigen (no Debian package fits):
/// a small Q-network (eq. 3 state → one Q value per eq. 4 action), Adam, a
/// replay buffer and a target network (deep Q-learning), and its weights
/// file. The agent moves dynamic objects to hide the landing marker from the
/// drone's camera; its reward is eq. 5 (see surrogate.hpp, object_policy.hpp).
///
/// Thread-safety: a QNetwork is read-only after training; q_values() and
/// greedy() neither allocate nor write, so one network may be shared by
/// many threads. A Dqn is one thread's.
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/random.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::search {

/// eq. 3: (object − marker, drone − marker) in x, y [m], in that order:
/// object x, object y, drone x, drone y.
inline constexpr int kDqnStateSize = 4;
/// eq. 4: U, D, L, R, S (index order) = ObjectAction Up, Down, Left, Right, Stay.
inline constexpr int kDqnActions = 5;
/// Largest hidden layer a QNetwork takes (q_values() works on the stack).
inline constexpr int kDqnMaxHidden = 256;
/// The network sees the state multiplied by this (1/10 m): positions of a
/// landing scene (±10 m) become inputs of order 1.
inline constexpr double kDqnInputScale = 0.1;

/// eq. 4 index (0..4) → ObjectAction; throws InvalidArgument outside.
scenario::ObjectAction dqn_action(int index);

using DqnState = std::array<double, kDqnStateSize>;
using DqnQValues = std::array<double, kDqnActions>;

/// 4 → hidden → hidden → 5, ReLU on both hidden layers, linear output (the
/// source: 2 × 24 ReLU units). Inputs are the state × kDqnInputScale.
///
/// Parameters, flat in this order (parameters(), set_parameters(),
/// gradient(), the weights file): W1 (hidden × 4), b1 (hidden), W2 (hidden ×
/// hidden), b2 (hidden), W3 (5 × hidden), b3 (5); every matrix column-major
/// (W(r, c) at r + c × rows). h1 = relu(W1 x + b1), h2 = relu(W2 h1 + b2),
/// Q = W3 h2 + b3.
class QNetwork {
 public:
  /// All parameters zero. Throws InvalidArgument unless 1 ≤ hidden ≤ kDqnMaxHidden.
  explicit QNetwork(int hidden = 24);

  /// He-uniform: each weight uniform in ±sqrt(6 / fan_in), biases zero.
  void initialise(Rng& rng);

  /// The Q value of every action in state `s`. No allocation.
  [[nodiscard]] DqnQValues q_values(const DqnState& s) const;
  /// argmax of q_values(s); ties go to the lowest index.
  [[nodiscard]] int greedy(const DqnState& s) const;

  [[nodiscard]] int hidden() const { return hidden_; }
  [[nodiscard]] int parameter_count() const { return static_cast<int>(params_.size()); }
  /// Number of parameters of a network with `hidden` units per layer.
  [[nodiscard]] static int parameter_count(int hidden);
  [[nodiscard]] std::vector<double> parameters() const { return params_; }
  /// The raw parameter storage (same order), for optimisers.
  [[nodiscard]] std::span<const double> parameter_view() const { return params_; }
  [[nodiscard]] std::span<double> mutable_parameters() { return params_; }
  /// Throws InvalidArgument when the size is not parameter_count().
  void set_parameters(std::span<const double> values);

  /// Gradient of 0.5 × (Q(s)[action] − target)² with respect to every
  /// parameter (same order as parameters()), written into `grad` (resized);
  /// returns that loss. At a ReLU kink (pre-activation exactly 0) the
  /// derivative is taken as 0.
  double gradient(const DqnState& s, int action, double target, std::vector<double>& grad) const;
  /// As gradient(), but adds `scale` × the gradient to `grad` (already
  /// parameter_count() long); for mini-batches.
  double accumulate_gradient(const DqnState& s, int action, double target, double scale, std::span<double> grad) const;

  friend bool operator==(const QNetwork&, const QNetwork&) = default;

 private:
  int hidden_;
  std::vector<double> params_;
};

/// Adam (Kingma & Ba 2015) with bias correction: m ← β1 m + (1 − β1) g,
/// v ← β2 v + (1 − β2) g², θ ← θ − lr × m̂ / (sqrt(v̂) + ε) with
/// m̂ = m / (1 − β1^t), v̂ = v / (1 − β2^t).
class Adam {
 public:
  Adam(int size, double learning_rate, double beta1 = 0.9, double beta2 = 0.999, double epsilon = 1e-8);
  /// One update of `params` by `grad` (both `size` long).
  void step(std::span<double> params, std::span<const double> grad);
  [[nodiscard]] long steps() const { return t_; }

 private:
  double lr_, beta1_, beta2_, eps_;
  double beta1_t_ = 1, beta2_t_ = 1;  // β^t
  long t_ = 0;
  std::vector<double> m_, v_;
};

struct DqnOptions {
  int hidden = 24;              ///< units per hidden layer (source: 24)
  double learning_rate = 1e-3;  ///< Adam (source: 1e-3)
  double gamma = 0.95;          ///< discount
  int batch = 32;               ///< transitions per training step
  int replay_capacity = 2000;   ///< replay buffer (oldest dropped first)
  int target_update = 100;      ///< training steps between target-network copies
  double epsilon_start = 0.99, epsilon_end = 0.01, epsilon_decay = 0.995;  ///< per episode (source)

  /// False (with "key: what") when a value is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
  /// ε-greedy exploration rate of episode `episode` (0-based):
  /// max(epsilon_end, epsilon_start × epsilon_decay^episode).
  [[nodiscard]] double epsilon(int episode) const;
};

/// One observed step for the replay buffer.
struct DqnTransition {
  DqnState state{};
  int action = 0;
  double reward = 0;
  DqnState next{};
  bool done = false;
};

/// Deep Q-learning: an online network trained by Adam on mini-batches drawn
/// uniformly (with replacement) from the replay buffer, towards targets
/// r + γ max_a' Q_target(s', a') (r alone when done) of a target network
/// copied from the online one every `target_update` training steps.
class Dqn {
 public:
  /// Throws InvalidArgument for invalid options. Initialises the online
  /// network from `rng` and copies it into the target network.
  Dqn(const DqnOptions& options, Rng& rng);

  /// ε-greedy: a uniform random action with probability `epsilon`, else the
  /// online network's greedy action. Draws from `rng` exactly once, plus once
  /// more when exploring.
  int act(const DqnState& s, double epsilon, Rng& rng) const;
  void remember(const DqnState& s, int action, double reward, const DqnState& next, bool done);
  /// One Adam step on a mini-batch; returns its mean loss 0.5 (Q − target)²,
  /// or 0 and does nothing while the buffer holds fewer than `batch`
  /// transitions.
  double train_step(Rng& rng);

  [[nodiscard]] const QNetwork& network() const { return online_; }
  [[nodiscard]] const QNetwork& target_network() const { return target_; }
  [[nodiscard]] int replay_size() const { return static_cast<int>(replay_.size()); }
  [[nodiscard]] long train_steps() const { return train_steps_; }
  [[nodiscard]] const DqnOptions& options() const { return options_; }

 private:
  DqnOptions options_;
  QNetwork online_, target_;
  Adam adam_;
  std::vector<DqnTransition> replay_;
  std::size_t replay_next_ = 0;  // ring position once full
  long train_steps_ = 0;
  std::vector<double> grad_;
};

/// Weights file (docs/formats.md, "DQN weights file"): a versioned text
/// file, the format name and version, `hidden`, the parameter count, the
/// parameters one per line in QNetwork's order (shortest exact decimal, so
/// they read back bit-exact) and an `end` line. Bad, truncated,
/// wrong-version or wrong-size files throw ParseError with one line naming
/// the file (and the line) and the problem.
inline constexpr std::string_view kDqnWeightsFormat = "touchdown-dqn-weights";
inline constexpr int kDqnWeightsVersion = 1;

/// Writes atomically (a failed write leaves no partial file); throws IoError.
void save_weights(const QNetwork& net, const std::filesystem::path& path);
/// Throws IoError (unreadable) or ParseError.
QNetwork load_weights(const std::filesystem::path& path);
std::string weights_text(const QNetwork& net);
/// `source` names the text in errors (the file name).
QNetwork parse_weights(std::string_view text, std::string_view source);

}  // namespace touchdown::search
