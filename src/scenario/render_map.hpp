#pragma once
/// \file
/// A map's texture as the renderer samples it, and where a scenario lies on
/// its map: built once and shared by the process-wide caches in
/// render_cache.cpp (render_cache.hpp has their test interface).
#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "scenario/render_texture.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario::render_detail {

/// Bitwise equality of doubles: a NaN key finds itself.
inline bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

/// Everything a map texture depends on.
struct MapTextureKey {
  MapKind map = MapKind::Ground;
  std::uint64_t seed = 0;
  double ground_snow = 0, ground_leaves = 0;
  float dark = 1;  // wet darkening
  bool operator==(const MapTextureKey& o) const {
    return map == o.map && seed == o.seed && same_bits(ground_snow, o.ground_snow) &&
           same_bits(ground_leaves, o.ground_leaves) &&
           std::bit_cast<std::uint32_t>(dark) == std::bit_cast<std::uint32_t>(o.dark);
  }
};

/// The ground texture (BGRA mips ≥ 32², one after the other, periodic,
/// swizzled) and the cover the markers sample (empty without cover).
struct MapTexture {
  std::unique_ptr<std::uint32_t[]> texels;
  std::array<std::uint32_t, 8> offsets{};
  int levels = 0;
  CoverSampler cover;
};

/// Where on its map a scenario lies and where on the fixed cover layers its
/// cover is read [texels, in [0, 2048)], from its seed: one periodic map
/// gives 2048² scenes, each with a cover pattern of its own.
struct MapPlacement {
  cv::Point ground, cover;
};
MapPlacement map_placement(std::uint64_t seed);

/// The texture of `key`, shared: built on the first call (by one caller
/// while the others wait), then kept while it is among the
/// detail::kMapTextureCacheCapacity most recently used.
std::shared_ptr<const MapTexture> shared_map_texture(const MapTextureKey& key);

/// Unit normal draws of the low-light noise tile (256² × 3), from the seed.
inline constexpr int kNoiseTile = 256;
std::shared_ptr<const std::vector<double>> shared_unit_noise(std::uint64_t seed);

}  // namespace touchdown::scenario::render_detail
