// The wind model (wind.hpp): the Dryden forms against each other and
// against the spec's numbers, the stepped filters against the analytic
// autocorrelation and spectrum, the turning mean, options and YAML.
#include "touchdown/mission/wind.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "touchdown/core/random.hpp"

namespace touchdown::mission {
namespace {

constexpr double kKnot = 1852.0 / 3600.0;
constexpr double kFoot = 0.3048;

TEST(Dryden, LowAltitudeIntensitiesAndScalesAreMilF8785cs) {
  EXPECT_DOUBLE_EQ(dryden_w20(TurbulenceLevel::None), 0.0);
  EXPECT_NEAR(dryden_w20(TurbulenceLevel::Light), 7.7167, 1e-4);  // 15 kt
  EXPECT_NEAR(dryden_w20(TurbulenceLevel::Moderate), 2 * dryden_w20(TurbulenceLevel::Light), 1e-12);
  EXPECT_NEAR(dryden_w20(TurbulenceLevel::Severe), 3 * dryden_w20(TurbulenceLevel::Light), 1e-12);
  // h = 100 ft, W20 = 30 kt: (0.177 + 0.0823) = 0.2593; σ_w = 3 kt;
  // σ_u = σ_w / 0.2593^0.4 = 5.1475 kt; L_u = 100 / 0.2593^1.2 = 505.17 ft;
  // L_w = 100 ft (the spec's formulas, evaluated apart in Python).
  const DrydenParameters p = dryden_low_altitude(100 * kFoot, 30 * kKnot);
  EXPECT_NEAR(p.sigma[2], 3 * kKnot, 1e-12);
  EXPECT_NEAR(p.sigma[0] / kKnot, 5.1475, 1e-3);
  EXPECT_EQ(p.sigma[0], p.sigma[1]);
  EXPECT_NEAR(p.length[0] / kFoot, 505.17, 0.01);
  EXPECT_EQ(p.length[0], p.length[1]);
  EXPECT_NEAR(p.length[2] / kFoot, 100, 1e-9);
  // Below 10 ft the model's lower limit holds.
  const DrydenParameters low = dryden_low_altitude(0.5, 30 * kKnot), ten = dryden_low_altitude(10 * kFoot, 30 * kKnot);
  EXPECT_EQ(low.length, ten.length);
  EXPECT_EQ(low.sigma, ten.sigma);
}

// ∫₀^∞ Φ(ω) dω = σ² and R(τ) = ∫₀^∞ Φ(ω) cos(ωτ) dω: the spectrum and the
// autocorrelation as coded are one model (numerical quadrature over
// x = arctan(T ω), which maps [0, ∞) onto [0, π/2)).
TEST(Dryden, SpectrumAndAutocorrelationAreAFourierPair) {
  const DrydenParameters p = dryden_low_altitude(20.0, 30 * kKnot);
  const double V = 8.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double T = p.length[static_cast<std::size_t>(axis)] / V;
    for (double tau : {0.0, 0.3 * T, T, 2.5 * T}) {
      const int n = 200000;
      double sum = 0;
      for (int k = 0; k < n; ++k) {
        const double x = (k + 0.5) * (std::numbers::pi / 2) / n;  // midpoint rule
        const double w = std::tan(x) / T;
        const double dw_dx = 1 / (T * std::cos(x) * std::cos(x));
        sum += dryden_psd(p, axis, w, V) * std::cos(w * tau) * dw_dx;
      }
      sum *= (std::numbers::pi / 2) / n;
      const double s2 = p.sigma[static_cast<std::size_t>(axis)] * p.sigma[static_cast<std::size_t>(axis)];
      EXPECT_NEAR(sum, dryden_autocorrelation(p, axis, tau, V), 2e-3 * s2) << "axis " << axis << " tau " << tau;
    }
    EXPECT_NEAR(dryden_autocorrelation(p, axis, 0, V),
                p.sigma[static_cast<std::size_t>(axis)] * p.sigma[static_cast<std::size_t>(axis)], 1e-12);
  }
}

// The stepped filters, sampled long at a fixed airspeed: variance,
// autocorrelation at several lags and the spectrum (averaged periodograms,
// Hann window) against the analytic forms.
TEST(Dryden, SteppedFiltersHaveTheModelsAutocorrelationAndSpectrum) {
  const DrydenParameters p = dryden_low_altitude(3.0, 30 * kKnot);  // L_u ≈ 23 m, L_w ≈ 3 m
  const double V = 10.0, dt = 0.05;
  const int n = 400000;
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    DrydenFilter f(axis);
    Rng rng(7, static_cast<std::uint64_t>(axis));
    std::vector<double> x(static_cast<std::size_t>(n));
    for (auto& v : x) v = f.step(dt, p.sigma[a], p.length[a], V, rng);
    const double s2 = p.sigma[a] * p.sigma[a];
    const double T = p.length[a] / V;
    // Independent stretches ≈ n dt / (2 T): u ≈ 4 300, w ≈ 33 000.
    for (double tau : {0.0, 0.5 * T, T, 2 * T}) {
      const auto lag = static_cast<std::size_t>(std::lround(tau / dt));
      double r = 0;
      for (std::size_t i = 0; i + lag < x.size(); ++i) r += x[i] * x[i + lag];
      r /= static_cast<double>(x.size() - lag);
      EXPECT_NEAR(r, dryden_autocorrelation(p, axis, static_cast<double>(lag) * dt, V), 0.08 * s2)
          << "axis " << axis << " lag " << lag;
    }
    // Spectrum: segments of 512 samples; bins from 2 to 40 (0.08–1.6 Hz,
    // well below the 10 Hz Nyquist frequency), four bins averaged a point.
    const int m = 512;
    const int segments = n / m;
    for (int bin : {2, 6, 12, 25, 40}) {
      double est = 0, model = 0;
      for (int b = bin; b < bin + 4; ++b) {
        double pw = 0, wsum = 0;
        for (int s = 0; s < segments; ++s) {
          std::complex<double> acc = 0;
          for (int k = 0; k < m; ++k) {
            const double w = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * k / m);
            const double ph = -2 * std::numbers::pi * b * k / m;
            acc += w * x[static_cast<std::size_t>(s * m + k)] * std::complex<double>(std::cos(ph), std::sin(ph));
            if (s == 0) wsum += w * w;
          }
          pw += std::norm(acc);
        }
        // One-sided PSD per hertz, then per rad/s.
        const double per_hz = 2 * dt * pw / segments / wsum;
        est += per_hz / (2 * std::numbers::pi);
        model += dryden_psd(p, axis, 2 * std::numbers::pi * b / (m * dt), V);
      }
      EXPECT_NEAR(est / model, 1.0, 0.15) << "axis " << axis << " bin " << bin;
    }
  }
}

// Over an ensemble of filters: every component starts stationary (the
// first sample has variance σ²), and stays so while the airspeed changes
// (the state follows the time constant, it does not jump).
TEST(Dryden, StationaryFromTheStartAndWhileTheAirspeedChanges) {
  const DrydenParameters p = dryden_low_altitude(10.0, 30 * kKnot);
  const int n = 4000;
  for (int axis = 0; axis < 3; ++axis) {
    const auto a = static_cast<std::size_t>(axis);
    double first = 0, last = 0;
    for (int k = 0; k < n; ++k) {
      DrydenFilter f(axis);
      Rng rng(11, static_cast<std::uint64_t>(k));
      double x = f.step(0.01, p.sigma[a], p.length[a], 1.0, rng);
      first += x * x;
      for (int i = 1; i <= 200; ++i) x = f.step(0.01, p.sigma[a], p.length[a], 1.0 + 5.0 * i / 200, rng);  // 1 → 6 m/s
      last += x * x;
    }
    const double s2 = p.sigma[a] * p.sigma[a];
    EXPECT_NEAR(first / n / s2, 1.0, 0.08) << "axis " << axis;  // 4 000 samples: σ of the ratio ≈ 0.022
    EXPECT_NEAR(last / n / s2, 1.0, 0.08) << "axis " << axis;
  }
}

TEST(WindModel, NoTurbulenceIsTheMeanPlusGustsAndTheMeanTurns) {
  WindOptions o;
  o.mean = {4, 0, 0.5};
  o.turn_rate_deg = 9;  // a quarter turn in 10 s
  WindModel w(o, Rng(1, 2), Rng(1, 6));
  EXPECT_NEAR((w.mean(10) - Eigen::Vector3d(0, 4, 0.5)).norm(), 0, 1e-12);
  EXPECT_EQ(w.step(0.01, 0.01, 5, Eigen::Vector3d::Zero()), w.mean(0.01));  // no gusts, no turbulence
  o.turn_rate_deg = 0;
  WindModel still(o, Rng(1, 2), Rng(1, 6));
  EXPECT_EQ(still.mean(123), o.mean);
}

TEST(WindModel, TurbulenceIsInTheMeanWindsAxesAndSeeded) {
  WindOptions o;
  o.mean = {0, 5, 0};  // from the south: u is world y, v is world −x
  o.turbulence = TurbulenceLevel::Severe;
  WindModel a(o, Rng(3, 2), Rng(3, 6)), b(o, Rng(3, 2), Rng(3, 6));
  for (int k = 1; k <= 200; ++k) {
    const double t = 0.01 * k;
    const Eigen::Vector3d wa = a.step(t, 0.01, 10, Eigen::Vector3d(1, 0, 0));
    EXPECT_EQ(wa, b.step(t, 0.01, 10, Eigen::Vector3d(1, 0, 0)));  // same seed, same wind
    const Eigen::Vector3d& uvw = a.turbulence_uvw();
    EXPECT_NEAR(wa.x(), -uvw.y(), 1e-12);
    EXPECT_NEAR(wa.y(), 5 + uvw.x(), 1e-12);
    EXPECT_NEAR(wa.z(), uvw.z(), 1e-12);
  }
  EXPECT_GT(a.turbulence_uvw().norm(), 0);
}

// A drone at velocity v in a steady wind w: the thrust balances gravity,
// drag and whatever acceleration it has; the observer recovers w exactly
// (the inversion of the quadratic drag) and flies the drag the wind adds.
TEST(WindObserver, RecoversASteadyWindThroughTheDrag) {
  const double m = 0.6, c1 = 0.05, c2 = 0.01, g = 9.80665;
  WindObserver obs(0.05, m, c1, c2);
  const Eigen::Vector3d w(5, -3, 0.5), v(2, 1, -0.4), a(0.3, -0.2, 0.1);
  const Eigen::Vector3d drag = obs.drag(v - w);
  // m a = T + D − m g e_z  ⇒  T / m = a − D / m + g e_z.
  const Eigen::Vector3d thrust = a - drag / m + Eigen::Vector3d(0, 0, g);
  for (int k = 0; k < 2000; ++k) obs.update(0.002, a, thrust, v);
  EXPECT_LT((obs.wind() - w).norm(), 1e-9);
  EXPECT_LT((obs.feed_forward(v) - (-(drag - obs.drag(v)) / m)).norm(), 1e-9);
  // Still air: nothing to fly against.
  WindObserver calm(0.05, m, c1, c2);
  const Eigen::Vector3d thrust_calm = a - calm.drag(v) / m + Eigen::Vector3d(0, 0, g);
  for (int k = 0; k < 2000; ++k) calm.update(0.002, a, thrust_calm, v);
  EXPECT_LT(calm.wind().norm(), 1e-9);
  EXPECT_LT(calm.feed_forward(v).norm(), 1e-9);
  // Linear drag only, and no drag at all (nothing to estimate).
  WindObserver linear(0.05, m, c1, 0);
  for (int k = 0; k < 2000; ++k) linear.update(0.002, a, a - linear.drag(v - w) / m + Eigen::Vector3d(0, 0, g), v);
  EXPECT_LT((linear.wind() - w).norm(), 1e-9);
  WindObserver none(0.05, m, 0, 0);
  none.update(0.002, a, thrust, v);
  EXPECT_EQ(none.wind(), Eigen::Vector3d::Zero());
}

TEST(WindOptions, RefusesWhatIsOutOfRange) {
  std::string why;
  WindOptions o;
  EXPECT_TRUE(o.validate(&why)) << why;
  o.turn_rate_deg = 45;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("wind.turn_rate_deg"), std::string::npos);
  o = {};
  o.min_airspeed = 0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("wind.min_airspeed"), std::string::npos);
  o = {};
  o.w20 = std::nan("");
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("wind.w20"), std::string::npos);
}

}  // namespace
}  // namespace touchdown::mission
