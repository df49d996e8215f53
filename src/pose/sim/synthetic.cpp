#include "touchdown/pose/sim/synthetic.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/se3.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::pose {

namespace {

constexpr int kMaxBlurSamples = 32;
constexpr double kMinDepth = 0.01;  // [m] points closer to the camera plane are not drawn

struct Bgr {
  float b, g, r;
};

// Core colours of the LED classes at saturation (BGR, DN).
Bgr core_colour(LedColor c) {
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
const std::vector<float>& normal_table() {
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

Scratch& scratch() {
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

Window clip_window(double umin, double vmin, double umax, double vmax, int w, int h) {
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

}  // namespace

// ---- options -----------------------------------------------------------------

bool RenderOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  auto finite_nonneg = [](double v) { return std::isfinite(v) && v >= 0; };
  auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!finite_nonneg(noise_sigma) || noise_sigma > 100) return fail("noise_sigma: must be in [0, 100] DN");
  if (!finite_nonneg(background_level) || background_level > 255)
    return fail("background_level: must be in [0, 255] DN");
  if (!finite_nonneg(led_radius) || led_radius > 0.1) return fail("led_radius: must be in [0, 0.1] m");
  if (!positive(optics_blur_sigma) || optics_blur_sigma > 20) return fail("optics_blur_sigma: must be in (0, 20] px");
  if (!positive(led_gain) || led_gain > 1000) return fail("led_gain: must be in (0, 1000]");
  if (!finite_nonneg(bloom_fraction) || bloom_fraction > 1) return fail("bloom_fraction: must be in [0, 1]");
  if (!positive(bloom_sigma) || bloom_sigma > 50) return fail("bloom_sigma: must be in (0, 50] px");
  if (!(led_dropout_probability >= 0 && led_dropout_probability <= 1)) {
    return fail("led_dropout_probability: must be in [0, 1]");
  }
  if (!finite_nonneg(exposure_s) || exposure_s > 1) return fail("exposure_s: must be in [0, 1] s");
  if (!positive(frame_rate_hz) || frame_rate_hz > 10000) return fail("frame_rate_hz: must be in (0, 10000] Hz");
  if (exposure_s * frame_rate_hz > 1) return fail("exposure_s: longer than the frame interval 1/frame_rate_hz");
  if (motion_blur_samples < 1 || motion_blur_samples > kMaxBlurSamples) {
    return fail("motion_blur_samples: must be in 1.." + std::to_string(kMaxBlurSamples));
  }
  if (!finite_nonneg(depth_noise_k) || depth_noise_k > 1) return fail("depth_noise_k: must be in [0, 1] 1/m");
  if (!(depth_invalid_fraction >= 0 && depth_invalid_fraction <= 1)) {
    return fail("depth_invalid_fraction: must be in [0, 1]");
  }
  if (!positive(ceiling_distance) || ceiling_distance > 1000) return fail("ceiling_distance: must be in (0, 1000] m");
  if (!finite_nonneg(body_half_size) || body_half_size > 10) return fail("body_half_size: must be in [0, 10] m");
  if (!std::isfinite(body_z_min) || !std::isfinite(body_z_max) || body_z_min > body_z_max) {
    return fail("body_z_min: must be finite and <= body_z_max");
  }
  if (!finite_nonneg(led_disc_radius) || led_disc_radius > 1) return fail("led_disc_radius: must be in [0, 1] m");
  if (distractor_count < 0 || distractor_count > 100) return fail("distractor_count: must be in 0..100");
  if (!positive(distractor_min_depth) || !std::isfinite(distractor_max_depth) ||
      distractor_max_depth < distractor_min_depth) {
    return fail("distractor_min_depth: must be positive and <= distractor_max_depth");
  }
  const auto* dict = find_aruco_dictionary(aruco_dictionary);
  if (!dict) return fail("aruco_dictionary: unknown dictionary " + unknown_aruco_dictionary(aruco_dictionary));
  if (aruco_id < 0 || aruco_id >= dict->codes) {
    return fail("aruco_id: must be in 0.." + std::to_string(dict->codes - 1) + " for " + aruco_dictionary);
  }
  if (!positive(aruco_size) || aruco_size > 10) return fail("aruco_size: must be in (0, 10] m");
  if (!finite_nonneg(marker_white) || marker_white > 255) return fail("marker_white: must be in [0, 255] DN");
  if (!finite_nonneg(marker_black) || marker_black > marker_white) {
    return fail("marker_black: must be in [0, marker_white] DN");
  }
  if (!(led_gain_spread_stops >= 0 && led_gain_spread_stops <= 4)) {
    return fail("led_gain_spread_stops: must be in [0, 4]");
  }
  if (exposure_step_stops < 0 || exposure_step_stops > 4) return fail("exposure_step_stops: must be in 0..4");
  if (exposure_step_frames < 1 || exposure_step_frames > 100000) {
    return fail("exposure_step_frames: must be in 1..100000");
  }
  if (led_dropout_frames < 1 || led_dropout_frames > 100000) return fail("led_dropout_frames: must be in 1..100000");
  if (!(reflection_probability >= 0 && reflection_probability <= 1)) {
    return fail("reflection_probability: must be in [0, 1]");
  }
  if (!finite_nonneg(reflection_gain) || reflection_gain > 1) return fail("reflection_gain: must be in [0, 1]");
  if (!finite_nonneg(reflection_offset) || reflection_offset > 1) {
    return fail("reflection_offset: must be in [0, 1] m");
  }
  if (!(distractor_led_like_fraction >= 0 && distractor_led_like_fraction <= 1)) {
    return fail("distractor_led_like_fraction: must be in [0, 1]");
  }
  if (!positive(merge_threshold_dn) || merge_threshold_dn > 255) {
    return fail("merge_threshold_dn: must be in (0, 255] DN");
  }
  return true;
}

RenderOptions apply_profile(RenderOptions o, RenderProfile profile) {
  if (profile != RenderProfile::Harsh) return o;
  // A camera at normal exposure: white cores whose hue halo varies with
  // each LED's brightness (±1 stop) and the exposure (±1 stop, steps every
  // second), a brighter bloom, an exposure four times longer (streaks at
  // short range), more noise, drop-outs of a third of a second, reflections
  // off the airframe, and half of four lamps LED-like.
  o.white_cores = true;
  o.led_gain = 12;
  o.led_gain_spread_stops = 1;
  o.exposure_step_stops = 1;
  o.exposure_step_frames = 30;
  o.bloom_fraction = 0.15;
  o.exposure_s = 0.016;
  o.motion_blur_samples = 9;
  o.noise_sigma = 3;
  o.led_dropout_probability = 0.03;
  o.led_dropout_frames = 10;
  o.reflection_probability = 0.5;
  o.distractor_count = 4;
  o.distractor_led_like_fraction = 0.5;
  o.marker_white = 90;  // at +1 stop still below the LED threshold
  return o;
}

Constellation random_constellation(std::uint64_t seed) {
  Rng rng(seed, 0x7261'6e64'6f6dull /* "random" */);
  Constellation k;
  const int n = 5 + static_cast<int>(rng.uniform(0, 4));
  const bool planar = rng.uniform() < 0.5;
  const Eigen::Vector3d f = normal_vector3(rng).normalized();
  const Eigen::Vector3d u = f.unitOrthogonal(), v = f.cross(u);
  constexpr std::array<LedColor, 4> colours{LedColor::Red, LedColor::Green, LedColor::Blue, LedColor::White};
  while (true) {
    k.leds.clear();
    for (int i = 0; i < n; ++i) {
      Led led;
      for (int tries = 0; tries < 100; ++tries) {
        // Drawn last term first, the order of the recorded constellations.
        const double along = rng.uniform(-1, 1), across_v = rng.uniform(-0.075, 0.075);
        const double across_u = rng.uniform(-0.1, 0.1);
        led.p_body = 0.1 * f + across_u * u + across_v * v + along * (planar ? 0.0025 : 0.03) * f;
        bool apart = true;
        for (const auto& other : k.leds) apart = apart && (other.p_body - led.p_body).norm() > 0.03;
        if (apart) break;
      }
      led.color = colours[static_cast<std::size_t>(rng.uniform(0, 4))];
      led.normal = f;
      led.half_angle_deg = rng.uniform(50, 90);
      k.leds.push_back(led);
    }
    if (k.validate(nullptr)) return k;  // else (collinear, too close: rare) draw again
  }
}

// ---- the camera ----------------------------------------------------------------

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
  void render_leds(const Eigen::Isometry3d* poses, int n, const Extras& extras, double exposure,
                   std::vector<float>& signal, RenderedFrame& out) const;
  bool render_marker(const Eigen::Isometry3d* poses, int n, double exposure, std::vector<float>& signal,
                     Scratch& s) const;
};

SyntheticCamera::SyntheticCamera(CameraModel camera, Constellation constellation, RenderOptions options)
    : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!camera.validate(&why)) throw InvalidArgument("SyntheticCamera: camera: " + why);
  if (const long long pixels = static_cast<long long>(camera.width) * camera.height; pixels > kMaxPixels) {
    throw InvalidArgument("SyntheticCamera: camera: " + std::to_string(camera.width) + " x " +
                          std::to_string(camera.height) + " = " + std::to_string(pixels) +
                          " pixels is more than the renderer's limit of " + std::to_string(kMaxPixels) +
                          " (4096 x 4096)");
  }
  if (!constellation.validate(&why)) throw InvalidArgument("SyntheticCamera: constellation: " + why);
  if (!options.validate(&why)) throw InvalidArgument("SyntheticCamera: options: " + why);
  impl_->camera = std::move(camera);
  impl_->constellation = std::move(constellation);
  impl_->options = std::move(options);
  const CameraModel& c = impl_->camera;
  if (c.has_distortion()) {
    impl_->rays.resize(2 * static_cast<std::size_t>(c.width) * static_cast<std::size_t>(c.height));
    std::size_t i = 0;
    for (int y = 0; y < c.height; ++y) {
      for (int x = 0; x < c.width; ++x) {
        const Eigen::Vector2d p = c.undistort(Eigen::Vector2d(x, y));
        impl_->rays[i++] = static_cast<float>((p.x() - c.cx) / c.fx);
        impl_->rays[i++] = static_cast<float>((p.y() - c.cy) / c.fy);
      }
    }
  }
  const RenderOptions& o = impl_->options;
  const std::vector<float>& table = normal_table();
  for (std::size_t i = 0; i < table.size(); ++i) {
    impl_->background_dn[i] =
        colour_dn(static_cast<float>(o.background_level), 0.0f, static_cast<float>(o.noise_sigma) * table[i]);
    impl_->ceiling_depth[i] = depth_units(static_cast<float>(o.ceiling_distance), static_cast<float>(o.depth_noise_k),
                                          table[i], static_cast<float>(1 / c.depth_scale));
  }
  const ArucoDictionaryInfo& dict = *find_aruco_dictionary(o.aruco_dictionary);
  const int side = dict.bits + 2;  // marker cells including the black border
  cv::Mat marker;
  cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(dict.opencv_id), o.aruco_id, side, marker, 1);
  impl_->card_cells = side + 2;
  impl_->cell_size = o.aruco_size / side;
  impl_->card.assign(static_cast<std::size_t>(impl_->card_cells * impl_->card_cells), 255);
  for (int r = 0; r < side; ++r) {
    for (int col = 0; col < side; ++col) {
      impl_->card[static_cast<std::size_t>((r + 1) * impl_->card_cells + col + 1)] = marker.at<std::uint8_t>(r, col);
    }
  }
}

SyntheticCamera::~SyntheticCamera() = default;
SyntheticCamera::SyntheticCamera(SyntheticCamera&&) noexcept = default;
SyntheticCamera& SyntheticCamera::operator=(SyntheticCamera&&) noexcept = default;
const CameraModel& SyntheticCamera::camera() const { return impl_->camera; }
const Constellation& SyntheticCamera::constellation() const { return impl_->constellation; }
const RenderOptions& SyntheticCamera::options() const { return impl_->options; }

void SyntheticCamera::Impl::led_extras(std::uint64_t seed, std::uint64_t frame_index, Rng& dropout_rng,
                                       Extras& extras) const {
  const RenderOptions& o = options;
  // Fixed per seed: every value is drawn whatever the options, so that one
  // option never changes another's draws.
  Rng rng(seed, 0xFFFFFFFFFFFF1EDBull);
  const auto runs = static_cast<std::uint64_t>(o.led_dropout_frames);
  for (std::size_t i = 0; i < constellation.leds.size(); ++i) {
    const Led& led = constellation.leds[i];
    LedExtras& e = extras[i];
    e.gain = std::exp2(o.led_gain_spread_stops * rng.uniform(-1, 1));
    e.reflection = rng.uniform() < o.reflection_probability;
    Eigen::Vector3d d = normal_vector3(rng);
    if (led.has_normal()) d -= d.dot(led.normal) * led.normal;  // along the airframe around the LED
    e.reflection_body = led.p_body + o.reflection_offset * d.normalized();
    const auto phase = static_cast<std::uint64_t>(rng.uniform(0, static_cast<double>(runs)));
    // Drawn for every LED every frame: stable streams.
    const bool single = dropout_rng.uniform() < o.led_dropout_probability;
    if (runs == 1) {
      e.dropped = single;
    } else {
      // Runs of led_dropout_frames frames, staggered per LED.
      Rng run(seed ^ 0x64726f70ull /* "drop" */, ((frame_index + phase) / runs) * kMaxLeds + i);
      e.dropped = run.uniform() < o.led_dropout_probability;
    }
  }
}

double SyntheticCamera::Impl::exposure(std::uint64_t seed, std::uint64_t frame_index) const {
  const int s = options.exposure_step_stops;
  if (s == 0) return 1;
  Rng rng(seed ^ 0x6578706full /* "expo" */, frame_index / static_cast<std::uint64_t>(options.exposure_step_frames));
  const int k = std::min(2 * s, static_cast<int>(rng.uniform(0, 2 * s + 1))) - s;
  return std::exp2(k);
}

void SyntheticCamera::Impl::render_depth_body(const Eigen::Isometry3d& T, const Extras& extras,
                                              std::vector<float>& zbuf) const {
  const RenderOptions& o = options;
  const int w = camera.width, h = camera.height;
  // The body box, by ray–box intersection in the body frame (slab method,
  // Kay & Kajiya 1986) over the bounding box of its projected corners.
  const Eigen::Vector3d lo(-o.body_half_size, -o.body_half_size, o.body_z_min);
  const Eigen::Vector3d hi(o.body_half_size, o.body_half_size, o.body_z_max);
  double umin = 1e300, vmin = 1e300, umax = -1e300, vmax = -1e300;
  bool in_front = o.body_half_size > 0;
  for (int i = 0; i < 8 && in_front; ++i) {
    const Eigen::Vector3d p_body(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
    const Eigen::Vector3d p = T * p_body;
    if (p.z() < kMinDepth) {
      in_front = false;
      break;
    }
    const Eigen::Vector2d uv = camera.project(p);
    umin = std::min(umin, uv.x()), umax = std::max(umax, uv.x());
    vmin = std::min(vmin, uv.y()), vmax = std::max(vmax, uv.y());
  }
  if (in_front) {
    // A few pixels of slack: with distortion the box's edges bow outward.
    const Window win = clip_window(umin - 3, vmin - 3, umax + 3, vmax + 3, w, h);
    const Eigen::Matrix3d Rt = T.linear().transpose();
    const Eigen::Vector3d o_body = -(Rt * T.translation());
    for (int y = win.y0; y <= win.y1; ++y) {
      for (int x = win.x0; x <= win.x1; ++x) {
        const Eigen::Vector2d r = ray(x, y);
        const Eigen::Vector3d d = Rt * Eigen::Vector3d(r.x(), r.y(), 1.0);  // camera z = 1: t is the depth
        double t0 = -1e300, t1 = 1e300;
        bool hit = true;
        for (int a = 0; a < 3 && hit; ++a) {
          if (std::abs(d[a]) < 1e-12) {
            hit = o_body[a] >= lo[a] && o_body[a] <= hi[a];
            continue;
          }
          double ta = (lo[a] - o_body[a]) / d[a], tb = (hi[a] - o_body[a]) / d[a];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
          hit = t0 <= t1;
        }
        if (!hit || t0 <= kMinDepth) continue;
        float& z = zbuf[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x];
        z = std::min(z, static_cast<float>(t0));
      }
    }
  }
  // A fronto-parallel disc around each LED at the LED's depth (its housing
  // and the arm under it), whether or not the LED is lit, and around each
  // reflection (the airframe surface it is seen on).
  for (std::size_t i = 0; i < 2 * constellation.leds.size(); ++i) {
    const std::size_t l = i % constellation.leds.size();
    const bool reflection = i >= constellation.leds.size();
    if (reflection && !extras[l].reflection) continue;
    const Eigen::Vector3d p = T * (reflection ? extras[l].reflection_body : constellation.leds[l].p_body);
    if (p.z() < kMinDepth || o.led_disc_radius <= 0) continue;
    const Eigen::Vector2d uv = camera.project(p);
    const double r = camera.fx * o.led_disc_radius / p.z();
    const Window win = clip_window(uv.x() - r, uv.y() - r, uv.x() + r, uv.y() + r, w, h);
    const auto z = static_cast<float>(p.z());
    for (int y = win.y0; y <= win.y1; ++y) {
      for (int x = win.x0; x <= win.x1; ++x) {
        const double dx = x - uv.x(), dy = y - uv.y();
        if (dx * dx + dy * dy > r * r) continue;
        float& zb = zbuf[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x];
        zb = std::min(zb, z);
      }
    }
  }
}

void SyntheticCamera::Impl::render_lamps(std::uint64_t seed, double exposure, std::vector<float>& signal,
                                         std::vector<float>& zbuf) const {
  const RenderOptions& o = options;
  const int w = camera.width, h = camera.height;
  // Lamps are fixed per seed (a stream no frame index uses in practice).
  Rng rng(seed, 0xFFFFFFFFFFFF1A3Bull);
  for (int i = 0; i < o.distractor_count; ++i) {
    const double u = rng.uniform(0, w), v = rng.uniform(0, h);
    const double z = rng.uniform(o.distractor_min_depth, o.distractor_max_depth);
    double radius = rng.uniform(6, 14);   // [px] larger than any LED spot
    double gain = rng.uniform(0.6, 3.0);  // >= 1 saturates the core
    const bool yellowish = rng.uniform() < 0.5;
    Bgr c = yellowish ? Bgr{150, 225, 255} : Bgr{255, 255, 255};
    if (o.distractor_led_like_fraction > 0) {  // extra draws only then: the clean lamps stay put
      const bool led_like = rng.uniform() < o.distractor_led_like_fraction;
      const double size = rng.uniform(2, 5), led_gain = rng.uniform(1, 6);
      const auto cls = static_cast<LedColor>(static_cast<int>(rng.uniform(0, 4)));
      if (led_like) radius = size, gain = led_gain, c = core_colour(cls);
    }
    gain *= exposure;
    const double sigma = radius / 2;
    const double inv2s2 = 1 / (2 * sigma * sigma);
    const double extent = 3 * sigma;
    const Window win = clip_window(u - extent, v - extent, u + extent, v + extent, w, h);
    const auto zf = static_cast<float>(z);
    for (int y = win.y0; y <= win.y1; ++y) {
      for (int x = win.x0; x <= win.x1; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x;
        if (zbuf[p] < zf) continue;  // hidden behind the drone (or a nearer lamp)
        const double d2 = (x - u) * (x - u) + (y - v) * (y - v);
        const double lit = gain * std::exp(-d2 * inv2s2);
        const auto e = static_cast<float>(o.white_cores ? lit : std::min(1.0, lit));
        signal[3 * p] += c.b * e;
        signal[3 * p + 1] += c.g * e;
        signal[3 * p + 2] += c.r * e;
      }
    }
    for (int y = win.y0; y <= win.y1; ++y) {
      for (int x = win.x0; x <= win.x1; ++x) {
        const double d2 = (x - u) * (x - u) + (y - v) * (y - v);
        if (d2 > radius * radius) continue;
        float& zb = zbuf[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x];
        zb = std::min(zb, zf);
      }
    }
  }
}

void SyntheticCamera::Impl::render_leds(const Eigen::Isometry3d* poses, int n, const Extras& extras, double exposure,
                                        std::vector<float>& signal, RenderedFrame& out) const {
  const RenderOptions& o = options;
  const int w = camera.width, h = camera.height;
  const Eigen::Isometry3d& T = poses[n / 2];  // the frame's pose (centre of the exposure)
  const std::size_t count = constellation.leds.size();
  out.led_visible.assign(count, false);
  out.led_merged.assign(count, false);
  const Eigen::Vector3d camera_body = -(T.linear().transpose() * T.translation());
  // The lit disc of every drawn spot, for the merge flags: LED i's spot, or
  // (led = i + count) its reflection's.
  struct Lit {
    Eigen::Vector2d uv;
    double radius;
    std::size_t led;
  };
  std::array<Lit, 2 * kMaxLeds> lit{};
  std::size_t lit_count = 0;
  const double threshold = std::max(1.0, o.merge_threshold_dn - o.background_level);
  std::array<Eigen::Vector2d, kMaxBlurSamples> centres;

  // Radius of the disc where a spot's brightest channel reaches the
  // threshold (its peak is 255·gain, clipped at 255 without white cores).
  auto lit_radius = [&](double sigma, double gain) {
    const double peak = 255 * (o.white_cores ? gain : std::min(1.0, gain));
    return peak > threshold ? sigma * std::sqrt(2 * std::log(peak / threshold)) : 0.0;
  };

  // One Gaussian spot of peak `gain` (relative to saturation) and sigma
  // `sigma` [px] with its bloom, smeared over the exposure samples of the
  // body point `p_body` (centred on `uv`, its image at the frame's pose).
  auto draw_spot = [&](const Eigen::Vector3d& p_body, const Eigen::Vector2d& uv, double sigma, double gain,
                       double bloom_fraction, Bgr c) {
    double umin = uv.x(), umax = uv.x(), vmin = uv.y(), vmax = uv.y();
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d pk = poses[k] * p_body;
      centres[static_cast<std::size_t>(k)] = pk.z() >= kMinDepth ? camera.project(pk) : uv;
      umin = std::min(umin, centres[static_cast<std::size_t>(k)].x());
      umax = std::max(umax, centres[static_cast<std::size_t>(k)].x());
      vmin = std::min(vmin, centres[static_cast<std::size_t>(k)].y());
      vmax = std::max(vmax, centres[static_cast<std::size_t>(k)].y());
    }
    // White cores: light linear per channel, clipped by the sensor (so the
    // halo's extent grows with the gain); else clipped to the core colour.
    const double wide = o.white_cores ? lit_radius(sigma, gain) : 0;
    const double extent = std::max(3.5 * std::max(sigma, bloom_fraction > 0 ? o.bloom_sigma : 0.0), wide + 3 * sigma);
    const Window win = clip_window(umin - extent, vmin - extent, umax + extent, vmax + extent, w, h);
    const double inv2s2 = 1 / (2 * sigma * sigma), inv2b2 = 1 / (2 * o.bloom_sigma * o.bloom_sigma);
    const double g = gain / n, bloom = bloom_fraction / n;
    for (int y = win.y0; y <= win.y1; ++y) {
      for (int x = win.x0; x <= win.x1; ++x) {
        double e = 0, b = 0;
        for (int k = 0; k < n; ++k) {
          const double dx = x - centres[static_cast<std::size_t>(k)].x(),
                       dy = y - centres[static_cast<std::size_t>(k)].y();
          const double d2 = dx * dx + dy * dy;
          e += std::exp(-d2 * inv2s2);
          if (bloom > 0) b += std::exp(-d2 * inv2b2);
        }
        const auto v = static_cast<float>((o.white_cores ? g * e : std::min(1.0, g * e)) + bloom * b);
        if (v < 1e-4f) continue;
        const std::size_t p3 = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x);
        signal[p3] += c.b * v;
        signal[p3 + 1] += c.g * v;
        signal[p3 + 2] += c.r * v;
      }
    }
  };

  for (std::size_t i = 0; i < count; ++i) {
    const Led& led = constellation.leds[i];
    const Eigen::Vector3d p = T * led.p_body;
    if (extras[i].dropped || p.z() < kMinDepth) continue;
    const Eigen::Vector2d uv = camera.project(p);
    if (!in_image(uv)) continue;
    // Emission geometry: the camera must lie in the LED's emission cone.
    if (!led.emits_toward(camera_body)) continue;
    out.led_visible[i] = true;
    // Spot: the LED's image disc (radius f·r/z, variance r²/4 per axis)
    // convolved with the optics' Gaussian blur.
    const double r_px = camera.fx * o.led_radius / p.z();
    const double sigma = std::sqrt(o.optics_blur_sigma * o.optics_blur_sigma + r_px * r_px / 4);
    const double gain = o.led_gain * extras[i].gain * exposure;
    draw_spot(led.p_body, uv, sigma, gain, o.bloom_fraction * exposure, core_colour(led.color));
    lit[lit_count++] = {uv, lit_radius(sigma, gain), i};
    if (!extras[i].reflection) continue;
    // Its reflection off the airframe: wider, no bloom, and returning
    // reflection_gain of the LED's light (a Gaussian spot's light is
    // gain·2πσ², so the wider spot's peak is lower by (σ/σ_q)²).
    const Eigen::Vector3d q = T * extras[i].reflection_body;
    if (q.z() < kMinDepth) continue;
    const Eigen::Vector2d uv_q = camera.project(q);
    const double sigma_q = 1.5 * sigma + 1;
    const double gain_q = o.reflection_gain * gain * (sigma / sigma_q) * (sigma / sigma_q);
    draw_spot(extras[i].reflection_body, uv_q, sigma_q, gain_q, 0, core_colour(led.color));
    lit[lit_count++] = {uv_q, lit_radius(sigma_q, gain_q), i + count};
  }
  // Merged: two lit discs touch (8-connected pixels: within 1.5 px).
  for (std::size_t a = 0; a < lit_count; ++a) {
    for (std::size_t b = a + 1; b < lit_count; ++b) {
      if (lit[a].radius <= 0 || lit[b].radius <= 0) continue;
      if ((lit[a].uv - lit[b].uv).norm() > lit[a].radius + lit[b].radius + 1.5) continue;
      out.led_merged[lit[a].led % count] = true;
      out.led_merged[lit[b].led % count] = true;
    }
  }
}

bool SyntheticCamera::Impl::render_marker(const Eigen::Isometry3d* poses, int n, double exposure,
                                          std::vector<float>& signal, Scratch& s) const {
  const RenderOptions& o = options;
  const int w = camera.width, h = camera.height;
  const double half = o.aruco_size / 2;       // the marker's outer black square
  const double card_half = half + cell_size;  // with the white margin
  const Eigen::Isometry3d T_cm = poses[n / 2] * constellation.T_body_marker;
  // Drawn only when its face (marker +z) points toward the camera.
  if (!(T_cm.linear().col(2).dot(T_cm.translation()) < 0)) return false;
  double umin = 1e300, vmin = 1e300, umax = -1e300, vmax = -1e300;
  for (int k = 0; k < n; ++k) {
    const Eigen::Isometry3d Tk = poses[k] * constellation.T_body_marker;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d p = Tk * Eigen::Vector3d(c & 1 ? card_half : -card_half, c & 2 ? card_half : -card_half, 0);
      if (p.z() < kMinDepth) return false;
      const Eigen::Vector2d uv = camera.project(p);
      umin = std::min(umin, uv.x()), umax = std::max(umax, uv.x());
      vmin = std::min(vmin, uv.y()), vmax = std::max(vmax, uv.y());
    }
  }
  bool visible = true;  // OpenCV's corner order: (-s/2, s/2), (s/2, s/2), (s/2, -s/2), (-s/2, -s/2)
  for (const auto& corner : {Eigen::Vector3d(-half, half, 0), Eigen::Vector3d(half, half, 0),
                             Eigen::Vector3d(half, -half, 0), Eigen::Vector3d(-half, -half, 0)}) {
    visible = visible && in_image(camera.project(T_cm * corner));
  }
  const double pad = 3 + 3 * o.optics_blur_sigma;
  const Window win = clip_window(umin - pad, vmin - pad, umax + pad, vmax + pad, w, h);
  if (win.empty()) return visible;

  // Per exposure sample: the inverse of the homography H = [c·r1, −c·r2,
  // t + h·(r2 − r1)] that maps card cell coordinates (column, row, 1) to the
  // normalised ray of their point (Hartley & Zisserman 2004, sec. 2.3 and
  // 8.1.1: a plane's image is a homography); G·ray = (column, row, 1)/z, so
  // the third component is positive exactly in front of the camera.
  std::array<Eigen::Matrix3d, kMaxBlurSamples> G;
  for (int k = 0; k < n; ++k) {
    const Eigen::Isometry3d Tk = poses[k] * constellation.T_body_marker;
    const Eigen::Vector3d r1 = Tk.linear().col(0), r2 = Tk.linear().col(1);
    Eigen::Matrix3d H;
    H.col(0) = cell_size * r1;
    H.col(1) = -cell_size * r2;
    H.col(2) = Tk.translation() + card_half * (r2 - r1);
    G[static_cast<std::size_t>(k)] = H.inverse();
  }
  // Area sampling (antialiasing) spread over space and exposure time: 3×3
  // sub-pixel rays without motion, else 2 per exposure sample (alternating
  // diagonals).
  struct Sample {
    double du, dv;
    int k;
  };
  std::array<Sample, 2 * kMaxBlurSamples> samples{};
  int count = 0;
  if (n == 1) {
    for (int i = 0; i < 9; ++i) samples[static_cast<std::size_t>(count++)] = {(i % 3 - 1) / 3.0, (i / 3 - 1) / 3.0, 0};
  } else {
    for (int k = 0; k < n; ++k) {
      const double flip = k % 2 ? -0.25 : 0.25;
      samples[static_cast<std::size_t>(count++)] = {-0.25, -flip, k};
      samples[static_cast<std::size_t>(count++)] = {0.25, flip, k};
    }
  }
  const int ww = win.x1 - win.x0 + 1, wh = win.y1 - win.y0 + 1;
  s.window.create(wh, ww, CV_32F);
  const auto bg = static_cast<float>(o.background_level);
  const float white = static_cast<float>(o.marker_white), black = static_cast<float>(o.marker_black);
  const double inv_samples = 1.0 / count;
  const double cells = card_cells;
  const auto gain = static_cast<float>(exposure);  // the card's light scales with the exposure
  for (int y = win.y0; y <= win.y1; ++y) {
    auto* row = s.window.ptr<float>(y - win.y0);
    for (int x = win.x0; x <= win.x1; ++x) {
      // The pixel's ray and its derivatives along u and v, for sub-pixel rays.
      Eigen::Vector2d r, ru, rv;
      if (rays.empty()) {
        r = ray(x, y);
        ru = {1 / camera.fx, 0};
        rv = {0, 1 / camera.fy};
      } else {
        auto at = [&](int xx, int yy) {
          const std::size_t i = 2 * (static_cast<std::size_t>(yy) * static_cast<std::size_t>(w) + xx);
          return Eigen::Vector2d(rays[i], rays[i + 1]);
        };
        r = at(x, y);
        ru = x + 1 < w ? Eigen::Vector2d(at(x + 1, y) - r) : Eigen::Vector2d(r - at(x - 1, y));
        rv = y + 1 < h ? Eigen::Vector2d(at(x, y + 1) - r) : Eigen::Vector2d(r - at(x, y - 1));
      }
      double acc = 0;
      for (int i = 0; i < count; ++i) {
        const Sample& smp = samples[static_cast<std::size_t>(i)];
        const Eigen::Vector2d q = r + smp.du * ru + smp.dv * rv;
        const Eigen::Vector3d m = G[static_cast<std::size_t>(smp.k)] * Eigen::Vector3d(q.x(), q.y(), 1.0);
        float value = bg;
        if (m.z() > 0) {
          const double col = m.x() / m.z(), rw = m.y() / m.z();
          if (col >= 0 && rw >= 0 && col < cells && rw < cells) {
            value = card[static_cast<std::size_t>(rw) * static_cast<std::size_t>(card_cells) +
                         static_cast<std::size_t>(col)]
                        ? white
                        : black;
          }
        }
        acc += value;
      }
      row[x - win.x0] = (static_cast<float>(acc * inv_samples) - bg) * gain;
    }
  }
  // The same optics blur as the LEDs (a thin lens blurs the whole image).
  cv::GaussianBlur(s.window, s.blurred, cv::Size(0, 0), o.optics_blur_sigma, o.optics_blur_sigma, cv::BORDER_REPLICATE);
  for (int y = win.y0; y <= win.y1; ++y) {
    const auto* row = s.blurred.ptr<float>(y - win.y0);
    for (int x = win.x0; x <= win.x1; ++x) {
      const float v = row[x - win.x0];
      const std::size_t p3 = 3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + x);
      signal[p3] += v;
      signal[p3 + 1] += v;
      signal[p3 + 2] += v;
    }
  }
  return visible;
}

void SyntheticCamera::render(const Eigen::Isometry3d& T_camera_body, const Eigen::Isometry3d& T_camera_body_previous,
                             std::uint64_t seed, std::uint64_t frame_index, RenderedFrame& out) const {
  if (!T_camera_body.matrix().allFinite() || !T_camera_body_previous.matrix().allFinite()) {
    throw InvalidArgument("SyntheticCamera::render: the pose is not finite");
  }
  const Impl& im = *impl_;
  const RenderOptions& o = im.options;
  const int w = im.camera.width, h = im.camera.height;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  Rng rng(seed, frame_index);
  // Independent streams per piece, so that changing one option (e.g. the
  // noise) never changes another piece's draws (e.g. the dropouts).
  Rng dropout_rng(rng.next()), noise_rng(rng.next()), depth_rng(rng.next());

  // Poses over the exposure, centred on the frame's pose: T(s) =
  // T·exp((s−1)ξ) with exp(ξ) = T_prev⁻¹·T, i.e. constant body velocity
  // (Barfoot 2017, sec. 7.1), s ∈ [1 − f/2, 1 + f/2], f = exposure·rate.
  std::array<Eigen::Isometry3d, kMaxBlurSamples> poses;
  int n = 1;
  poses[0] = T_camera_body;
  const Vector6d xi = se3_log(T_camera_body_previous.inverse() * T_camera_body);
  const double f = o.exposure_s * o.frame_rate_hz;
  if (o.motion_blur_samples > 1 && xi.norm() * f > 1e-9) {
    n = o.motion_blur_samples | 1;  // odd: the middle sample is the frame's pose
    if (n > kMaxBlurSamples) n -= 2;
    for (int k = 0; k < n; ++k) {
      const double s = f * (static_cast<double>(k) / (n - 1) - 0.5);
      poses[static_cast<std::size_t>(k)] =
          k == n / 2 ? T_camera_body : Eigen::Isometry3d(T_camera_body * se3_exp(s * xi));
    }
  }

  Scratch& s = scratch();
  // The buffers are left cleared by the previous frame's final passes
  // (saves a pass over 6 MB); re-clear after a size change or an exception.
  if (!s.clean || s.signal.size() != 3 * pixels) {
    s.signal.assign(3 * pixels, 0.0f);
    s.zbuf.assign(pixels, std::numeric_limits<float>::infinity());
  }
  s.clean = false;

  Impl::Extras extras;
  im.led_extras(seed, frame_index, dropout_rng, extras);
  const double exposure = im.exposure(seed, frame_index);
  im.render_depth_body(T_camera_body, extras, s.zbuf);
  im.render_lamps(seed, exposure, s.signal, s.zbuf);
  im.render_leds(poses.data(), n, extras, exposure, s.signal, out);
  out.marker_visible = o.render_marker && im.render_marker(poses.data(), n, exposure, s.signal, s);

  const std::vector<float>& table = normal_table();
  // Colour: background + light + sensor noise, rounded and clipped.
  out.colour.resize(w, h);
  {
    const auto bg = static_cast<float>(o.background_level), sigma = static_cast<float>(o.noise_sigma);
    std::uint8_t* dst = out.colour.pixels.data();
    float* src = s.signal.data();
    const std::size_t count = 3 * pixels;
    // Most pixels get no light: their value is a lookup.
    auto store = [&](std::size_t j, std::size_t noise_index) {
      if (src[j] == 0.0f) {
        dst[j] = im.background_dn[noise_index];
        return;
      }
      dst[j] = colour_dn(bg, src[j], sigma * table[noise_index]);
      src[j] = 0;
    };
    std::size_t i = 0;
    if (sigma > 0) {
      // Five 12-bit table indices per 64 random bits.
      for (; i + 5 <= count; i += 5) {
        const std::uint64_t r = noise_rng.next();
        for (std::size_t j = 0; j < 5; ++j) store(i + j, (r >> (12 * j)) & kTableMask);
      }
      const std::uint64_t r = noise_rng.next();
      for (std::size_t j = 0; i < count; ++i, ++j) store(i, (r >> (12 * j)) & kTableMask);
    } else {
      for (; i < count; ++i) store(i, 0);
    }
  }

  // Depth: nearest surface (body, lamp or ceiling) + noise σ = k·z²,
  // quantised to depth_scale; a fraction of pixels invalid (0).
  out.depth.resize(w, h);
  {
    const auto inv_scale = static_cast<float>(1 / im.camera.depth_scale);
    const auto invalid_below = static_cast<std::uint32_t>(std::min(65536.0, o.depth_invalid_fraction * 65536.0));
    const auto k = static_cast<float>(o.depth_noise_k);
    const bool noisy = k > 0 || invalid_below > 0;
    std::uint16_t* dst = out.depth.pixels.data();
    float* zbuf = s.zbuf.data();
    std::uint64_t r = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      // Per pixel 32 random bits: 16 for validity, 12 for the noise.
      if (noisy && (i & 1) == 0) r = depth_rng.next();
      const auto bits = static_cast<std::uint32_t>(r >> (32 * (i & 1)));
      const float zb = zbuf[i];
      zbuf[i] = std::numeric_limits<float>::infinity();
      if ((bits & 0xFFFF) < invalid_below) {
        dst[i] = 0;
        continue;
      }
      const std::size_t noise_index = (bits >> 16) & kTableMask;
      dst[i] = std::isinf(zb) ? im.ceiling_depth[noise_index] : depth_units(zb, k, table[noise_index], inv_scale);
    }
  }
  s.clean = true;
}

}  // namespace touchdown::pose
