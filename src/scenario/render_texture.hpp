#pragma once
/// \file
/// The renderer's ground textures (render_texture.cpp): the two maps'
/// procedural textures (concrete, lawn), the ground cover's fixed layers
/// (snow field, leaf litter) and a scenario's cover sampled from them, the
/// wet darkening, mip chains and the swizzled texel layout the ground kernel
/// reads. All periodic over kGroundTexels, so the textures tile without seams.
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "scenario/render_internal.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario::render_detail {

/// Writes a square BGRA level to `dst`, swizzled.
void swizzle_into(const cv::Mat& bgra, std::uint32_t* dst);

/// The resolution of the periodic fields (fbm): a quarter of the texture's.
inline constexpr int kFieldRes = 512;

/// A 512² periodic field at texel (x, y) of the 2048² texture, bilinear.
inline float field_at(const cv::Mat& f, int x, int y) {
  constexpr float kScale = static_cast<float>(kFieldRes) / kGroundTexels;
  const float fx = (static_cast<float>(x) + 0.5f) * kScale - 0.5f, fy = (static_cast<float>(y) + 0.5f) * kScale - 0.5f;
  const int ix = floor_int(fx), iy = floor_int(fy);
  const float tx = fx - static_cast<float>(ix), ty = fy - static_cast<float>(iy);
  constexpr int m = kFieldRes - 1;
  const float* r0 = f.ptr<float>(iy & m);
  const float* r1 = f.ptr<float>((iy + 1) & m);
  const int x0 = ix & m, x1 = (ix + 1) & m;
  return (r0[x0] * (1 - tx) + r0[x1] * tx) * (1 - ty) + (r1[x0] * (1 - tx) + r1[x1] * tx) * ty;
}

/// Per-texel grain, about N(0, 1) (sum of four uniform bytes of a hash).
inline float grain_at(std::uint32_t seed, int x, int y) {
  std::uint32_t h =
      (static_cast<std::uint32_t>(x) * 0x9E3779B1u) ^ (static_cast<std::uint32_t>(y) * 0x85EBCA77u) ^ seed;
  h ^= h >> 15, h *= 0x2C1B3C6Du, h ^= h >> 12, h *= 0x297A2D39u, h ^= h >> 15;
  return (static_cast<float>((h & 255u) + ((h >> 8) & 255u) + ((h >> 16) & 255u) + (h >> 24)) - 510.0f) / 147.8f;
}

/// Concrete (city-like): tonal variation, aggregate grain, slab seams every
/// 3.2 m, worn paint (a yellow line, a dashed white line, parking stalls),
/// cracks and oil stains. Float BGR.
cv::Mat concrete_texture(cv::RNG& rng);

/// Lawn: grass with clumps, dry and lush patches, fine blade noise. Float BGR.
cv::Mat lawn_texture(cv::RNG& rng);

/// The ground cover's fixed layers, the same under every scenario: where
/// snow and leaves lie first (their coverage fields: a scenario covers the
/// texels whose field exceeds the quantile of its fraction), and the leaf
/// litter itself (the colour of the leaf owning each texel; alpha 255
/// inside a leaf, 0 in the gap between two).
struct CoverBase {
  cv::Mat snow_field, leaf_field;  // 512², periodic
  cv::Mat leaves;                  // BGRA 2048², periodic
  std::uint32_t grain_seed = 0;
};

/// Builds the cover's fixed layers (the same every time: a fixed seed).
std::shared_ptr<const CoverBase> build_cover_base();

/// Whether the ground has snow or leaf cover at all.
inline bool has_cover(const Weather& w) { return w.ground_snow > 0 || w.ground_leaves > 0; }

/// A scenario's snow cover and leaf litter: the fixed layers read `shift`
/// texels on, covered to the scenario's fractions. Periodic.
class CoverSampler {
 public:
  CoverSampler() = default;
  CoverSampler(const Weather& w, std::shared_ptr<const CoverBase> base, cv::Point shift);
  [[nodiscard]] bool empty() const { return !base_; }
  /// The cover at map texel (x, y): its colour (BGR) and how much it covers
  /// (0 bare ground … 1). False where it does not cover (everywhere when
  /// empty).
  bool at(int x, int y, cv::Vec3f* colour, float* alpha) const {
    if (!base_) return false;
    constexpr int mask = kGroundTexels - 1;
    const int xx = (x + shift_.x) & mask, yy = (y + shift_.y) & mask;
    float a_l = field_at(leaf_a_, xx, yy);
    const float a_s = field_at(snow_a_, xx, yy);
    if (a_l <= 0 && a_s <= 0) return false;
    const cv::Vec4b lf = base_->leaves.at<cv::Vec4b>(yy, xx);
    if (lf[3] == 0) a_l *= 0.3f;  // the gap between two leaves
    *alpha = 1 - (1 - a_s) * (1 - a_l);
    if (*alpha <= 0) return false;
    const cv::Vec3f snow(238, 238, 234);
    const float g = grain_at(base_->grain_seed, xx, yy);
    *colour = (snow * (1.0f + 0.02f * g) * (a_s * (1 - a_l)) + cv::Vec3f(lf[0], lf[1], lf[2]) * a_l) / *alpha;
    return true;
  }

 private:
  std::shared_ptr<const CoverBase> base_;
  cv::Point shift_;
  cv::Mat snow_a_, leaf_a_;  // coverage, 512²
};

/// Wet surfaces look darker: light is trapped in the water film by total
/// internal reflection (Lekner & Dorf 1988); up to ~35 % darker.
float wet_darkening(const Weather& w);

/// Halving mip chain of a BGRA image (box filter, exact for periodic maps).
std::vector<cv::Mat> mip_chain(const cv::Mat& level0, int min_side);

}  // namespace touchdown::scenario::render_detail
