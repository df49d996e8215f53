// The DQN: Q-network, backpropagation, Adam, replay buffer, target network
// (dqn.hpp). RLaGA paper eq. 3 (state), eq. 4 (actions); the source's
// supplement fixes 2 × 24 ReLU units, learning rate 1e-3 and the ε schedule.
#include "touchdown/search/dqn.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "touchdown/core/error.hpp"

namespace touchdown::search {

namespace {

using HiddenVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kDqnMaxHidden, 1>;
using CMat = Eigen::Map<const Eigen::MatrixXd>;
using CVec = Eigen::Map<const Eigen::VectorXd>;
using Mat = Eigen::Map<Eigen::MatrixXd>;
using Vec = Eigen::Map<Eigen::VectorXd>;

// Offsets of the parameter blocks (QNetwork's documented order).
struct Layout {
  int h;
  int w1, b1, w2, b2, w3, b3, total;
  explicit Layout(int hidden) : h(hidden) {
    w1 = 0;
    b1 = w1 + h * kDqnStateSize;
    w2 = b1 + h;
    b2 = w2 + h * h;
    w3 = b2 + h;
    b3 = w3 + kDqnActions * h;
    total = b3 + kDqnActions;
  }
};

// The forward pass's intermediate values (stack only).
struct Forward {
  Eigen::Matrix<double, kDqnStateSize, 1> x;
  HiddenVec z1, h1, z2, h2;
  Eigen::Matrix<double, kDqnActions, 1> q;
};

void forward(const double* p, const Layout& l, const DqnState& s, Forward& f) {
  for (int i = 0; i < kDqnStateSize; ++i) f.x(i) = s[static_cast<std::size_t>(i)] * kDqnInputScale;
  const CMat w1(p + l.w1, l.h, kDqnStateSize), w2(p + l.w2, l.h, l.h), w3(p + l.w3, kDqnActions, l.h);
  const CVec b1(p + l.b1, l.h), b2(p + l.b2, l.h), b3(p + l.b3, kDqnActions);
  f.z1.noalias() = w1 * f.x;
  f.z1 += b1;
  f.h1 = f.z1.cwiseMax(0.0);
  f.z2.noalias() = w2 * f.h1;
  f.z2 += b2;
  f.h2 = f.z2.cwiseMax(0.0);
  f.q.noalias() = w3 * f.h2;
  f.q += b3;
}

}  // namespace

scenario::ObjectAction dqn_action(int index) {
  // eq. 4: U, D, L, R, S.
  using scenario::ObjectAction;
  switch (index) {
    case 0:
      return ObjectAction::Up;
    case 1:
      return ObjectAction::Down;
    case 2:
      return ObjectAction::Left;
    case 3:
      return ObjectAction::Right;
    case 4:
      return ObjectAction::Stay;
    default:
      throw InvalidArgument("dqn_action: index " + std::to_string(index) + " outside 0..4");
  }
}

QNetwork::QNetwork(int hidden) : hidden_(hidden) {
  if (hidden < 1 || hidden > kDqnMaxHidden)
    throw InvalidArgument("QNetwork: hidden " + std::to_string(hidden) + " outside 1.." +
                          std::to_string(kDqnMaxHidden));
  params_.assign(static_cast<std::size_t>(parameter_count(hidden)), 0.0);
}

int QNetwork::parameter_count(int hidden) { return Layout(hidden).total; }

void QNetwork::initialise(Rng& rng) {
  const Layout l(hidden_);
  auto fill = [&](int offset, int count, int fan_in) {
    const double a = std::sqrt(6.0 / fan_in);
    for (int i = 0; i < count; ++i) params_[static_cast<std::size_t>(offset + i)] = rng.uniform(-a, a);
  };
  std::fill(params_.begin(), params_.end(), 0.0);
  fill(l.w1, l.h * kDqnStateSize, kDqnStateSize);
  fill(l.w2, l.h * l.h, l.h);
  fill(l.w3, kDqnActions * l.h, l.h);
}

DqnQValues QNetwork::q_values(const DqnState& s) const {
  Forward f;
  forward(params_.data(), Layout(hidden_), s, f);
  DqnQValues q{};
  for (int a = 0; a < kDqnActions; ++a) q[static_cast<std::size_t>(a)] = f.q(a);
  return q;
}

int QNetwork::greedy(const DqnState& s) const {
  const DqnQValues q = q_values(s);
  int best = 0;
  for (int a = 1; a < kDqnActions; ++a)
    if (q[static_cast<std::size_t>(a)] > q[static_cast<std::size_t>(best)]) best = a;
  return best;
}

void QNetwork::set_parameters(std::span<const double> values) {
  if (values.size() != params_.size())
    throw InvalidArgument("QNetwork::set_parameters: " + std::to_string(values.size()) + " values for " +
                          std::to_string(params_.size()) + " parameters");
  std::copy(values.begin(), values.end(), params_.begin());
}

double QNetwork::gradient(const DqnState& s, int action, double target, std::vector<double>& grad) const {
  grad.assign(params_.size(), 0.0);
  return accumulate_gradient(s, action, target, 1.0, grad);
}

double QNetwork::accumulate_gradient(const DqnState& s, int action, double target, double scale,
                                     std::span<double> grad) const {
  if (action < 0 || action >= kDqnActions)
    throw InvalidArgument("QNetwork::gradient: action " + std::to_string(action) + " outside 0..4");
  if (grad.size() != params_.size()) throw InvalidArgument("QNetwork::gradient: wrong gradient size");
  const Layout l(hidden_);
  Forward f;
  forward(params_.data(), l, s, f);
  const double err = f.q(action) - target;
  const double loss = 0.5 * err * err;
  // Backpropagation: only row `action` of the output carries an error.
  const double d = scale * err;
  double* g = grad.data();
  const CMat w3(params_.data() + l.w3, kDqnActions, l.h), w2(params_.data() + l.w2, l.h, l.h);
  Mat g_w3(g + l.w3, kDqnActions, l.h), g_w2(g + l.w2, l.h, l.h), g_w1(g + l.w1, l.h, kDqnStateSize);
  Vec g_b2(g + l.b2, l.h), g_b1(g + l.b1, l.h);
  g_w3.row(action) += d * f.h2.transpose();
  g[l.b3 + action] += d;
  HiddenVec d2 = d * w3.row(action).transpose();
  d2 = d2.cwiseProduct((f.z2.array() > 0.0).cast<double>().matrix());
  g_w2.noalias() += d2 * f.h1.transpose();
  g_b2 += d2;
  HiddenVec d1;
  d1.noalias() = w2.transpose() * d2;
  d1 = d1.cwiseProduct((f.z1.array() > 0.0).cast<double>().matrix());
  g_w1.noalias() += d1 * f.x.transpose();
  g_b1 += d1;
  return loss;
}

Adam::Adam(int size, double learning_rate, double beta1, double beta2, double epsilon)
    : lr_(learning_rate),
      beta1_(beta1),
      beta2_(beta2),
      eps_(epsilon),
      m_(static_cast<std::size_t>(size), 0.0),
      v_(static_cast<std::size_t>(size), 0.0) {}

void Adam::step(std::span<double> params, std::span<const double> grad) {
  if (params.size() != m_.size() || grad.size() != m_.size()) throw InvalidArgument("Adam::step: wrong size");
  ++t_;
  beta1_t_ *= beta1_;
  beta2_t_ *= beta2_;
  const double c1 = 1.0 - beta1_t_, c2 = 1.0 - beta2_t_;
  for (std::size_t i = 0; i < m_.size(); ++i) {
    m_[i] = beta1_ * m_[i] + (1.0 - beta1_) * grad[i];
    v_[i] = beta2_ * v_[i] + (1.0 - beta2_) * grad[i] * grad[i];
    params[i] -= lr_ * (m_[i] / c1) / (std::sqrt(v_[i] / c2) + eps_);
  }
}

bool DqnOptions::validate(std::string* why) const {
  if (hidden < 1 || hidden > kDqnMaxHidden)
    return invalid(why, "hidden: must be in 1.." + std::to_string(kDqnMaxHidden));
  if (!(learning_rate > 0) || !std::isfinite(learning_rate)) return invalid(why, "learning_rate: must be > 0");
  if (!(gamma >= 0 && gamma < 1)) return invalid(why, "gamma: must be in [0, 1)");
  if (batch < 1) return invalid(why, "batch: must be >= 1");
  if (replay_capacity < batch) return invalid(why, "replay_capacity: must be >= batch");
  if (target_update < 1) return invalid(why, "target_update: must be >= 1");
  if (!(epsilon_start >= 0 && epsilon_start <= 1)) return invalid(why, "epsilon_start: must be in [0, 1]");
  if (!(epsilon_end >= 0 && epsilon_end <= epsilon_start))
    return invalid(why, "epsilon_end: must be in [0, epsilon_start]");
  if (!(epsilon_decay > 0 && epsilon_decay <= 1)) return invalid(why, "epsilon_decay: must be in (0, 1]");
  return true;
}

double DqnOptions::epsilon(int episode) const {
  return std::max(epsilon_end, epsilon_start * std::pow(epsilon_decay, episode));
}

namespace {
const DqnOptions& checked(const DqnOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("DqnOptions: " + why);
  return o;
}
}  // namespace

Dqn::Dqn(const DqnOptions& options, Rng& rng)
    : options_(checked(options)),
      online_(options.hidden),
      target_(options.hidden),
      adam_(QNetwork::parameter_count(options.hidden), options.learning_rate) {
  online_.initialise(rng);
  target_ = online_;
  replay_.reserve(static_cast<std::size_t>(options_.replay_capacity));
  grad_.assign(static_cast<std::size_t>(online_.parameter_count()), 0.0);
}

int Dqn::act(const DqnState& s, double epsilon, Rng& rng) const {
  if (rng.uniform() < epsilon) return std::min(kDqnActions - 1, static_cast<int>(rng.uniform() * kDqnActions));
  return online_.greedy(s);
}

void Dqn::remember(const DqnState& s, int action, double reward, const DqnState& next, bool done) {
  const DqnTransition t{s, action, reward, next, done};
  if (replay_.size() < static_cast<std::size_t>(options_.replay_capacity)) {
    replay_.push_back(t);
  } else {
    replay_[replay_next_] = t;
    replay_next_ = (replay_next_ + 1) % replay_.size();
  }
}

double Dqn::train_step(Rng& rng) {
  const int n = static_cast<int>(replay_.size());
  if (n < options_.batch) return 0.0;
  std::fill(grad_.begin(), grad_.end(), 0.0);
  const double scale = 1.0 / options_.batch;
  double loss = 0;
  for (int k = 0; k < options_.batch; ++k) {
    const auto i = std::min(static_cast<std::size_t>(rng.uniform() * n), replay_.size() - 1);
    const DqnTransition& t = replay_[i];
    double target = t.reward;
    if (!t.done) {
      const DqnQValues q = target_.q_values(t.next);
      target += options_.gamma * *std::max_element(q.begin(), q.end());
    }
    loss += online_.accumulate_gradient(t.state, t.action, target, scale, grad_);
  }
  adam_.step(online_.mutable_parameters(), grad_);
  ++train_steps_;
  if (train_steps_ % options_.target_update == 0) target_ = online_;
  return loss * scale;
}

}  // namespace touchdown::search
