// The renderer's weather as image effects (pass 5; render.cpp has the whole
// frame): wet-ground glare, fog and dust, motion blur, rain, snow, falling
// leaves and low light. Ground snow, leaf litter and wetness are in the
// textures (render_texture.cpp, render_marker.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "scenario/render_impl.hpp"
#include "scenario/render_kernels.hpp"

namespace touchdown::scenario {

using render_detail::add_row;
using render_detail::average_row;
using render_detail::blur_divisor_mul;
using render_detail::fog_row;
using render_detail::kGlareCut;
using render_detail::kNear;
using render_detail::low_light_row;
using render_detail::rain_row;
using render_detail::sat8i;

// Wet-ground glare: the sun's mirror image in the water film, a Blinn–Phong
// style lobe about the mirror direction of the view ray (sharp core from a
// smooth film plus a broad lobe from the rough surface under it). Not where
// the sun is blocked (shadow_mask, when `shadows_on`).
void Renderer::Impl::glare_pass(Frame& fr, bool shadows_on) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  std::uint8_t* mask = fr.mask;
  const View& v = fr.v;
  if (!glare_add.empty()) {
    const float lx = static_cast<float>(sun.x()), ly = static_cast<float>(sun.y()), lz = static_cast<float>(sun.z());
    const float ax = static_cast<float>(v.A.x()), ay = static_cast<float>(v.A.y()), az = static_cast<float>(v.A.z());
    const float c2_min = glare_c2_min, c2_lo = kGlareCut * kGlareCut, scale = glare_scale;
    const float* table = glare_add.data();
    // m = the sun mirrored about the ground normal: a pixel can glare only
    // where (r·m)² ≥ c2_min·|r|² with r·m > 0, r = r0 + A·x along a row; a
    // quadratic in x, so each row is scanned only between its roots (widened
    // by two pixels: the per-pixel test below still decides every pixel).
    const Eigen::Vector3d mdir(sun.x(), sun.y(), -sun.z());
    const double am = v.A.dot(mdir), aa = v.A.squaredNorm();
    for (int y = 0; y < H; ++y) {
      const Eigen::Vector3d r0 = v.B * y + v.C;
      int xa = 0, xb = W;
      {
        // c slightly relaxed: float rounding in the per-pixel test cannot
        // pass a pixel outside the interval.
        const double bm = r0.dot(mdir), c = c2_min * (1 - 1e-5);
        const double qa = am * am - c * aa, qb = 2 * (am * bm - c * v.A.dot(r0)), qc = bm * bm - c * r0.squaredNorm();
        if (qa < 0) {  // the cone meets the row in one interval (or not at all)
          const double disc = qb * qb - 4 * qa * qc;
          if (disc < 0) continue;
          const double sq = std::sqrt(disc), x1 = (-qb + sq) / (2 * qa), x2 = (-qb - sq) / (2 * qa);
          const double lo = std::min(x1, x2) - 2, hi = std::max(x1, x2) + 2;
          if (hi < 0 || lo > W) continue;
          xa = static_cast<int>(std::max(0.0, std::floor(lo)));
          xb = static_cast<int>(std::min(static_cast<double>(W), std::ceil(hi) + 1));
        }
      }
      const float rx0 = static_cast<float>(r0.x()), ry0 = static_cast<float>(r0.y()), rz0 = static_cast<float>(r0.z());
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      const std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      const std::uint8_t* sm = shadows_on ? shadow_mask.ptr<std::uint8_t>(y) : nullptr;
      for (int x = xa; x < xb; ++x) {
        const float x_f = static_cast<float>(x);
        const float rx = rx0 + ax * x_f, ry = ry0 + ay * x_f, rz = rz0 + az * x_f;
        // Mirror of the (downward) ray about the ground normal, dotted with the sun.
        const float num = rx * lx + ry * ly - rz * lz;
        if (num <= 0) continue;
        const float len2 = rx * rx + ry * ry + rz * rz;
        if (num * num < c2_min * len2 || mk[x] > mask_value(Label::Distractor)) continue;
        if (sm && sm[x]) continue;  // the sun is blocked
        const float bin = (num * num / len2 - c2_lo) * scale;
        const auto i = static_cast<std::size_t>(bin);
        const float frac = bin - static_cast<float>(i);
        const int add = static_cast<int>(table[i] + (table[i + 1] - table[i]) * frac);
        px[3 * x] = sat8i(px[3 * x] + add * 15 / 16);  // sunlight: slightly warm
        px[3 * x + 1] = sat8i(px[3 * x + 1] + add);
        px[3 * x + 2] = sat8i(px[3 * x + 2] + add);
      }
    }
  }
}

// Fog and dust: Koschmieder's law per pixel, sky = airlight.
void Renderer::Impl::fog_pass(Frame& fr) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  float* depth = fr.depth;
  row_scratch.resize(static_cast<std::size_t>(W));
  if (beta > 1e-6) {
    const auto last = static_cast<float>(fog_t.size() - 1);
    const float scale = static_cast<float>(lut_scale);
    for (int y = 0; y < H; ++y) {
      fog_row(img.ptr<std::uint8_t>(y), depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W), W,
              fog_t.data(), scale, last, airlight.data(), row_scratch.data());
    }
  }
}

// Motion blur: the image moves by the ground's image velocity × exposure;
// average shifted copies along it (a box kernel along the motion).
void Renderer::Impl::motion_blur_pass(Frame& fr, const SceneState& state) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  const View& v = fr.v;
  const Eigen::Matrix3d& R_wc = fr.R_wc;
  if (cam.exposure_s > 0 && state.v_world.squaredNorm() > 0) {
    const Eigen::Vector3d axis = R_wc.col(2);
    if (axis.z() < -1e-6) {
      const Eigen::Vector3d p = v.c + (v.c.z() / -axis.z()) * axis;  // ground point on the optical axis
      const Eigen::Vector3d q1 = v.R_cw * (p - (v.c + state.v_world * cam.exposure_s));
      if (q1.z() > kNear) {
        const Eigen::Vector2d shift = project(q1) - Eigen::Vector2d(cx, cy);
        const double len = shift.norm();
        if (len > 1.5) {
          const int copies = std::min(9, static_cast<int>(std::ceil(len)) + 1);
          img.copyTo(blur_src);
          if (blur_acc.rows != H || blur_acc.cols != W) blur_acc.create(H, W, CV_16UC3);
          blur_acc.setTo(0);
          for (int k = 0; k < copies; ++k) {
            const Eigen::Vector2d s = shift * (static_cast<double>(k) / (copies - 1) - 0.5);
            // Clamped to the image: columns outside take the edge pixel.
            const int dx = std::clamp(static_cast<int>(std::lround(s.x())), -W, W);
            const int dy = static_cast<int>(std::lround(s.y()));
            const int xa = std::clamp(dx, 0, W), xb = std::clamp(W + dx, 0, W);  // x − dx inside [0, W)
            for (int y = 0; y < H; ++y) {
              const std::uint8_t* src = blur_src.ptr<std::uint8_t>(std::clamp(y - dy, 0, H - 1));
              std::uint16_t* acc = blur_acc.ptr<std::uint16_t>(y);
              for (int x = 0; x < xa; ++x) {
                for (int c = 0; c < 3; ++c) acc[3 * x + c] = static_cast<std::uint16_t>(acc[3 * x + c] + src[c]);
              }
              if (xb > xa) add_row(acc + 3 * xa, src + 3 * (xa - dx), 3 * (xb - xa));
              for (int x = std::max(xa, xb); x < W; ++x) {
                for (int c = 0; c < 3; ++c) {
                  acc[3 * x + c] = static_cast<std::uint16_t>(acc[3 * x + c] + src[3 * (W - 1) + c]);
                }
              }
            }
          }
          const auto n = static_cast<std::uint32_t>(copies);
          for (int y = 0; y < H; ++y) {
            average_row(img.ptr<std::uint8_t>(y), blur_acc.ptr<std::uint16_t>(y), 3 * W, n / 2, blur_divisor_mul(n));
          }
        }
      }
    }
  }
}

// Particles between the camera and the scene (rain, snow, falling leaves),
// drawn from `rng`.
void Renderer::Impl::particles_pass(Frame& fr, const SceneState& state, Rng& rng) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  float* depth = fr.depth;
  const View& v = fr.v;
  const Weather& weather = scenario.weather;
  const double exposure = std::max(cam.exposure_s, 1e-3);
  const auto sample = [&](double z_min, double z_max, Eigen::Vector3d& p) {
    const double u = rng.uniform(particles.u_lo, particles.u_hi), vv = rng.uniform(particles.v_lo, particles.v_hi);
    // Uniform in the frustum's volume (∝ z²): z³ uniform.
    const double z3 = z_min * z_min * z_min + rng.uniform() * (z_max * z_max * z_max - z_min * z_min * z_min);
    const double z = std::cbrt(z3);
    p = Eigen::Vector3d((u - cx) / f * z, (vv - cy) / f * z, z);
    const long xi = std::lround(u), yi = std::lround(vv);
    if (xi >= 0 && xi < W && yi >= 0 && yi < H) {
      return depth[static_cast<std::size_t>(yi) * static_cast<std::size_t>(W) + static_cast<std::size_t>(xi)] > z;
    }
    return true;
  };
  const auto to_fixed = [](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16)));
  };
  const auto on_screen = [&](const Eigen::Vector2d& p) {
    return std::abs(p.x()) < 4.0 * (W + H) && std::abs(p.y()) < 4.0 * (W + H);
  };
  // Rain: drops at terminal velocity (~6.5 m/s for 2 mm drops, Gunn &
  // Kinzer 1949) streak over the exposure; semi-transparent and bright
  // (they refract the sky).
  if (weather.rain > 0) {
    if (overlay.rows != H || overlay.cols != W) overlay.create(H, W, CV_8U);
    overlay.setTo(0);
    const int drops = static_cast<int>(std::lround(3000 * weather.rain * particles.scale));
    for (int i = 0; i < drops; ++i) {
      Eigen::Vector3d p;
      const bool visible = sample(0.3, 10, p);
      const Eigen::Vector3d vel(0, 0, -rng.uniform(5.5, 7.5));
      if (!visible) continue;
      const Eigen::Vector3d p1 = p + v.R_cw * (vel - state.v_world) * exposure;
      if (p1.z() < kNear) continue;
      const Eigen::Vector2d a = project(p), b = project(p1);
      if (!on_screen(a) || !on_screen(b)) continue;
      const double level = std::min(1.0, 0.25 + 0.5 / p.z());
      cv::line(overlay, to_fixed(a), to_fixed(b), cv::Scalar(255 * level), p.z() < 1.5 ? 2 : 1, cv::LINE_AA, 4);
    }
    for (int y = 0; y < H; ++y) rain_row(img.ptr<std::uint8_t>(y), overlay.ptr<std::uint8_t>(y), W);
  }
  // Snow: flakes of 3–10 mm falling at ~1 m/s with some flutter.
  if (weather.snow > 0) {
    const int flakes = static_cast<int>(std::lround(2500 * weather.snow * particles.scale));
    for (int i = 0; i < flakes; ++i) {
      Eigen::Vector3d p;
      const bool visible = sample(0.3, 12, p);
      const double fall = rng.uniform(0.7, 1.3), drift_y = rng.normal(0, 0.3);  // drawn z first
      const Eigen::Vector3d vel(rng.normal(0, 0.3), drift_y, -fall);
      const double size = rng.uniform(0.004, 0.014);
      const double grey = rng.uniform(225, 252);
      if (!visible) continue;
      const Eigen::Vector3d p1 = p + v.R_cw * (vel - state.v_world) * exposure;
      if (p1.z() < kNear) continue;
      const Eigen::Vector2d a = project(p), b = project(p1);
      if (!on_screen(a) || !on_screen(b)) continue;
      const double r = std::max(0.6, f * size / (2 * p.z()));
      const cv::Scalar colour(grey, grey, grey);
      if ((b - a).norm() > r) {
        cv::line(img, to_fixed(a), to_fixed(b), colour, std::max(1, static_cast<int>(2 * r)), cv::LINE_AA, 4);
      } else {
        cv::circle(img, to_fixed(a), static_cast<int>(std::lround(r * 16)), colour, -1, cv::LINE_AA, 4);
      }
    }
  }
  // Falling leaves: 4–8 cm, opaque, autumn colours.
  if (weather.leaves > 0) {
    const int leaves = static_cast<int>(std::lround(40 * weather.leaves * particles.scale));
    static constexpr std::array<std::array<double, 3>, 4> kLeaf{
        {{30, 95, 200}, {40, 175, 215}, {35, 65, 115}, {35, 45, 165}}};
    for (int i = 0; i < leaves; ++i) {
      Eigen::Vector3d p;
      const bool visible = sample(0.5, 15, p);
      const double size = rng.uniform(0.04, 0.08), angle = rng.uniform(0, 180), shade = rng.uniform(0.6, 1.1);
      const auto& c = kLeaf[static_cast<std::size_t>(rng.next() % kLeaf.size())];
      if (!visible) continue;
      const Eigen::Vector2d a = project(p);
      const double ax = f * size / (2 * p.z());
      cv::ellipse(img, to_fixed(a),
                  cv::Size(static_cast<int>(std::lround(ax * 16)), static_cast<int>(std::lround(ax * 8))), angle, 0,
                  360, cv::Scalar(c[0] * shade, c[1] * shade, c[2] * shade), -1, cv::LINE_AA, 4);
    }
  }
}

// Low light: auto-gain brightness and amplified sensor noise (a noise tile
// at a random offset per frame: cheap, and no two frames alike).
void Renderer::Impl::low_light_pass(Frame& fr, Rng& rng) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  if (low_light) {
    const int ox = static_cast<int>(rng.next() & 255u), oy = static_cast<int>(rng.next() & 255u);
    for (int y = 0; y < H; ++y) {
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      const auto* noise = noise_tile.ptr<std::int16_t>((y + oy) & 255);
      // The tile repeats every 256 columns: contiguous runs up to its edge.
      for (int x = 0; x < W;) {
        const int nx = (x + ox) & 255, run = std::min(W - x, 256 - nx);
        low_light_row(px + 3 * x, noise + 3 * nx, 3 * run, gain);
        x += run;
      }
    }
  }
}

}  // namespace touchdown::scenario
