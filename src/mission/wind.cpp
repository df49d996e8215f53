// Mean wind, Gauss–Markov gusts and Dryden turbulence (wind.hpp).
#include "touchdown/mission/wind.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

#include "core/checks.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/twin/flight_control.hpp"

namespace touchdown::mission {

namespace {

using touchdown::detail::positive;

constexpr double kFoot = 0.3048;           // [m]
constexpr double kKnot = 1852.0 / 3600.0;  // [m/s]

// The low-altitude model's factor (0.177 + 0.000823 h), h in feet within
// the model's range.
double low_altitude_factor(double h_ft) { return 0.177 + 0.000823 * h_ft; }

}  // namespace

double dryden_w20(TurbulenceLevel level) {
  switch (level) {
    case TurbulenceLevel::None:
      return 0;
    case TurbulenceLevel::Light:
      return 15 * kKnot;
    case TurbulenceLevel::Moderate:
      return 30 * kKnot;
    case TurbulenceLevel::Severe:
      return 45 * kKnot;
  }
  return 0;
}

DrydenParameters dryden_low_altitude(double altitude_m, double w20) {
  const double h_ft = std::clamp(altitude_m / kFoot, 10.0, 1000.0);
  const double f = low_altitude_factor(h_ft);
  DrydenParameters p;
  const double sigma_w = 0.1 * w20;
  const double sigma_uv = sigma_w / std::pow(f, 0.4);
  p.sigma = {sigma_uv, sigma_uv, sigma_w};
  const double l_uv = h_ft / std::pow(f, 1.2) * kFoot;
  p.length = {l_uv, l_uv, h_ft * kFoot};
  return p;
}

double dryden_psd(const DrydenParameters& p, int axis, double omega, double airspeed) {
  const double s2 = p.sigma[static_cast<std::size_t>(axis)] * p.sigma[static_cast<std::size_t>(axis)];
  const double L = p.length[static_cast<std::size_t>(axis)];
  const double x = L * omega / airspeed;  // L Ω
  if (axis == 0) return s2 * (2 * L / std::numbers::pi) / (1 + x * x) / airspeed;
  return s2 * (L / std::numbers::pi) * (1 + 3 * x * x) / ((1 + x * x) * (1 + x * x)) / airspeed;
}

double dryden_autocorrelation(const DrydenParameters& p, int axis, double tau, double airspeed) {
  const double s2 = p.sigma[static_cast<std::size_t>(axis)] * p.sigma[static_cast<std::size_t>(axis)];
  const double r = std::abs(tau) * airspeed / p.length[static_cast<std::size_t>(axis)];  // V|τ| / L
  if (axis == 0) return s2 * std::exp(-r);
  return s2 * (1 - 0.5 * r) * std::exp(-r);
}

bool WindOptions::validate(std::string* why) const {
  if (!mean.allFinite()) return invalid(why, "wind.mean: must be finite [m/s]");
  if (!(std::abs(turn_rate_deg) <= 30)) return invalid(why, "wind.turn_rate_deg: must be in [-30, 30] deg/s");
  if (!(gust_sigma >= 0) || !std::isfinite(gust_sigma)) return invalid(why, "wind.gust_sigma: must be >= 0");
  if (!positive(gust_time)) return invalid(why, "wind.gust_time: must be positive [s]");
  if (!(w20 >= 0 && w20 <= 50)) return invalid(why, "wind.w20: must be in [0, 50] m/s (0 = the level's)");
  if (!(positive(min_airspeed) && min_airspeed <= 50)) return invalid(why, "wind.min_airspeed: must be in (0, 50] m/s");
  return true;
}

double DrydenFilter::step(double dt, double sigma, double length, double airspeed, Rng& rng) {
  const double T = length / airspeed;  // the filter's time constant [s]
  const std::array<double, 3> key{dt, length, airspeed};
  const bool remake =
      key_[0] != dt || std::abs(key_[1] - length) > 0.01 * length || std::abs(key_[2] - airspeed) > 0.01 * airspeed;
  if (axis_ == 0) {
    // u: x' = −x/T + √(2/T) ξ (unit variance), exactly: a = e^{−dt/T};
    // a stationary start.
    if (remake) {
      key_ = key;
      phi_(0, 0) = std::exp(-dt / T);
      chol_(0, 0) = std::sqrt(std::max(0.0, 1 - phi_(0, 0) * phi_(0, 0)));
    }
    if (!started_) {
      started_ = true;
      x_(0) = rng.normal();
      return sigma * x_(0);
    }
    x_(0) = phi_(0, 0) * x_(0) + chol_(0, 0) * rng.normal();
    return sigma * x_(0);
  }
  if (remake) {
    // The state's stationary covariance, diag(T⁴/4, T²/4), depends on T:
    // rescaled to the new T so the output keeps unit variance (and does not
    // jump) when the airspeed or the height changes.
    if (started_ && T_ > 0) {
      const double r = T / T_;
      x_(0) *= r * r;
      x_(1) *= r;
    }
    T_ = T;
    // v, w: (1 + √3 T s) / (1 + T s)² in controllable canonical form,
    // driven by white noise of intensity q = T (unit output variance):
    // A = [0 1; −1/T² −2/T], B = [0 1]ᵀ, C = [1/T² √3/T]. Exact step by
    // Van Loan's method: exp([−A, B q Bᵀ; 0, Aᵀ] dt) = [·, E12; 0, E22],
    // Φ = E22ᵀ, Q = Φ E12.
    key_ = key;
    Eigen::Matrix2d A;
    A << 0, 1, -1 / (T * T), -2 / T;
    Eigen::Matrix2d BqB = Eigen::Matrix2d::Zero();
    BqB(1, 1) = T;
    Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
    M.topLeftCorner<2, 2>() = -A * dt;
    M.topRightCorner<2, 2>() = BqB * dt;
    M.bottomRightCorner<2, 2>() = A.transpose() * dt;
    const Eigen::Matrix4d E = M.exp();
    phi_ = E.bottomRightCorner<2, 2>().transpose();
    Eigen::Matrix2d Q = phi_ * E.topRightCorner<2, 2>();
    Q = 0.5 * (Q + Q.transpose());
    // 2 × 2 Cholesky, clamped: Q is rank-deficient to rounding for small steps.
    const double l11 = std::sqrt(std::max(0.0, Q(0, 0)));
    const double l21 = l11 > 0 ? Q(1, 0) / l11 : 0.0;
    const double l22 = std::sqrt(std::max(0.0, Q(1, 1) - l21 * l21));
    chol_ << l11, 0, l21, l22;
    c_ << 1 / (T * T), std::sqrt(3.0) / T;
    if (!started_) {
      started_ = true;
      // A stationary start: P∞ = diag(q / (2 a b), q / (2 b)), a = 1/T², b = 2/T.
      const double p22 = T * T / 4, p11 = p22 * T * T;
      x_ = Eigen::Vector2d(std::sqrt(p11) * rng.normal(), std::sqrt(p22) * rng.normal());
      return sigma * c_.dot(x_);
    }
  }
  const double n1 = rng.normal();
  const double n2 = rng.normal();
  x_ = phi_ * x_ + chol_ * Eigen::Vector2d(n1, n2);
  return sigma * c_.dot(x_);
}

WindModel::WindModel(const WindOptions& options, Rng gust_rng, Rng turbulence_rng)
    : o_(options), gust_rng_(gust_rng), turbulence_rng_(turbulence_rng) {
  // The gusts start stationary (as the mission always drew them).
  Eigen::Vector3d gust = normal_vector3(gust_rng_);
  gust.z() *= 0.5;  // vertical gusts are half as strong
  gust_ = gust * o_.gust_sigma;
}

Eigen::Vector3d WindModel::mean(double t) const {
  if (o_.turn_rate_deg == 0) return o_.mean;
  const double a = deg_to_rad(o_.turn_rate_deg) * t;
  const double c = std::cos(a), s = std::sin(a);
  return {c * o_.mean.x() - s * o_.mean.y(), s * o_.mean.x() + c * o_.mean.y(), o_.mean.z()};
}

Eigen::Vector3d WindModel::step(double t, double dt, double altitude, const Eigen::Vector3d& velocity) {
  const double ga = std::exp(-dt / o_.gust_time), gb = std::sqrt(1 - ga * ga);
  for (int i = 0; i < 3; ++i) {
    gust_[i] = ga * gust_[i] + gb * o_.gust_sigma * (i == 2 ? 0.5 : 1.0) * gust_rng_.normal();
  }
  const Eigen::Vector3d m = mean(t);
  const double w20 = o_.turbulence_w20();
  if (w20 <= 0) return m + gust_;
  const DrydenParameters p = dryden_low_altitude(altitude, w20);
  const double airspeed = std::max(o_.min_airspeed, (velocity - m).norm());
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(k);
    uvw_[k] = filters_[i].step(dt, p.sigma[i], p.length[i], airspeed, turbulence_rng_);
  }
  // The mean wind's axes: u along its horizontal direction (world x when
  // there is none), v to the left of it, w up.
  Eigen::Vector2d u = m.head<2>();
  u = u.norm() > 1e-9 ? Eigen::Vector2d(u.normalized()) : Eigen::Vector2d::UnitX();
  const Eigen::Vector3d turbulence(u.x() * uvw_.x() - u.y() * uvw_.y(), u.y() * uvw_.x() + u.x() * uvw_.y(), uvw_.z());
  return m + gust_ + turbulence;
}

void WindObserver::update(double dt, const Eigen::Vector3d& measured, const Eigen::Vector3d& thrust_specific,
                          const Eigen::Vector3d& velocity) {
  const Eigen::Vector3d force =
      mass_ * (measured - thrust_specific + Eigen::Vector3d(0, 0, twin::kStandardGravity));  // = D(air)
  const double f = force.norm();
  // |air| from c₂ a² + c₁ a = |F| (the root ≥ 0); air against the force.
  double a = 0;
  if (c2_ > 0) {
    a = (-c1_ + std::sqrt(c1_ * c1_ + 4 * c2_ * f)) / (2 * c2_);
  } else if (c1_ > 0) {
    a = f / c1_;
  } else {
    return;  // no drag: the wind does nothing to the drone, nothing to estimate
  }
  const Eigen::Vector3d air = f > 0 ? Eigen::Vector3d(-force / f * a) : Eigen::Vector3d::Zero();
  w_ += std::min(1.0, dt / tau_) * (velocity - air - w_);
}

Eigen::Vector3d WindObserver::feed_forward(const Eigen::Vector3d& velocity) const {
  return -(drag(velocity - w_) - drag(velocity)) / mass_;
}

}  // namespace touchdown::mission
