#pragma once
/// \file
/// Wind that real flights meet: a mean wind whose direction may turn
/// slowly, plus turbulence from the Dryden model in its MIL-F-8785C form
/// (the low-altitude model, section 3.7.3.2 and 3.7.3.3; the same forms as
/// MIL-HDBK-1797's Dryden model for altitudes below 1000 ft).
///
/// The Dryden model gives each turbulence component as white noise through
/// a rational filter, in the mean wind's axes (u along the mean wind, v
/// across it, w up), for an aircraft flying through a frozen field at
/// airspeed V (Taylor's hypothesis):
///   Φ_u(Ω) = σ_u² (2 L_u / π) / (1 + (L_u Ω)²)
///   Φ_v(Ω) = σ_v² (L_v / π) (1 + 3 (L_v Ω)²) / (1 + (L_v Ω)²)²     (w alike)
/// with Ω = ω / V the spatial frequency [rad/m], one-sided, so that the
/// integral over Ω ≥ 0 is σ². In time: Φ(ω) = Φ(Ω = ω / V) / V, and the
/// autocorrelations are R_u(τ) = σ_u² e^{−Vτ/L_u},
/// R_v(τ) = σ_v² (1 − Vτ / (2 L_v)) e^{−Vτ/L_v} (dryden_autocorrelation).
///
/// Low altitude (h in feet, 10 < h < 1000): L_w = h, L_u = L_v =
/// h / (0.177 + 0.000823 h)^1.2, σ_w = 0.1 W20, σ_u = σ_v =
/// σ_w / (0.177 + 0.000823 h)^0.4, W20 the wind speed at 20 ft: 15, 30 and
/// 45 knots for light, moderate and severe turbulence. Below 10 ft the
/// 10 ft values are used (the model's lower limit).
///
/// Discretisation: each filter's state-space form is stepped with its exact
/// discrete transition and the exact covariance of the noise integrated
/// over the step (Van Loan 1978), so a sampled sequence has the model's
/// autocorrelation at every lag, for any step, not an approximation of it.
/// V changes with the drone's speed through the air: the transition is
/// recomputed when it moved by more than 1 % since the last. A hovering
/// rotorcraft has no airspeed of its own; V is floored at `min_airspeed`
/// (the frozen field then drifts past at that speed).
///
/// Thread-safety: one WindModel per mission.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/random.hpp"

namespace touchdown::mission {

enum class TurbulenceLevel { None, Light, Moderate, Severe };

/// The flight controller's wind estimate. Each control step in free flight
/// the force its thrust and gravity do not explain, F = m (a_measured − g)
/// − R e_z T, is taken as the airframe's drag, F = −(c₁ + c₂|air|) air,
/// and inverted for the air's velocity relative to the drone; the wind is
/// the drone's velocity minus it, low-passed with time constant τ:
///   ŵ ← ŵ + (dt / τ) (v − air(F) − ŵ).
/// The controller flies the drag the wind adds, −(D(v − ŵ) − D(v)) / m, as
/// acceleration feed-forward (feed_forward), so its integrators keep only
/// what the estimate misses, and in still air it flies as it did without
/// one. Why a wind state and not the raw disturbance: feeding the whole
/// unexplained acceleration forward, lagged by τ, cancels the airframe's own
/// drag a moment late and took the damping out of the touchdown (median
/// error 0.014 → 0.066 m, 95th-percentile touchdown speed 0.28 → 0.74 m/s in
/// still air); the wind changes slowly, the drone's own drag does not.
/// The drag coefficients are the airframe's (DroneOptions): the flight
/// controller is assumed to know them, as from a system identification.
class WindObserver {
 public:
  WindObserver(double time_constant, double mass, double drag_linear, double drag_quadratic)
      : tau_(time_constant), mass_(mass), c1_(drag_linear), c2_(drag_quadratic) {}
  /// One control step: the world acceleration measured over the last step,
  /// the thrust's specific force (world) that acted in it [m/s²] and the
  /// drone's (estimated) velocity [m/s].
  void update(double dt, const Eigen::Vector3d& measured, const Eigen::Vector3d& thrust_specific,
              const Eigen::Vector3d& velocity);
  /// The wind estimate, world [m/s].
  [[nodiscard]] const Eigen::Vector3d& wind() const { return w_; }
  /// The acceleration to fly against the drag the estimated wind adds at
  /// `velocity` [m/s²].
  [[nodiscard]] Eigen::Vector3d feed_forward(const Eigen::Vector3d& velocity) const;
  /// The airframe's drag force at this velocity relative to the air [N].
  [[nodiscard]] Eigen::Vector3d drag(const Eigen::Vector3d& air) const { return -(c1_ + c2_ * air.norm()) * air; }

 private:
  double tau_, mass_, c1_, c2_;
  Eigen::Vector3d w_ = Eigen::Vector3d::Zero();
};

}  // namespace touchdown::mission

template <>
struct touchdown::EnumNames<touchdown::mission::TurbulenceLevel> {
  static constexpr std::array<std::string_view, 4> names{"none", "light", "moderate", "severe"};
};

namespace touchdown::mission {

inline std::string_view to_string(TurbulenceLevel level) { return enum_name(level); }

/// W20, the wind speed 20 ft above the ground that sets the low-altitude
/// intensities: 15 / 30 / 45 knots (MIL-F-8785C fig. 10) [m/s]; 0 for None.
double dryden_w20(TurbulenceLevel level);

/// The Dryden model's intensities and scale lengths at an altitude.
struct DrydenParameters {
  std::array<double, 3> sigma{};   ///< σ_u, σ_v, σ_w [m/s]
  std::array<double, 3> length{};  ///< L_u, L_v, L_w [m]
};

/// MIL-F-8785C low altitude: from the altitude above ground [m] and W20
/// [m/s] (dryden_w20). Altitudes below 10 ft use 10 ft's values, above
/// 1000 ft 1000 ft's.
DrydenParameters dryden_low_altitude(double altitude_m, double w20);

/// Φ(ω) of component `axis` (0 u, 1 v, 2 w) at angular frequency ω
/// [rad/s] for airspeed V [m/s], one-sided: ∫₀^∞ Φ dω = σ² [(m/s)² s].
double dryden_psd(const DrydenParameters& p, int axis, double omega, double airspeed);

/// R(τ) = E[x(t) x(t + τ)] of component `axis` at airspeed V [(m/s)²].
double dryden_autocorrelation(const DrydenParameters& p, int axis, double tau, double airspeed);

struct WindOptions {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  ///< world at t = 0 [m/s]
  /// The mean wind's horizontal direction turns at this rate (positive
  /// counter-clockwise seen from above) [deg/s], |rate| ≤ 30.
  double turn_rate_deg = 0;
  /// Gusts: a first-order Gauss–Markov process per axis (kept beside the
  /// Dryden model; 0 = none).
  double gust_sigma = 0;   ///< per horizontal axis [m/s] (vertical: half)
  double gust_time = 2.0;  ///< correlation time [s], > 0
  /// Dryden turbulence (above); `w20` > 0 overrides the level's W20 [m/s].
  TurbulenceLevel turbulence = TurbulenceLevel::None;
  double w20 = 0;
  double min_airspeed = 1.0;  ///< V's floor [m/s], > 0

  /// False (with "wind.key: problem") for an invalid value.
  [[nodiscard]] bool validate(std::string* why) const;
  [[nodiscard]] double turbulence_w20() const { return w20 > 0 ? w20 : dryden_w20(turbulence); }
};

/// One Dryden component as a stepped filter (exact discretisation).
class DrydenFilter {
 public:
  explicit DrydenFilter(int axis) : axis_(axis) {}
  /// The next sample after `dt` seconds, for intensity σ, scale length L
  /// and airspeed V; `rng` gives the white noise.
  double step(double dt, double sigma, double length, double airspeed, Rng& rng);
  void reset() { x_.setZero(), key_ = {}, started_ = false, T_ = 0; }

 private:
  int axis_;
  Eigen::Vector2d x_ = Eigen::Vector2d::Zero();  // unit-σ state (u: first element only)
  std::array<double, 3> key_{};                  // dt, L, V the transition below was made for
  bool started_ = false;                         // drawn from the stationary distribution once
  double T_ = 0;                                 // the time constant the state is scaled for (v, w)
  Eigen::Matrix2d phi_ = Eigen::Matrix2d::Zero(), chol_ = Eigen::Matrix2d::Zero();
  Eigen::RowVector2d c_ = Eigen::RowVector2d::Zero();
};

/// The wind at the drone: mean (turning) + gusts + Dryden turbulence.
class WindModel {
 public:
  /// `gust_rng` draws the Gauss–Markov gusts (one normal per axis per
  /// step, as before the Dryden model), `turbulence_rng` the Dryden noise.
  WindModel(const WindOptions& options, Rng gust_rng, Rng turbulence_rng);
  /// The mean wind at time t [m/s].
  [[nodiscard]] Eigen::Vector3d mean(double t) const;
  /// Advances by dt to time t (after the step) for a drone at `altitude`
  /// above the ground moving at `velocity` (world) and returns the wind
  /// there, world frame [m/s].
  Eigen::Vector3d step(double t, double dt, double altitude, const Eigen::Vector3d& velocity);
  /// The turbulence part of the last step, in the mean wind's axes (u, v, w).
  [[nodiscard]] const Eigen::Vector3d& turbulence_uvw() const { return uvw_; }

 private:
  WindOptions o_;
  Rng gust_rng_, turbulence_rng_;
  Eigen::Vector3d gust_ = Eigen::Vector3d::Zero(), uvw_ = Eigen::Vector3d::Zero();
  std::array<DrydenFilter, 3> filters_{DrydenFilter(0), DrydenFilter(1), DrydenFilter(2)};
};

}  // namespace touchdown::mission
