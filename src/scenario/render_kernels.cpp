// The renderer's row kernels and their run-time dispatch (render_kernels.hpp).
#include "scenario/render_kernels.hpp"

#include <algorithm>
#include <bit>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <limits>

#include "scenario/render_internal.hpp"
#include "touchdown/scenario/camera.hpp"

namespace touchdown::scenario::render_detail {

namespace {

constexpr float kInvTexel0 = static_cast<float>(1 / kGroundTexel);  // 40 texels/m, exact

inline void ground_pixel(const GroundRow& g, int x, std::uint8_t* px, std::uint8_t* mk, float* dp) {
  const float x_f = static_cast<float>(x);
  const float wdepth = (g.rz0 + g.az * x_f) * -g.inv_h;  // 1/depth
  if (!(wdepth > g.w_min)) {
    px[3 * x] = kSkyBgr[0], px[3 * x + 1] = kSkyBgr[1], px[3 * x + 2] = kSkyBgr[2];
    mk[x] = mask_value(Label::Sky);
    dp[x] = std::numeric_limits<float>::infinity();
    return;
  }
  const float s = 1.0f / wdepth;
  const float X = g.cxw + s * (g.rx0 + g.ax * x_f), Y = g.cyw + s * (g.ry0 + g.ay * x_f);
  const int k = mip_level(s * g.lod, g.levels);
  const unsigned msk = (static_cast<unsigned>(kGroundTexels) >> k) - 1;
  const float it = kInvTexel0 * std::bit_cast<float>(static_cast<std::uint32_t>(127 - k) << 23);
  const float u = X * it - 0.5f, vv = Y * it - 0.5f;
  const int ui = floor_int(u), vi = floor_int(vv);
  const auto tu = static_cast<std::uint32_t>(static_cast<int>((u - static_cast<float>(ui)) * 256.0f));
  const auto tv = static_cast<std::uint32_t>(static_cast<int>((vv - static_cast<float>(vi)) * 256.0f));
  const std::uint32_t* t = g.texels + g.offsets[k];
  const int tiles = kGroundTileShift - k;
  const unsigned u0 = static_cast<unsigned>(ui) & msk, u1 = static_cast<unsigned>(ui + 1) & msk;
  const unsigned v0 = static_cast<unsigned>(vi) & msk, v1 = static_cast<unsigned>(vi + 1) & msk;
  const std::uint32_t top = lerp_bgra(t[swizzle(u0, v0, tiles)], t[swizzle(u1, v0, tiles)], tu);
  const std::uint32_t bot = lerp_bgra(t[swizzle(u0, v1, tiles)], t[swizzle(u1, v1, tiles)], tu);
  const std::uint32_t c = lerp_bgra(top, bot, tv);
  px[3 * x] = static_cast<std::uint8_t>(c);
  px[3 * x + 1] = static_cast<std::uint8_t>(c >> 8);
  px[3 * x + 2] = static_cast<std::uint8_t>(c >> 16);
  mk[x] = mask_value(Label::Ground);
  dp[x] = s;
}

}  // namespace

void ground_row_scalar(const GroundRow& g, int x0, int x1, std::uint8_t* px, std::uint8_t* mk, float* dp) {
  for (int x = x0; x < x1; ++x) ground_pixel(g, x, px, mk, dp);
}

#if defined(__x86_64__) && defined(__GNUC__)
bool has_avx2() {
  static const bool kYes = __builtin_cpu_supports("avx2");
  return kYes;
}

namespace {

#define TD_AVX2 __attribute__((target("avx2"), always_inline)) inline
// swizzle() split into the bits from u and the bits from v (they do not
// overlap, so OR or add them; the level's offset, a multiple of the level's
// size, adds without carrying into either).
TD_AVX2 __m256i swz8_u(__m256i u) {
  const __m256i c3 = _mm256_set1_epi32(3), c7 = _mm256_set1_epi32(7);
  __m256i r = _mm256_slli_epi32(_mm256_srli_epi32(u, 5), 10);
  r = _mm256_or_si256(r, _mm256_slli_epi32(_mm256_and_si256(_mm256_srli_epi32(u, 2), c7), 4));
  return _mm256_or_si256(r, _mm256_and_si256(u, c3));
}
TD_AVX2 __m256i swz8_v(__m256i v, __m256i tiles) {
  const __m256i c3 = _mm256_set1_epi32(3), c7 = _mm256_set1_epi32(7);
  __m256i r = _mm256_slli_epi32(_mm256_sllv_epi32(_mm256_srli_epi32(v, 5), tiles), 10);
  r = _mm256_or_si256(r, _mm256_slli_epi32(_mm256_and_si256(_mm256_srli_epi32(v, 2), c7), 7));
  return _mm256_or_si256(r, _mm256_slli_epi32(_mm256_and_si256(v, c3), 2));
}
// Eight 32-bit loads at `idx`. Plain loads, not vpgatherdd: the hardware
// gather is microcoded on AMD Zen and was the ground pass's bottleneck.
TD_AVX2 __m256i gather8(const int* base, __m256i idx) {
  alignas(32) std::int32_t i[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(i), idx);
  return _mm256_setr_epi32(base[i[0]], base[i[1]], base[i[2]], base[i[3]], base[i[4]], base[i[5]], base[i[6]],
                           base[i[7]]);
}
// lerp_bgra on 8 texels: t16/s16 hold the weight in both 16-bit halves.
TD_AVX2 __m256i lerp8(__m256i a, __m256i b, __m256i t16, __m256i s16) {
  const __m256i lo_mask = _mm256_set1_epi32(0x00FF00FF), hi_mask = _mm256_set1_epi32(static_cast<int>(0xFF00FF00u));
  const __m256i rb = _mm256_srli_epi16(_mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(a, lo_mask), s16),
                                                        _mm256_mullo_epi16(_mm256_and_si256(b, lo_mask), t16)),
                                       8);
  const __m256i ga =
      _mm256_and_si256(_mm256_add_epi16(_mm256_mullo_epi16(_mm256_and_si256(_mm256_srli_epi32(a, 8), lo_mask), s16),
                                        _mm256_mullo_epi16(_mm256_and_si256(_mm256_srli_epi32(b, 8), lo_mask), t16)),
                       hi_mask);
  return _mm256_or_si256(rb, ga);
}
TD_AVX2 __m256i dup16(__m256i t) { return _mm256_or_si256(t, _mm256_slli_epi32(t, 16)); }

}  // namespace

// The same arithmetic as ground_pixel, eight pixels at a time (no FMA, so
// every float is rounded as in the scalar code: identical bits).
__attribute__((target("avx2"))) int ground_row_avx2(const GroundRow& g, std::uint8_t* px, std::uint8_t* mk, float* dp,
                                                    int end) {
  const __m256 iota = _mm256_setr_ps(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 rx0 = _mm256_set1_ps(g.rx0), ry0 = _mm256_set1_ps(g.ry0), rz0 = _mm256_set1_ps(g.rz0);
  const __m256 ax = _mm256_set1_ps(g.ax), ay = _mm256_set1_ps(g.ay), az = _mm256_set1_ps(g.az);
  const __m256 neg_inv_h = _mm256_set1_ps(-g.inv_h), w_min = _mm256_set1_ps(g.w_min), one = _mm256_set1_ps(1.0f);
  const __m256 cxw = _mm256_set1_ps(g.cxw), cyw = _mm256_set1_ps(g.cyw), lod = _mm256_set1_ps(g.lod);
  const __m256 inv_t0 = _mm256_set1_ps(kInvTexel0), half = _mm256_set1_ps(0.5f), f256 = _mm256_set1_ps(256.0f);
  const __m256 inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  const __m256i offsets = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(g.offsets));
  const __m256i zero = _mm256_setzero_si256(), max_level = _mm256_set1_epi32(g.levels - 1);
  const __m256i c127 = _mm256_set1_epi32(127), cff = _mm256_set1_epi32(0xFF), c1 = _mm256_set1_epi32(1);
  const __m256i c256 = _mm256_set1_epi32(256);
  const __m256i n0 = _mm256_set1_epi32(kGroundTexels), tile0 = _mm256_set1_epi32(kGroundTileShift);
  const __m256i sky = _mm256_set1_epi32(static_cast<int>(kSkyBgr[0] | (kSkyBgr[1] << 8) | (kSkyBgr[2] << 16)));
  // BGRA → BGR within each 128-bit lane (4 pixels → 12 bytes, 4 bytes of junk).
  const __m256i pack = _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1, 0, 1, 2, 4, 5, 6, 8, 9,
                                        10, 12, 13, 14, -1, -1, -1, -1);
  static_assert(mask_value(Label::Ground) == 0, "the label store below writes 0 for the ground");
  const __m256i sky_label = _mm256_set1_epi32(mask_value(Label::Sky)),
                label_order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
  int x = 0;
  for (; x + 8 <= end; x += 8) {
    const __m256 xs = _mm256_add_ps(_mm256_set1_ps(static_cast<float>(x)), iota);
    const __m256 w = _mm256_mul_ps(_mm256_add_ps(rz0, _mm256_mul_ps(az, xs)), neg_inv_h);
    const __m256 valid = _mm256_cmp_ps(w, w_min, _CMP_GT_OQ);
    const __m256 s = _mm256_div_ps(one, _mm256_blendv_ps(one, w, valid));
    const __m256 X = _mm256_add_ps(cxw, _mm256_mul_ps(s, _mm256_add_ps(rx0, _mm256_mul_ps(ax, xs))));
    const __m256 Y = _mm256_add_ps(cyw, _mm256_mul_ps(s, _mm256_add_ps(ry0, _mm256_mul_ps(ay, xs))));
    const __m256 q = _mm256_mul_ps(s, lod);
    __m256i k = _mm256_sub_epi32(_mm256_and_si256(_mm256_srli_epi32(_mm256_castps_si256(q), 23), cff), c127);
    k = _mm256_max_epi32(zero, _mm256_min_epi32(k, max_level));
    const __m256 it = _mm256_mul_ps(inv_t0, _mm256_castsi256_ps(_mm256_slli_epi32(_mm256_sub_epi32(c127, k), 23)));
    const __m256 u = _mm256_sub_ps(_mm256_mul_ps(X, it), half), v = _mm256_sub_ps(_mm256_mul_ps(Y, it), half);
    const __m256 uf = _mm256_floor_ps(u), vf = _mm256_floor_ps(v);
    const __m256i ui = _mm256_cvttps_epi32(uf), vi = _mm256_cvttps_epi32(vf);
    const __m256i tu = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_sub_ps(u, uf), f256));
    const __m256i tv = _mm256_cvttps_epi32(_mm256_mul_ps(_mm256_sub_ps(v, vf), f256));
    const __m256i msk = _mm256_sub_epi32(_mm256_srlv_epi32(n0, k), c1);
    const __m256i tiles = _mm256_sub_epi32(tile0, k);
    const __m256i u0 = _mm256_and_si256(ui, msk), u1 = _mm256_and_si256(_mm256_add_epi32(ui, c1), msk);
    const __m256i v0 = _mm256_and_si256(vi, msk), v1 = _mm256_and_si256(_mm256_add_epi32(vi, c1), msk);
    const __m256i base = _mm256_permutevar8x32_epi32(offsets, k);
    const int* tex = reinterpret_cast<const int*>(g.texels);
    // swizzle(u, v) = its u bits | its v bits: two of each for the four texels.
    const __m256i su0 = swz8_u(u0), su1 = swz8_u(u1);
    const __m256i sv0 = _mm256_add_epi32(base, swz8_v(v0, tiles)), sv1 = _mm256_add_epi32(base, swz8_v(v1, tiles));
    const __m256i t00 = gather8(tex, _mm256_or_si256(sv0, su0));
    const __m256i t01 = gather8(tex, _mm256_or_si256(sv0, su1));
    const __m256i t10 = gather8(tex, _mm256_or_si256(sv1, su0));
    const __m256i t11 = gather8(tex, _mm256_or_si256(sv1, su1));
    const __m256i tu16 = dup16(tu), su16 = dup16(_mm256_sub_epi32(c256, tu));
    const __m256i tv16 = dup16(tv), sv16 = dup16(_mm256_sub_epi32(c256, tv));
    __m256i c = lerp8(lerp8(t00, t01, tu16, su16), lerp8(t10, t11, tu16, su16), tv16, sv16);
    const __m256i vmask = _mm256_castps_si256(valid);
    c = _mm256_blendv_epi8(sky, c, vmask);
    const __m256i packed = _mm256_shuffle_epi8(c, pack);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(px + 3 * x), _mm256_castsi256_si128(packed));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(px + 3 * x + 12), _mm256_extracti128_si256(packed, 1));
    _mm256_storeu_ps(dp + x, _mm256_blendv_ps(inf, s, valid));
    // Labels: Label::Ground (0) where valid, Label::Sky elsewhere; 32 → 8 bits per pixel.
    const __m256i labels = _mm256_andnot_si256(vmask, sky_label);
    const __m256i bytes = _mm256_packus_epi16(_mm256_packs_epi32(labels, labels), zero);
    _mm_storel_epi64(reinterpret_cast<__m128i*>(mk + x),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(bytes, label_order)));
  }
  return x;
}
#else
bool has_avx2() { return false; }
int ground_row_avx2(const GroundRow&, std::uint8_t*, std::uint8_t*, float*, int) { return 0; }
#endif

// ---- elementwise weather passes ----
// Plain loops over contiguous bytes that the compiler vectorises, compiled
// twice (the baseline ISA and AVX2) and picked at run time like the ground
// kernel. Integer arithmetic only, so both builds give the same bytes.
#if defined(__x86_64__) && defined(__GNUC__)
#define TD_DISPATCH(name, params, args)                                         \
  void name##_base params { name##_body args; }                                 \
  __attribute__((target("avx2"))) void name##_avx2 params { name##_body args; } \
  void name params {                                                            \
    if (has_avx2()) {                                                           \
      name##_avx2 args;                                                         \
    } else {                                                                    \
      name##_base args;                                                         \
    }                                                                           \
  }
#else
#define TD_DISPATCH(name, params, args) \
  void name params { name##_body args; }
#endif
#define TD_BODY __attribute__((always_inline)) inline

/// Fog/dust (Koschmieder) on one row: transmission ×256 from the depth
/// table (its last entry is 0: beyond the range and the sky), then
/// I = (J·t + A·(256 − t)) / 256 per channel.
TD_BODY void fog_row_body(std::uint8_t* px, const float* dp, int n, const std::int32_t* table, float scale, float last,
                          const std::int32_t* airlight, std::int32_t* t) {
  for (int x = 0; x < n; ++x) t[x] = table[static_cast<int>(std::min(dp[x] * scale, last))];
  const std::int32_t a0 = airlight[0], a1 = airlight[1], a2 = airlight[2];
  for (int x = 0; x < n; ++x) {
    const std::int32_t tx = t[x], sx = 256 - tx;
    px[3 * x] = static_cast<std::uint8_t>((px[3 * x] * tx + a0 * sx) >> 8);
    px[3 * x + 1] = static_cast<std::uint8_t>((px[3 * x + 1] * tx + a1 * sx) >> 8);
    px[3 * x + 2] = static_cast<std::uint8_t>((px[3 * x + 2] * tx + a2 * sx) >> 8);
  }
}
TD_DISPATCH(fog_row,
            (std::uint8_t * px, const float* dp, int n, const std::int32_t* table, float scale, float last,
             const std::int32_t* airlight, std::int32_t* t),
            (px, dp, n, table, scale, last, airlight, t))

/// acc[i] += src[i] (motion blur: one shifted copy).
TD_BODY void add_row_body(std::uint16_t* acc, const std::uint8_t* src, int n) {
  for (int i = 0; i < n; ++i) acc[i] = static_cast<std::uint16_t>(acc[i] + src[i]);
}
TD_DISPATCH(add_row, (std::uint16_t * acc, const std::uint8_t* src, int n), (acc, src, n))

/// px[i] = (acc[i] + half) / copies as a multiply and shift (exact here:
/// blur_division_exact in render_kernels.hpp).
TD_BODY void average_row_body(std::uint8_t* px, const std::uint16_t* acc, int n, std::uint32_t half,
                              std::uint32_t mul) {
  for (int i = 0; i < n; ++i) px[i] = static_cast<std::uint8_t>(((acc[i] + half) * mul) >> 16);
}
TD_DISPATCH(average_row, (std::uint8_t * px, const std::uint16_t* acc, int n, std::uint32_t half, std::uint32_t mul),
            (px, acc, n, half, mul))

/// Low light: brightness × gain (8.8 fixed point) plus sensor noise, saturated.
TD_BODY void low_light_row_body(std::uint8_t* px, const std::int16_t* noise, int n, std::int32_t gain) {
  for (int i = 0; i < n; ++i) {
    const std::int32_t v = ((px[i] * gain + 128) >> 8) + noise[i];
    px[i] = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
  }
}
TD_DISPATCH(low_light_row, (std::uint8_t * px, const std::int16_t* noise, int n, std::int32_t gain),
            (px, noise, n, gain))

/// Rain streaks: px += (215 − px)·a/256 with a = overlay·170/255 (≤ 66 % opaque).
TD_BODY void rain_row_body(std::uint8_t* px, const std::uint8_t* ov, int n) {
  for (int x = 0; x < n; ++x) {
    const std::int32_t a = ov[x] * 2 / 3;
    px[3 * x] = static_cast<std::uint8_t>(px[3 * x] + (((215 - px[3 * x]) * a) >> 8));
    px[3 * x + 1] = static_cast<std::uint8_t>(px[3 * x + 1] + (((215 - px[3 * x + 1]) * a) >> 8));
    px[3 * x + 2] = static_cast<std::uint8_t>(px[3 * x + 2] + (((215 - px[3 * x + 2]) * a) >> 8));
  }
}
TD_DISPATCH(rain_row, (std::uint8_t * px, const std::uint8_t* ov, int n), (px, ov, n))

}  // namespace touchdown::scenario::render_detail
