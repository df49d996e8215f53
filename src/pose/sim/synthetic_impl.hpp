#pragma once
// The synthetic camera's internals (private to pose_sim): the per-thread
// buffers, the noise table, the pixel helpers and SyntheticCamera::Impl,
// shared by synthetic.cpp (options, set-up, the frame's final passes) and
// synthetic_render.cpp (the depth body, lamps, LEDs and marker passes).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "touchdown/core/random.hpp"
#include "touchdown/pose/se3.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

namespace touchdown::pose {

namespace render_detail {

constexpr int kMaxBlurSamples = 32;
constexpr double kMinDepth = 0.01;  // [m] points closer to the camera plane are not drawn

struct Bgr {
  float b, g, r;
};

// Core colours of the LED classes at saturation (BGR, DN).
inline Bgr core_colour(LedColor c) {
  switch (c) {
    case LedColor::Red:
      return {40, 50, 255};
    case LedColor::Green:
      return {70, 255, 60};
    case LedColor::Blue:
      return {255, 110, 40};
    case LedColor::White:
    case LedColor::Unknown:
      break;
  }
  return {255, 255, 255};
}

// 4096 standard normal draws: per-pixel noise is a table lookup indexed by
// 12 random bits (the table stays in L1 cache), much faster than
// Box–Muller per pixel and as deterministic (a fixed-seed Rng fills it).
constexpr std::size_t kTableMask = 4095;
inline const std::vector<float>& normal_table() {
  static const std::vector<float> kTable = [] {
    std::vector<float> t(kTableMask + 1);
    Rng rng(0x6e6f697365ull /* "noise" */, 0);
    double mean = 0, var = 0;
    std::vector<double> d(t.size());
    for (auto& v : d) v = rng.normal(), mean += v;
    mean /= static_cast<double>(d.size());
    for (double v : d) var += (v - mean) * (v - mean);
    const double sd = std::sqrt(var / static_cast<double>(d.size()));
    // Exactly zero mean and unit variance, so that noise_sigma is what it says.
    for (std::size_t i = 0; i < d.size(); ++i) t[i] = static_cast<float>((d[i] - mean) / sd);
    return t;
  }();
  return kTable;
}

// Per-thread scratch buffers, so that render() is const, thread-safe and
// allocation-free in steady state.
struct Scratch {
  std::vector<float> signal;  // BGR light added to the background [DN]
  std::vector<float> zbuf;    // nearest body/lamp depth [m]; +inf = none
  cv::Mat window;             // CV_32F marker window
  cv::Mat blurred;
  bool clean = false;  // signal all 0 and zbuf all +inf
};

inline Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// One colour value: background + light + noise, rounded and clipped [DN].
inline std::uint8_t colour_dn(float background, float light, float noise) {
  float v = background + light + noise;
  v = v > 0 ? (v < 255 ? v : 255.0f) : 0.0f;  // NaN → 0: never an undefined conversion
  return static_cast<std::uint8_t>(v + 0.5f);
}

// One depth value: z + k·z²·n quantised to the depth unit; 0 (invalid) when
// not positive, saturating at 65535.
inline std::uint16_t depth_units(float z, float k, float n, float inv_scale) {
  z += k * z * z * n;
  const float q = z * inv_scale + 0.5f;
  return !(q >= 1) ? std::uint16_t{0} : q >= 65535 ? std::uint16_t{65535} : static_cast<std::uint16_t>(q);
}

struct Window {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;  // inclusive
  [[nodiscard]] bool empty() const { return x1 < x0 || y1 < y0; }
};

inline Window clip_window(double umin, double vmin, double umax, double vmax, int w, int h) {
  Window r;
  if (!(umin <= umax) || !(vmin <= vmax)) return r;  // also NaN
  const double lo_u = std::max(umin, -1.0), lo_v = std::max(vmin, -1.0);
  const double hi_u = std::min(umax, static_cast<double>(w)), hi_v = std::min(vmax, static_cast<double>(h));
  if (lo_u > hi_u || lo_v > hi_v) return r;
  r.x0 = std::max(0, static_cast<int>(std::floor(lo_u)));
  r.y0 = std::max(0, static_cast<int>(std::floor(lo_v)));
  r.x1 = std::min(w - 1, static_cast<int>(std::ceil(hi_u)));
  r.y1 = std::min(h - 1, static_cast<int>(std::ceil(hi_v)));
  return r;
}

}  // namespace render_detail

struct SyntheticCamera::Impl {
  CameraModel camera;
  Constellation constellation;
  RenderOptions options;
  /// Undistorted normalised ray (x/z, y/z) of every pixel centre; only with
  /// lens distortion (otherwise computed on the fly).
  std::vector<float> rays;
  /// The printed card, one byte per cell (255 white, 0 black): the marker
  /// with its black border, surrounded by one white cell.
  std::vector<std::uint8_t> card;
  int card_cells = 0;
  /// Precomputed outputs for the common pixels, indexed like the normal
  /// table: background + noise (no light), and the ceiling's noisy depth.
  std::array<std::uint8_t, 4096> background_dn{};
  std::array<std::uint16_t, 4096> ceiling_depth{};
  double cell_size = 0;  // [m]

  /// Normalised ray through the (sub)pixel (u, v).
  [[nodiscard]] Eigen::Vector2d ray(double u, double v) const {
    if (rays.empty()) return {(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy};
    // Bilinear interpolation of the per-pixel map (smooth, so exact enough
    // for sub-pixel samples); clamped at the image border.
    const int w = camera.width, h = camera.height;
    const double uc = std::clamp(u, 0.0, static_cast<double>(w - 1));
    const double vc = std::clamp(v, 0.0, static_cast<double>(h - 1));
    const int x0 = std::min(static_cast<int>(uc), std::max(w - 2, 0));
    const int y0 = std::min(static_cast<int>(vc), std::max(h - 2, 0));
    const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
    const double fx = uc - x0, fy = vc - y0;
    auto at = [&](int x, int y, int c) {
      return static_cast<double>(rays[2 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x) + c]);
    };
    Eigen::Vector2d r;
    for (int c = 0; c < 2; ++c) {
      r[c] = (1 - fy) * ((1 - fx) * at(x0, y0, c) + fx * at(x1, y0, c)) +
             fy * ((1 - fx) * at(x0, y1, c) + fx * at(x1, y1, c));
    }
    return r;
  }

  [[nodiscard]] bool in_image(const Eigen::Vector2d& uv) const { return camera.in_image(uv); }

  /// Per-LED properties fixed per seed, and the frame's drop-outs.
  struct LedExtras {
    double gain = 1;  // brightness factor (led_gain_spread_stops)
    bool reflection = false;
    Eigen::Vector3d reflection_body = Eigen::Vector3d::Zero();
    bool dropped = false;
  };
  using Extras = std::array<LedExtras, kMaxLeds>;
  void led_extras(std::uint64_t seed, std::uint64_t frame_index, Rng& dropout_rng, Extras& extras) const;
  [[nodiscard]] double exposure(std::uint64_t seed, std::uint64_t frame_index) const;

  void render_depth_body(const Eigen::Isometry3d& T, const Extras& extras, std::vector<float>& zbuf) const;
  void render_lamps(std::uint64_t seed, double exposure, std::vector<float>& signal, std::vector<float>& zbuf) const;
  /// `xi`: the motion over one frame interval (the motion blur's), for the
  /// rolling shutter.
  void render_leds(const Eigen::Isometry3d* poses, int n, const Vector6d& xi, const Extras& extras, double exposure,
                   std::vector<float>& signal, RenderedFrame& out) const;
  bool render_marker(const Eigen::Isometry3d* poses, int n, double exposure, std::vector<float>& signal,
                     render_detail::Scratch& s) const;
};

}  // namespace touchdown::pose
