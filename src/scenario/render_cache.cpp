// The renderer's process-wide caches (render_cache.hpp for tests,
// render_map.hpp for the renderer): the maps' grounds, the cover layers, the
// composed map textures and the low-light noise tables.
#include "scenario/render_cache.hpp"

#include <algorithm>
#include <future>
#include <mutex>

#include "scenario/render_map.hpp"
#include "touchdown/core/random.hpp"

namespace touchdown::scenario {

namespace render_detail {

namespace {

/// A small LRU cache of immutable values shared between threads. The first
/// caller of a key builds the value outside the lock; callers of the same
/// key meanwhile wait for it instead of building it again.
template <class Key, class Value>
class SharedCache {
 public:
  using Ptr = std::shared_ptr<const Value>;
  explicit SharedCache(std::size_t capacity) : capacity_(capacity) {}

  template <class Build>
  Ptr get(const Key& key, Build&& build) {
    std::promise<Ptr> promise;
    std::shared_future<Ptr> value;
    std::uint64_t id = 0;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      for (Entry& e : entries_) {
        if (e.key == key) {
          e.used = ++clock_;
          value = e.value;
          break;
        }
      }
      if (!value.valid()) {
        if (entries_.size() >= capacity_) {
          entries_.erase(std::min_element(entries_.begin(), entries_.end(),
                                          [](const Entry& a, const Entry& b) { return a.used < b.used; }));
        }
        value = promise.get_future().share();
        id = ++clock_;
        entries_.push_back({key, value, id, id});
      }
    }
    if (id != 0) {
      try {
        promise.set_value(build());
      } catch (...) {
        {
          const std::lock_guard<std::mutex> lock(mutex_);
          std::erase_if(entries_, [&](const Entry& e) { return e.id == id; });
        }
        promise.set_exception(std::current_exception());
      }
    }
    return value.get();
  }

  void clear() {
    const std::lock_guard<std::mutex> lock(mutex_);
    entries_.clear();
  }
  std::size_t size() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return entries_.size();
  }

 private:
  struct Entry {
    Key key;
    std::shared_future<Ptr> value;
    std::uint64_t id = 0, used = 0;
  };
  std::mutex mutex_;
  std::vector<Entry> entries_;
  std::uint64_t clock_ = 0;
  std::size_t capacity_;
};

/// A map kind's ground, the same under every scenario on it (the source's
/// two maps are fixed worlds): built once, from the map's own seed.
std::shared_ptr<const cv::Mat> build_map_ground(MapKind map) {
  cv::RNG rng(map == MapKind::Ground ? 0x6A09E667ull : 0xBB67AE85ull);
  return std::make_shared<const cv::Mat>(map == MapKind::Ground ? concrete_texture(rng) : lawn_texture(rng));
}

SharedCache<MapKind, cv::Mat>& map_ground_cache() {
  static SharedCache<MapKind, cv::Mat> cache(2);  // 16 MiB each
  return cache;
}
SharedCache<int, CoverBase>& cover_base_cache() {
  static SharedCache<int, CoverBase> cache(1);  // 16.5 MiB
  return cache;
}

}  // namespace

MapPlacement map_placement(std::uint64_t seed) {
  static_assert(kGroundTexels == 1 << 11);
  Rng rng(seed, 0x9A9A0ull);
  const auto draw = [&] { return static_cast<int>(rng.next() >> 53); };
  MapPlacement p;
  p.ground.x = draw(), p.ground.y = draw();
  p.cover.x = draw(), p.cover.y = draw();
  return p;
}

namespace {

std::shared_ptr<const MapTexture> build_map_texture(const MapTextureKey& key) {
  auto out = std::make_shared<MapTexture>();
  Weather w;
  w.ground_snow = key.ground_snow;
  w.ground_leaves = key.ground_leaves;
  const std::shared_ptr<const cv::Mat> ground =
      map_ground_cache().get(key.map, [&] { return build_map_ground(key.map); });
  if (has_cover(w))
    out->cover =
        CoverSampler(w, cover_base_cache().get(0, [] { return build_cover_base(); }), map_placement(key.seed).cover);
  const CoverSampler& cover = out->cover;
  const float dark = key.dark;
  cv::Mat tex = *ground;  // shared, read only
  if (!cover.empty() || dark < 1) {
    tex = cv::Mat(kGroundTexels, kGroundTexels, CV_8UC4);  // a buffer of its own: the ground stays as it is
    for (int y = 0; y < kGroundTexels; ++y) {
      const cv::Vec4b* g = ground->ptr<cv::Vec4b>(y);
      cv::Vec4b* o = tex.ptr<cv::Vec4b>(y);
      for (int x = 0; x < kGroundTexels; ++x) {
        cv::Vec3f c(g[x][0], g[x][1], g[x][2]), colour;
        float a = 0;
        if (cover.at(x, y, &colour, &a)) c = c * (1 - a) + colour * a;
        o[x] = cv::Vec4b(sat8(c[0] * dark), sat8(c[1] * dark), sat8(c[2] * dark), 255);
      }
    }
  }
  const std::vector<cv::Mat> mips = mip_chain(tex, 32);
  std::size_t total = 0;
  for (const cv::Mat& level : mips) total += level.total();
  out->texels.reset(new std::uint32_t[total]);  // not zero-filled: every texel is written below
  std::size_t offset = 0;
  for (const cv::Mat& level : mips) {
    if (out->levels == static_cast<int>(out->offsets.size())) break;
    out->offsets[static_cast<std::size_t>(out->levels++)] = static_cast<std::uint32_t>(offset);
    swizzle_into(level, out->texels.get() + offset);
    offset += level.total();
  }
  return out;
}

std::shared_ptr<const std::vector<double>> build_unit_noise(std::uint64_t seed) {
  auto out = std::make_shared<std::vector<double>>(static_cast<std::size_t>(kNoiseTile * kNoiseTile * 3));
  Rng nrng(seed, 0x401523ull);
  for (double& v : *out) v = nrng.normal();
  return out;
}

SharedCache<MapTextureKey, MapTexture>& map_texture_cache() {
  static SharedCache<MapTextureKey, MapTexture> cache(detail::kMapTextureCacheCapacity);
  return cache;
}
SharedCache<std::uint64_t, std::vector<double>>& unit_noise_cache() {
  static SharedCache<std::uint64_t, std::vector<double>> cache(8);  // 1.5 MiB each
  return cache;
}

}  // namespace

std::shared_ptr<const MapTexture> shared_map_texture(const MapTextureKey& key) {
  return map_texture_cache().get(key, [&] { return build_map_texture(key); });
}

std::shared_ptr<const std::vector<double>> shared_unit_noise(std::uint64_t seed) {
  return unit_noise_cache().get(seed, [&] { return build_unit_noise(seed); });
}

}  // namespace render_detail

namespace detail {
void clear_render_caches() {
  render_detail::map_texture_cache().clear();
  render_detail::map_ground_cache().clear();
  render_detail::cover_base_cache().clear();
  render_detail::unit_noise_cache().clear();
}
std::size_t cached_map_textures() { return render_detail::map_texture_cache().size(); }
}  // namespace detail

}  // namespace touchdown::scenario
