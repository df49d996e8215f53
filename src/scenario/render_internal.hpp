#pragma once
/// \file
/// What the renderer's files (render*.cpp, camera.cpp) share: the ground
/// texture's size and memory layout, the near plane, the texture prefilter,
/// and the small per-pixel helpers. The helpers are inline here because the
/// ground, marker and glare kernels in several files call them per pixel and
/// must inline them to keep their speed.
///
/// The renderer's internals live in namespace render_detail (not in
/// scenario::detail), so that their names cannot collide with another file's
/// helpers in the same library.
#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <numbers>

namespace touchdown::scenario::render_detail {

inline constexpr double kPi = std::numbers::pi;

using Bgr = std::array<std::uint8_t, 3>;

// The ground texture: 2048² texels of 2.5 cm = 51.2 m, repeated (its noise
// and features are periodic, so the seams do not show).
inline constexpr int kGroundTexels = 2048;
inline constexpr double kGroundTexel = 0.025;
inline constexpr int kMarkerTexelsPerCell = 32;
inline constexpr double kNear = 0.05;       // near plane [m]
inline constexpr double kMaxGround = 1000;  // the ground ends (sky) 1 km away along the axis
// Texture prefilter width in pixel footprints. The sensor integrates each
// pixel over its whole area and the lens and demosaicing blur by about
// another pixel (a system PSF of σ ≈ 0.5–0.7 px, MTF50 near 0.3 cycles/px
// for small-drone cameras), so detail finer than about two footprints does
// not reach the image. Sampling the box-filtered mip level of twice the
// footprint renders that: without it, level 0 was chosen at 10 m (1.25
// texels per pixel) and per-texel grain reached the image at full contrast,
// unlike a real camera (and it tripled OpenCV's contour work on grass).
inline constexpr double kPrefilterFootprints = 2;
inline constexpr float kGlareCut = 0.85f;     // cos of the widest angle with visible glare (0.85^40 ≈ 0.002)
inline constexpr Bgr kSkyBgr{232, 205, 172};  // light blue, seen only at strong tilt

inline std::uint8_t sat8(double v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0) + 0.5); }
inline std::uint8_t sat8i(int v) { return static_cast<std::uint8_t>(std::clamp(v, 0, 255)); }

// Bilinear blend of two BGRA texels with weight t ∈ [0, 256] on b, two
// channels per 32-bit lane (no lane overflows: 255·256 < 2^16).
inline std::uint32_t lerp_bgra(std::uint32_t a, std::uint32_t b, std::uint32_t t) {
  const std::uint32_t s = 256 - t;
  const std::uint32_t rb = (((a & 0xFF00FFu) * s + (b & 0xFF00FFu) * t) >> 8) & 0xFF00FFu;
  const std::uint32_t ga = (((a >> 8) & 0xFF00FFu) * s + ((b >> 8) & 0xFF00FFu) * t) & 0xFF00FF00u;
  return rb | ga;
}

inline int floor_int(float v) {
  const int i = static_cast<int>(v);
  return i - (v < static_cast<float>(i) ? 1 : 0);
}

// floor(log2(q)) for q ≥ 1 from the float's exponent bits; 0 below 1.
inline int mip_level(float q, int levels) {
  if (!(q >= 1.0f)) return 0;
  const int e = static_cast<int>((std::bit_cast<std::uint32_t>(q) >> 23) & 0xFFu) - 127;
  return std::min(e, levels - 1);
}

// Texels stored in 4×4 blocks inside 32×32 tiles (4 KiB pages): the
// camera walks the texture in any direction (yaw), and a row-major 16 MiB
// texture read along a column misses cache and TLB on every pixel (measured
// 40 ns/pixel); swizzled, neighbours share cache lines and pages.
inline constexpr int kGroundTileShift = 6;  // log2(2048 / 32) tiles per row at level 0
inline std::size_t swizzle(unsigned u, unsigned v, int tile_shift) {
  return (static_cast<std::size_t>(((v >> 5) << tile_shift) | (u >> 5)) << 10) | (((v >> 2) & 7u) << 7) |
         (((u >> 2) & 7u) << 4) | ((v & 3u) << 2) | (u & 3u);
}

}  // namespace touchdown::scenario::render_detail
