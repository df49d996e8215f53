#pragma once
/// \file
/// The renderer's process-wide caches (render.cpp), for tests and benchmarks.
///
/// Building a map's texture (2048² texels, mip-mapped, with its snow/leaf
/// cover and wet darkening) takes a few hundred ms; a campaign constructs a
/// Renderer per scenario, often on the same map. Renderers therefore share
/// these textures, immutable, through a small thread-safe cache keyed by
/// everything a texture depends on (map, seed, ground snow, ground leaves,
/// wet darkening). A cached texture is bit-identical to a fresh one, so
/// results do not depend on the order renderers are built in.
#include <cstddef>

namespace touchdown::scenario::detail {

/// At most this many map textures stay cached (≈ 22 MiB each, ≈ 38 MiB
/// with ground cover); the least recently used one is dropped first.
/// Renderers keep the textures they use alive either way.
inline constexpr std::size_t kMapTextureCacheCapacity = 4;

/// Drops every cached texture and sensor-noise table (renderers keep theirs):
/// the next Renderer builds its own again (cold construction).
void clear_render_caches();

/// Map textures held by the cache now (≤ kMapTextureCacheCapacity).
std::size_t cached_map_textures();

}  // namespace touchdown::scenario::detail
