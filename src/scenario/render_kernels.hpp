#pragma once
/// \file
/// The renderer's row kernels (render_kernels.cpp): the ground pass's row,
/// scalar and AVX2 (eight pixels at a time, the same bits), and the
/// elementwise weather passes, each compiled for the baseline ISA and for
/// AVX2 and picked at run time (has_avx2).
#include <cstdint>

namespace touchdown::scenario::render_detail {

// One image row of the ground pass. Per pixel: 1/depth is affine in the
// pixel (the plane z = 0 seen through a pinhole), one division gives the
// depth and the world point, the mip level comes from the footprint
// depth/f, and the texel is a bilinear blend (8-bit weights).
struct GroundRow {
  const std::uint32_t* texels = nullptr;   // all levels, swizzled
  const std::uint32_t* offsets = nullptr;  // start of each level (8 entries)
  int levels = 1;
  int width = 0;
  float rx0 = 0, ry0 = 0, rz0 = 0, ax = 0, ay = 0, az = 0;
  float inv_h = 0, w_min = 0, cxw = 0, cyw = 0, lod = 0;
};

/// Whether this CPU runs AVX2 (asked once).
bool has_avx2();

/// Pixels [x0, x1) of a ground row: colour, label (Label::Ground or Label::Sky) and depth.
void ground_row_scalar(const GroundRow& g, int x0, int x1, std::uint8_t* px, std::uint8_t* mk, float* dp);

/// The same as ground_row_scalar for the pixels [0, n) of a row, eight at a
/// time, n the largest multiple of 8 not over `end`; returns n (0 without
/// AVX2). The pixels from n on are the scalar kernel's.
int ground_row_avx2(const GroundRow& g, std::uint8_t* px, std::uint8_t* mk, float* dp, int end);

// The elementwise weather passes on one row (what each computes: its _body
// in render_kernels.cpp).
void fog_row(std::uint8_t* px, const float* dp, int n, const std::int32_t* table, float scale, float last,
             const std::int32_t* airlight, std::int32_t* t);
void add_row(std::uint16_t* acc, const std::uint8_t* src, int n);
void average_row(std::uint8_t* px, const std::uint16_t* acc, int n, std::uint32_t half, std::uint32_t mul);
void low_light_row(std::uint8_t* px, const std::int16_t* noise, int n, std::int32_t gain);
void rain_row(std::uint8_t* px, const std::uint8_t* ov, int n);

/// (a + c/2) / c == ((a + c/2) · mul(c)) >> 16 for every sum a ≤ 255·c of
/// c ≤ 9 copies (motion blur).
constexpr std::uint32_t blur_divisor_mul(std::uint32_t c) { return (65536 + c - 1) / c; }
constexpr bool blur_division_exact() {
  for (std::uint32_t c = 1; c <= 9; ++c) {
    for (std::uint32_t a = 0; a <= 255 * c; ++a) {
      if ((a + c / 2) / c != (((a + c / 2) * blur_divisor_mul(c)) >> 16)) return false;
    }
  }
  return true;
}
static_assert(blur_division_exact());

}  // namespace touchdown::scenario::render_detail
