#include "touchdown/pose/sim/synthetic.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <utility>

#include "synthetic_impl.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/random_vector.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/se3.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::pose {

using namespace render_detail;  // NOLINT(google-build-using-namespace): this file's own private helpers

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
  if (!finite_nonneg(rolling_shutter_s) || rolling_shutter_s * frame_rate_hz > 1) {
    return fail("rolling_shutter_s: must be in [0, 1/frame_rate_hz] s");
  }
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
  im.render_leds(poses.data(), n, xi, extras, exposure, s.signal, out);
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