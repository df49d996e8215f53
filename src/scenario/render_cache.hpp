#pragma once
/// \file
/// The renderer's process-wide caches (render_cache.cpp), for tests and benchmarks.
///
/// Each map's ground and the cover layers are built once (a few hundred
/// ms); a scenario's texture (2048² texels, mip-mapped, with its snow/leaf
/// cover and wet darkening) is composed from them, and every dry scenario
/// of a map uses the ground as it is. Renderers share these textures,
/// immutable, through small thread-safe caches keyed by everything a
/// texture depends on (map, ground snow, ground leaves, wet darkening, and
/// the seed when there is cover). A cached texture is bit-identical to a
/// fresh one, so results do not depend on the order renderers are built in.
#include <cstddef>

namespace touchdown::scenario::detail {

/// At most this many map textures stay cached (≈ 22 MiB each, ≈ 38 MiB
/// with ground cover); the least recently used one is dropped first.
/// Renderers keep the textures they use alive either way.
inline constexpr std::size_t kMapTextureCacheCapacity = 4;

/// Drops every cached texture, map ground, cover layer and sensor-noise
/// table (renderers keep theirs):
/// the next Renderer builds its own again (cold construction).
void clear_render_caches();

/// Map textures held by the cache now (≤ kMapTextureCacheCapacity).
std::size_t cached_map_textures();

}  // namespace touchdown::scenario::detail
