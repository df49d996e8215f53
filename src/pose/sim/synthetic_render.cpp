#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "synthetic_impl.hpp"
#include "touchdown/pose/se3.hpp"

// The synthetic camera's drawing passes (synthetic_impl.hpp); the frame's
// set-up and final passes are in synthetic.cpp.
namespace touchdown::pose {

using namespace render_detail;  // NOLINT(google-build-using-namespace): this file's own private helpers

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

void SyntheticCamera::Impl::render_leds(const Eigen::Isometry3d* poses, int n, const Vector6d& xi, const Extras& extras,
                                        double exposure, std::vector<float>& signal, RenderedFrame& out) const {
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
    // Rolling shutter: the spot's row was read δ after the frame's time;
    // its poses move on by δ along the same constant velocity.
    Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
    if (o.rolling_shutter_s > 0 && h > 1) {
      const double delta = o.rolling_shutter_s * (uv.y() / (h - 1) - 0.5);
      shift = se3_exp(delta * o.frame_rate_hz * xi);
    }
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d pk = poses[k] * (shift * p_body);
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

}  // namespace touchdown::pose
