// The renderer's ground textures and cover (render_texture.hpp).
#include "scenario/render_texture.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "touchdown/core/statistics.hpp"

namespace touchdown::scenario::render_detail {

void swizzle_into(const cv::Mat& bgra, std::uint32_t* dst) {
  int shift = 0;
  while ((32 << shift) < bgra.cols) ++shift;
  for (int v = 0; v < bgra.rows; ++v) {
    const auto* row = bgra.ptr<std::uint32_t>(v);
    for (int u = 0; u < bgra.cols; ++u)
      dst[swizzle(static_cast<unsigned>(u), static_cast<unsigned>(v), shift)] = row[u];
  }
}

namespace {

// ---- periodic procedural noise (textures tile without seams) ----

cv::Mat wrap_resize(const cv::Mat& src, int out, int interpolation) {
  const int n = src.rows, pad = 2, scale = out / n;
  cv::Mat padded, up;
  cv::copyMakeBorder(src, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::resize(padded, up, cv::Size((n + 2 * pad) * scale, (n + 2 * pad) * scale), 0, 0, interpolation);
  return up(cv::Rect(pad * scale, pad * scale, out, out));  // a view: no 16 MiB copy
}

/// Periodic value noise in about [−1, 1] at `res`² with `cells` lattice cells
/// per period (bicubic between lattice values).
cv::Mat periodic_noise(int res, int cells, cv::RNG& rng) {
  cv::Mat grid(cells, cells, CV_32F);
  rng.fill(grid, cv::RNG::UNIFORM, -1.0f, 1.0f);
  if (cells >= res) return grid;
  return wrap_resize(grid, res, cv::INTER_CUBIC);
}

/// Sum of octaves at 512² (a quarter of the texture's resolution), sampled
/// bilinearly by field_at: no 16 MiB temporaries (construction time is
/// dominated by page faults otherwise).
cv::Mat fbm(cv::RNG& rng, std::initializer_list<std::pair<int, float>> octaves) {
  cv::Mat sum = cv::Mat::zeros(kFieldRes, kFieldRes, CV_32F);
  for (const auto& [cells, weight] : octaves) sum += weight * periodic_noise(kFieldRes, cells, rng);
  return sum;
}

/// The value of `noise` below which a fraction `fraction` of texels lie.
float quantile(const cv::Mat& noise, double fraction) {
  std::vector<float> v;
  v.reserve(static_cast<std::size_t>(noise.total() / 16 + 1));
  for (int y = 0; y < noise.rows; y += 4) {
    const float* row = noise.ptr<float>(y);
    for (int x = 0; x < noise.cols; x += 4) v.push_back(row[x]);
  }
  return quantile_in_place(std::span(v), fraction);
}

/// Soft coverage mask: ≈ `fraction` of the texels covered, 8 cm soft edges.
cv::Mat coverage(const cv::Mat& noise, double fraction) {
  cv::Mat a(noise.size(), CV_32F);
  if (fraction <= 0) return cv::Mat::zeros(noise.size(), CV_32F);
  if (fraction >= 0.999) return cv::Mat::ones(noise.size(), CV_32F);
  const float thr = quantile(noise, 1.0 - fraction);
  const float inv_width = 1.0f / 0.06f;
  for (int y = 0; y < noise.rows; ++y) {
    const float* n = noise.ptr<float>(y);
    float* o = a.ptr<float>(y);
    for (int x = 0; x < noise.cols; ++x) o[x] = std::clamp((n[x] - thr) * inv_width + 0.5f, 0.0f, 1.0f);
  }
  return a;
}

/// Draws `draw(offset)` at the 9 periodic copies so features crossing the
/// texture's edge continue on the other side.
template <class Draw>
void draw_wrapped(Draw draw) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) draw(cv::Point(dx * kGroundTexels, dy * kGroundTexels));
  }
}

}  // namespace

cv::Mat concrete_texture(cv::RNG& rng) {
  const int n = kGroundTexels;
  const cv::Mat tone = fbm(rng, {{4, 0.5f}, {16, 0.3f}, {64, 0.2f}});
  const cv::Mat wear = fbm(rng, {{32, 0.6f}, {128, 0.4f}});
  const auto grain_seed = static_cast<std::uint32_t>(rng.next());
  // Stains: dark blotches, blurred, at 512² then upsampled.
  cv::Mat stain = cv::Mat::zeros(512, 512, CV_32F);
  const int stains = 30;
  for (int i = 0; i < stains; ++i) {
    const int cy = rng.uniform(0, 512), cx = rng.uniform(0, 512);  // drawn y first
    const cv::Point c(cx, cy);
    const int ay = rng.uniform(4, 18), ax = rng.uniform(4, 26);
    const cv::Size axes(ax, ay);
    const double angle = rng.uniform(0.0, 180.0), strength = rng.uniform(0.3, 1.0);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        cv::ellipse(stain, c + cv::Point(dx * 512, dy * 512), axes, angle, 0, 360, cv::Scalar(strength), -1,
                    cv::LINE_AA);
      }
    }
  }
  cv::Mat padded;
  cv::copyMakeBorder(stain, padded, 16, 16, 16, 16, cv::BORDER_WRAP);
  cv::GaussianBlur(padded, padded, cv::Size(0, 0), 4.0);
  stain = padded(cv::Rect(16, 16, 512, 512)).clone();
  // Cracks: random walks, 1 texel wide.
  cv::Mat crack = cv::Mat::zeros(n, n, CV_8U);
  for (int i = 0; i < 40; ++i) {
    std::vector<cv::Point> walk;
    const double py = rng.uniform(0.0, static_cast<double>(n));  // drawn y first
    cv::Point2d p(rng.uniform(0.0, static_cast<double>(n)), py);
    double heading = rng.uniform(0.0, 2 * kPi);
    const int steps = rng.uniform(15, 70);
    for (int s = 0; s < steps; ++s) {
      walk.emplace_back(static_cast<int>(p.x), static_cast<int>(p.y));
      heading += rng.gaussian(0.25);
      p += 4.0 * cv::Point2d(std::cos(heading), std::sin(heading));
    }
    draw_wrapped([&](cv::Point o) {
      std::vector<cv::Point> w(walk);
      for (auto& q : w) q += o;
      cv::polylines(crack, w, false, cv::Scalar(255), 1, cv::LINE_AA);
    });
  }
  cv::Mat out(n, n, CV_8UC4);
  const cv::Vec3f base(146, 150, 152), yellow(40, 185, 225), white(225, 228, 228);
  for (int y = 0; y < n; ++y) {
    const std::uint8_t* cr = crack.ptr<std::uint8_t>(y);
    cv::Vec4b* o = out.ptr<cv::Vec4b>(y);
    const bool seam_row = (y % 128) < 2;
    for (int x = 0; x < n; ++x) {
      const float t = field_at(tone, x, y), g = grain_at(grain_seed, x, y);
      const float lum = 1.0f + 0.09f * t + 0.05f * g;
      cv::Vec3f c = base * lum + cv::Vec3f(3, 0, -3) * t;  // slight warm/cool shifts
      if (seam_row || (x % 128) < 2) c *= 0.7f;            // slab joints (sawn, 5 cm)
      // Paint: a yellow line along x, a dashed white line along y, stalls.
      float paint = 0;
      cv::Vec3f paint_colour = white;
      if (y >= 600 && y < 605) {
        paint = 1, paint_colour = yellow;
      } else if (x >= 1500 && x < 1505 && (y % 256) < 160) {
        paint = 1;
      } else if (y >= 1100 && y < 1300 && (x % 128) >= 60 && (x % 128) < 64) {
        paint = 1;
      } else if (y >= 1296 && y < 1300) {
        paint = 1;
      }
      if (paint > 0) {
        const float w = field_at(wear, x, y);
        const float a = std::clamp(0.95f - 0.6f * std::max(0.0f, w) - 0.15f * std::abs(g), 0.0f, 1.0f);
        c = c * (1 - a) + paint_colour * (a * (1.0f + 0.04f * g));
      }
      c *= 1.0f - 0.35f * std::min(1.0f, field_at(stain, x, y));
      c *= 1.0f - 0.45f * static_cast<float>(cr[x]) / 255.0f;
      o[x] = cv::Vec4b(sat8(c[0]), sat8(c[1]), sat8(c[2]), 255);
    }
  }
  return out;
}

cv::Mat lawn_texture(cv::RNG& rng) {
  const int n = kGroundTexels;
  const cv::Mat patches = fbm(rng, {{4, 0.5f}, {16, 0.35f}, {64, 0.15f}});
  const cv::Mat clumps = fbm(rng, {{128, 0.7f}, {256, 0.3f}});
  const cv::Mat soil = fbm(rng, {{8, 0.6f}, {32, 0.4f}});
  const float soil_thr = quantile(soil, 0.97);  // ~3 % bare soil
  const auto grain_seed = static_cast<std::uint32_t>(rng.next());
  cv::Mat out(n, n, CV_8UC4);
  const cv::Vec3f lush(45, 120, 60), dry(80, 160, 150), dark(30, 80, 35), earth(60, 85, 110);
  for (int y = 0; y < n; ++y) {
    cv::Vec4b* o = out.ptr<cv::Vec4b>(y);
    for (int x = 0; x < n; ++x) {
      const float dryness = std::clamp(0.5f * field_at(patches, x, y) + 0.25f, 0.0f, 1.0f);
      cv::Vec3f col = lush * (1 - dryness) + dry * dryness;
      // Clumps: darker hollows, brighter tufts.
      const float clump = std::clamp(field_at(clumps, x, y) * 0.9f, -0.6f, 0.6f);
      col = clump < 0 ? col * (1 + clump) + dark * (-clump) : col * (1 + 0.25f * clump);
      const float bare = std::clamp((field_at(soil, x, y) - soil_thr) * 20.0f, 0.0f, 1.0f);
      col = col * (1 - bare) + earth * bare;
      const cv::Vec3f out_c = col * (1.0f + 0.16f * grain_at(grain_seed, x, y));
      o[x] = cv::Vec4b(sat8(out_c[0]), sat8(out_c[1]), sat8(out_c[2]), 255);
    }
  }
  return out;
}

namespace {

/// Leaf litter as leaves: one leaf per cell of kLeafCell texels (10 cm),
/// centred at a jittered point, with its own orientation and elongation; a
/// texel belongs to the leaf nearest under that leaf's elliptical metric
/// (an anisotropic Voronoi diagram, so leaves are irregular, elongated and
/// tile the litter), and texels almost equidistant from two leaves are the
/// gaps between them. Colours follow patches (leaves under one tree share
/// their colour) with a per-leaf variation, darker towards the leaf's edge.
constexpr int kLeafCell = 4;
constexpr int kLeafCells = kGroundTexels / kLeafCell;  // per period
struct LeafCell {
  float x = 0, y = 0;          // centre [texels], inside the cell
  float c = 1, s = 0;          // orientation
  float inv_a = 1, inv_b = 1;  // 1 / semi-axes [1/texels]
  float jitter = 0;            // per-leaf colour offset
  float bright = 1;
};

std::vector<LeafCell> leaf_cells(cv::RNG& rng) {
  std::vector<LeafCell> cells(static_cast<std::size_t>(kLeafCells) * kLeafCells);
  for (int j = 0; j < kLeafCells; ++j) {
    for (int i = 0; i < kLeafCells; ++i) {
      LeafCell& c = cells[static_cast<std::size_t>(j) * kLeafCells + static_cast<std::size_t>(i)];
      c.x = static_cast<float>(kLeafCell * (i + rng.uniform(0.15, 0.85)));
      c.y = static_cast<float>(kLeafCell * (j + rng.uniform(0.15, 0.85)));
      const double angle = rng.uniform(0.0, kPi);
      c.c = static_cast<float>(std::cos(angle)), c.s = static_cast<float>(std::sin(angle));
      // The ellipse gives the leaf its shape (2–2.5:1) and its pull against
      // its neighbours; the 10 cm cell spacing gives its size.
      const double length = rng.uniform(1.6, 2.4) * kLeafCell;
      c.inv_a = static_cast<float>(2 / length);
      c.inv_b = static_cast<float>(2 / (length / rng.uniform(2.0, 2.5)));
      c.jitter = static_cast<float>(rng.uniform(-0.7, 0.7));
      c.bright = static_cast<float>(rng.uniform(0.85, 1.1));
    }
  }
  return cells;
}

/// The four leaves that may own a texel: those of the 2×2 cells nearest to
/// it (its own cell and the neighbours on its side), centres unwrapped next
/// to it. Leaves further away rarely reach past a neighbour's centre.
struct LeafNeighbours {
  std::array<LeafCell, 4> c;
  LeafNeighbours(const std::vector<LeafCell>& cells, int cx0, int cy0) {  // cells cx0..cx0+1, cy0..cy0+1
    std::size_t k = 0;
    for (int j = cy0; j <= cy0 + 1; ++j) {
      const int jw = (j + kLeafCells) % kLeafCells;
      for (int i = cx0; i <= cx0 + 1; ++i) {
        const int iw = (i + kLeafCells) % kLeafCells;
        c[k] = cells[static_cast<std::size_t>(jw) * kLeafCells + static_cast<std::size_t>(iw)];
        c[k].x += static_cast<float>((i - iw) * kLeafCell);
        c[k].y += static_cast<float>((j - jw) * kLeafCell);
        ++k;
      }
    }
  }
  /// The first cell of the 2×2 block nearest to texel (x, y).
  static int block(int x) { return (x + kLeafCell / 2) / kLeafCell - 1; }
  /// The owner of texel (x, y), how deep inside it the texel is (0 at the gap
  /// to the next leaf) and how far from its centre (1 at the ellipse).
  const LeafCell& at(int x, int y, float& inside, float& radial) const {
    const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
    std::array<float, 4> d{};
    for (std::size_t k = 0; k < c.size(); ++k) {
      const float dx = px - c[k].x, dy = py - c[k].y;
      const float u = (c[k].c * dx + c[k].s * dy) * c[k].inv_a, v = (c[k].c * dy - c[k].s * dx) * c[k].inv_b;
      d[k] = u * u + v * v;
    }
    std::size_t best = 0;
    for (std::size_t k = 1; k < d.size(); ++k) best = d[k] < d[best] ? k : best;
    float d2 = std::numeric_limits<float>::max();
    for (std::size_t k = 0; k < d.size(); ++k) d2 = k != best ? std::min(d2, d[k]) : d2;
    inside = std::sqrt(d2) - std::sqrt(d[best]);
    radial = std::sqrt(d[best]);
    return c[best];
  }
};

/// The leaf litter's colour at texel (x, y) (alpha 0 in the gap between two
/// leaves): the patch colour with the leaf's own variation, darker towards
/// its edge, with grain.
cv::Vec4b leaf_texel(const LeafNeighbours& near, const cv::Mat& leaf_tone, const std::array<cv::Vec3f, 4>& palette,
                     std::uint32_t grain_seed, int x, int y) {
  float inside = 0, radial = 0;
  const LeafCell& c = near.at(x, y, inside, radial);
  const float tone = std::clamp(1.5f + 1.6f * field_at(leaf_tone, x, y) + c.jitter, 0.0f, 3.0f);
  const auto i0 = static_cast<std::size_t>(std::min(2.0f, std::floor(tone)));
  const float t = tone - static_cast<float>(i0);
  const float shade = c.bright * (1.0f - 0.2f * std::min(1.0f, radial)) * (1.0f + 0.05f * grain_at(grain_seed, x, y));
  const cv::Vec3f leaf = (palette[i0] * (1 - t) + palette[i0 + 1] * t) * shade;
  return {sat8(leaf[0]), sat8(leaf[1]), sat8(leaf[2]), static_cast<std::uint8_t>(inside < 0.12f ? 0 : 255)};
}

}  // namespace

std::shared_ptr<const CoverBase> build_cover_base() {
  auto out = std::make_shared<CoverBase>();
  cv::RNG rng(0x1EAF5A0Full);
  out->snow_field = fbm(rng, {{8, 0.5f}, {32, 0.3f}, {128, 0.2f}});
  out->leaf_field = fbm(rng, {{16, 0.5f}, {64, 0.3f}, {256, 0.2f}});
  // Patches of leaf colour, metres across.
  const cv::Mat leaf_tone = fbm(rng, {{8, 0.6f}, {32, 0.4f}});
  const std::vector<LeafCell> cells = leaf_cells(rng);
  out->grain_seed = static_cast<std::uint32_t>(rng.next());
  // Dry-leaf colours by luminance (dark brown, red, orange-brown, yellow):
  // neighbouring patches blend through similar ones.
  const std::array<cv::Vec3f, 4> palette{cv::Vec3f(35, 65, 115), cv::Vec3f(35, 45, 165), cv::Vec3f(30, 95, 200),
                                         cv::Vec3f(40, 175, 215)};
  const int n = kGroundTexels;
  out->leaves.create(n, n, CV_8UC4);
  for (int y = 0; y < n; ++y) {
    cv::Vec4b* o = out->leaves.ptr<cv::Vec4b>(y);
    std::optional<LeafNeighbours> near;  // the four leaves around the texel in hand
    int near_cx = -2;
    for (int x = 0; x < n; ++x) {
      if (LeafNeighbours::block(x) != near_cx) {
        near_cx = LeafNeighbours::block(x);
        near.emplace(cells, near_cx, LeafNeighbours::block(y));
      }
      o[x] = leaf_texel(*near, leaf_tone, palette, out->grain_seed, x, y);
    }
  }
  return out;
}

CoverSampler::CoverSampler(const Weather& w, std::shared_ptr<const CoverBase> base, cv::Point shift)
    : base_(std::move(base)), shift_(shift) {
  snow_a_ = coverage(base_->snow_field, w.ground_snow);
  leaf_a_ = coverage(base_->leaf_field, w.ground_leaves);
}

float wet_darkening(const Weather& w) {
  return 1.0f - 0.35f * static_cast<float>(std::clamp(w.ground_wetness, 0.0, 1.0));
}

std::vector<cv::Mat> mip_chain(const cv::Mat& level0, int min_side) {
  std::vector<cv::Mat> mips{level0};
  while (mips.back().cols / 2 >= min_side && mips.back().rows / 2 >= min_side) {
    cv::Mat next;
    cv::resize(mips.back(), next, cv::Size(mips.back().cols / 2, mips.back().rows / 2), 0, 0, cv::INTER_AREA);
    mips.push_back(next);
  }
  return mips;
}

}  // namespace touchdown::scenario::render_detail
