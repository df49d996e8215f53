// The drone's downward camera (camera.hpp), headless: a software renderer
// built for ≤ 2 ms per 640×480 frame on one core.
//
// Per frame, in this order:
//  1. ground: every pixel's ray meets the plane z = 0; 1/depth and the ray
//     are affine in pixel coordinates, so one division per pixel gives the
//     depth and the world point, which samples a periodic, mip-mapped
//     procedural texture of the map (bilinear, mip level from twice the
//     pixel footprint: the pixel area and the lens blur, kPrefilterFootprints);
//  2. markers and distractors: the same ray/plane intersection over each
//     quadrilateral's bounding box, sampled from the marker's own mip-mapped
//     image (so the marker stays sharp from 1 m), label kMarker/kDistractor;
//  3. sun shadows: every solid's vertices projected along the sun onto the
//     ground, convex hull, drawn into the image through the camera;
//  4. objects: solids tessellated once, clipped at the near plane and
//     rasterised with a z-buffer (1/z interpolated in screen space, which is
//     exact for perspective), flat Lambertian shading;
//  5. weather as image effects: wet-ground sun glare (Blinn–Phong lobe about
//     the sun's mirror direction), fog and dust by Koschmieder's law
//     I = J·t + A·(1 − t), t = exp(−β·depth), motion blur along the image
//     velocity of the ground, rain streaks / snow flakes / leaves as 3-D
//     particles moved during the exposure, low light as gain and sensor noise.
// Ground snow, leaf litter and wetness are baked into the ground texture and
// into the marker images (they lie on the marker too).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <future>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "pose/aruco_dictionary.hpp"
#include "scenario/render_cache.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/geometry.hpp"

namespace touchdown::scenario {

namespace {

constexpr double kPi = std::numbers::pi;
double rad(double d) { return d * kPi / 180.0; }

std::string num(double v) {
  std::string s = std::to_string(v);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

}  // namespace

// ---------------------------------------------------------------- camera --

bool CameraOptions::validate(std::string* why) const {
  if (width < 16 || width > 4096) return invalid(why, "width: " + std::to_string(width) + " px is outside [16, 4096]");
  if (height < 16 || height > 4096) {
    return invalid(why, "height: " + std::to_string(height) + " px is outside [16, 4096]");
  }
  if (!(hfov_deg > 10 && hfov_deg < 170)) {
    return invalid(why, "hfov_deg: " + num(hfov_deg) + " deg is outside (10, 170)");
  }
  if (!(tilt_deg >= 0 && tilt_deg <= 80)) return invalid(why, "tilt_deg: " + num(tilt_deg) + " deg is outside [0, 80]");
  if (!(rate_hz > 0 && rate_hz <= 100)) return invalid(why, "rate_hz: " + num(rate_hz) + " Hz is outside (0, 100]");
  if (!(exposure_s >= 0 && exposure_s <= 0.2)) {
    return invalid(why, "exposure_s: " + num(exposure_s) + " s is outside [0, 0.2]");
  }
  if (!offset_body.allFinite()) return invalid(why, "offset_body: must be finite");
  return true;
}

double CameraOptions::fx() const { return 0.5 * width / std::tan(0.5 * rad(hfov_deg)); }

Eigen::Matrix3d CameraOptions::K() const {
  // Pixel centres at integer coordinates (OpenCV's convention), so the
  // image centre is ((w − 1)/2, (h − 1)/2).
  Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
  k(0, 0) = k(1, 1) = fx();
  k(0, 2) = 0.5 * (width - 1);
  k(1, 2) = 0.5 * (height - 1);
  return k;
}

Eigen::Isometry3d CameraOptions::T_body_camera() const {
  // Columns = camera axes in the body frame at nadir: x right = −y body,
  // y down = −x body (image up = forward), z = −z body (looking down).
  Eigen::Matrix3d nadir;
  nadir << 0, -1, 0, -1, 0, 0, 0, 0, -1;
  // Rotating about the camera's x axis by +tilt leans z towards body +x:
  // z' = nadir · (0, −sin, cos) = (sin, 0, −cos).
  const Eigen::Matrix3d R = nadir * Eigen::AngleAxisd(rad(tilt_deg), Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = offset_body;
  return T;
}

// -------------------------------------------------------------- renderer --

namespace {

using Bgr = std::array<std::uint8_t, 3>;

// The ground texture: 2048² texels of 2.5 cm = 51.2 m, repeated (its noise
// and features are periodic, so the seams do not show).
constexpr int kGroundTexels = 2048;
constexpr double kGroundTexel = 0.025;
constexpr int kMarkerTexelsPerCell = 32;
constexpr double kNear = 0.05;       // near plane [m]
constexpr double kMaxGround = 1000;  // the ground ends (sky) 1 km away along the axis
// Texture prefilter width in pixel footprints. The sensor integrates each
// pixel over its whole area and the lens and demosaicing blur by about
// another pixel (a system PSF of σ ≈ 0.5–0.7 px, MTF50 near 0.3 cycles/px
// for small-drone cameras), so detail finer than about two footprints does
// not reach the image. Sampling the box-filtered mip level of twice the
// footprint renders that: without it, level 0 was chosen at 10 m (1.25
// texels per pixel) and per-texel grain reached the image at full contrast,
// unlike a real camera (and it tripled OpenCV's contour work on grass).
constexpr double kPrefilterFootprints = 2;
constexpr float kGlareCut = 0.85f;  // cos of the widest angle with visible glare (0.85^40 ≈ 0.002)
const Bgr kSkyBgr{232, 205, 172};   // light blue, seen only at strong tilt

std::uint8_t sat8(double v) { return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0) + 0.5); }
std::uint8_t sat8i(int v) { return static_cast<std::uint8_t>(std::clamp(v, 0, 255)); }

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
constexpr int kGroundTileShift = 6;  // log2(2048 / 32) tiles per row at level 0
inline std::size_t swizzle(unsigned u, unsigned v, int tile_shift) {
  return (static_cast<std::size_t>(((v >> 5) << tile_shift) | (u >> 5)) << 10) | (((v >> 2) & 7u) << 7) |
         (((u >> 2) & 7u) << 4) | ((v & 3u) << 2) | (u & 3u);
}

/// Writes a square BGRA level to `dst`, swizzled.
void swizzle_into(const cv::Mat& bgra, std::uint32_t* dst) {
  int shift = 0;
  while ((32 << shift) < bgra.cols) ++shift;
  for (int v = 0; v < bgra.rows; ++v) {
    const auto* row = bgra.ptr<std::uint32_t>(v);
    for (int u = 0; u < bgra.cols; ++u)
      dst[swizzle(static_cast<unsigned>(u), static_cast<unsigned>(v), shift)] = row[u];
  }
}

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
constexpr int kFieldRes = 512;
cv::Mat fbm(cv::RNG& rng, std::initializer_list<std::pair<int, float>> octaves) {
  cv::Mat sum = cv::Mat::zeros(kFieldRes, kFieldRes, CV_32F);
  for (const auto& [cells, weight] : octaves) sum += weight * periodic_noise(kFieldRes, cells, rng);
  return sum;
}

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

/// The value of `noise` below which a fraction `fraction` of texels lie.
float quantile(const cv::Mat& noise, double fraction) {
  std::vector<float> v;
  v.reserve(static_cast<std::size_t>(noise.total() / 16 + 1));
  for (int y = 0; y < noise.rows; y += 4) {
    const float* row = noise.ptr<float>(y);
    for (int x = 0; x < noise.cols; x += 4) v.push_back(row[x]);
  }
  const auto k = static_cast<std::size_t>(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
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

/// Concrete (city-like): tonal variation, aggregate grain, slab seams every
/// 3.2 m, worn paint (a yellow line, a dashed white line, parking stalls),
/// cracks and oil stains. Float BGR.
cv::Mat concrete_texture(cv::RNG& rng) {
  const int n = kGroundTexels;
  const cv::Mat tone = fbm(rng, {{4, 0.5f}, {16, 0.3f}, {64, 0.2f}});
  const cv::Mat wear = fbm(rng, {{32, 0.6f}, {128, 0.4f}});
  const auto grain_seed = static_cast<std::uint32_t>(rng.next());
  // Stains: dark blotches, blurred, at 512² then upsampled.
  cv::Mat stain = cv::Mat::zeros(512, 512, CV_32F);
  const int stains = 30;
  for (int i = 0; i < stains; ++i) {
    const cv::Point c(rng.uniform(0, 512), rng.uniform(0, 512));
    const cv::Size axes(rng.uniform(4, 26), rng.uniform(4, 18));
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
    cv::Point2d p(rng.uniform(0.0, static_cast<double>(n)), rng.uniform(0.0, static_cast<double>(n)));
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

/// Lawn: grass with clumps, dry and lush patches, fine blade noise. Float BGR.
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

/// Whether the ground has snow or leaf cover at all.
bool has_cover(const Weather& w) { return w.ground_snow > 0 || w.ground_leaves > 0; }

/// A scenario's snow cover and leaf litter: the fixed layers read `shift`
/// texels on, covered to the scenario's fractions. Periodic.
class CoverSampler {
 public:
  CoverSampler() = default;
  CoverSampler(const Weather& w, std::shared_ptr<const CoverBase> base, cv::Point shift)
      : base_(std::move(base)), shift_(shift) {
    snow_a_ = coverage(base_->snow_field, w.ground_snow);
    leaf_a_ = coverage(base_->leaf_field, w.ground_leaves);
  }
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
float wet_darkening(const Weather& w) {
  return 1.0f - 0.35f * static_cast<float>(std::clamp(w.ground_wetness, 0.0, 1.0));
}

/// Halving mip chain of a BGRA image (box filter, exact for periodic maps).
std::vector<cv::Mat> mip_chain(const cv::Mat& level0, int min_side) {
  std::vector<cv::Mat> mips{level0};
  while (mips.back().cols / 2 >= min_side && mips.back().rows / 2 >= min_side) {
    cv::Mat next;
    cv::resize(mips.back(), next, cv::Size(mips.back().cols / 2, mips.back().rows / 2), 0, 0, cv::INTER_AREA);
    mips.push_back(next);
  }
  return mips;
}

// ---- meshes ----

struct Mesh {
  std::vector<Eigen::Vector3d> v;  // vertices (world for static objects, object frame for dynamic ones)
  std::vector<std::array<int, 3>> tri;
  std::vector<float> tint;  // per-triangle colour variation
  Bgr bgr{128, 128, 128};
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // bounding sphere
  double radius = 0;
};

/// A convex solid as triangles in its parent frame, wound outwards.
Mesh tessellate(const Solid& s, std::uint64_t seed) {
  Mesh m;
  m.bgr = s.bgr;
  std::vector<Eigen::Vector3d> v;
  std::vector<std::array<int, 3>> quads_as_tris;
  auto add_tri = [&](int a, int b, int c) { quads_as_tris.push_back({a, b, c}); };
  auto add_quad = [&](int a, int b, int c, int d) {
    add_tri(a, b, c);
    add_tri(a, c, d);
  };
  constexpr int kSides = 16;
  switch (s.shape) {
    case Solid::Shape::box: {
      const Eigen::Vector3d h = 0.5 * s.size;
      for (int i = 0; i < 8; ++i)
        v.emplace_back(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z());
      add_quad(0, 1, 3, 2), add_quad(4, 5, 7, 6), add_quad(0, 1, 5, 4);
      add_quad(2, 3, 7, 6), add_quad(0, 2, 6, 4), add_quad(1, 3, 7, 5);
      break;
    }
    case Solid::Shape::cylinder:
    case Solid::Shape::cone: {
      const double r = s.size.x(), hz = 0.5 * s.size.z();
      const bool cone = s.shape == Solid::Shape::cone;
      for (int i = 0; i < kSides; ++i) {
        const double a = 2 * kPi * i / kSides;
        v.emplace_back(r * std::cos(a), r * std::sin(a), -hz);
        if (!cone) v.emplace_back(r * std::cos(a), r * std::sin(a), hz);
      }
      const int bottom = static_cast<int>(v.size());
      v.emplace_back(0, 0, -hz);
      v.emplace_back(0, 0, hz);
      const int step = cone ? 1 : 2;
      for (int i = 0; i < kSides; ++i) {
        const int a = i * step, b = ((i + 1) % kSides) * step;
        add_tri(bottom, a, b);
        if (cone) {
          add_tri(a, b, bottom + 1);
        } else {
          add_tri(bottom + 1, a + 1, b + 1);
          add_quad(a, b, b + 1, a + 1);
        }
      }
      break;
    }
    case Solid::Shape::sphere:
    case Solid::Shape::capsule: {
      // UV sphere (8 stacks, 12 slices); a capsule splits it at the equator.
      const double r = s.size.x(), hl = s.shape == Solid::Shape::capsule ? 0.5 * s.size.z() : 0.0;
      constexpr int kStacks = 8, kSlices = 12;
      std::vector<double> ring_z, ring_r;
      for (int i = 1; i < kStacks; ++i) {
        const double phi = kPi * i / kStacks, z = r * std::cos(phi), rr = r * std::sin(phi);
        if (i == kStacks / 2 && hl > 0) {
          ring_z.push_back(hl), ring_r.push_back(rr);
          ring_z.push_back(-hl), ring_r.push_back(rr);
        } else {
          ring_z.push_back(z + (z > 0 ? hl : -hl)), ring_r.push_back(rr);
        }
      }
      for (std::size_t k = 0; k < ring_z.size(); ++k) {
        for (int j = 0; j < kSlices; ++j) {
          const double a = 2 * kPi * j / kSlices;
          v.emplace_back(ring_r[k] * std::cos(a), ring_r[k] * std::sin(a), ring_z[k]);
        }
      }
      const int top = static_cast<int>(v.size());
      v.emplace_back(0, 0, r + hl);
      v.emplace_back(0, 0, -r - hl);
      const int rings = static_cast<int>(ring_z.size());
      for (int j = 0; j < kSlices; ++j) {
        const int jn = (j + 1) % kSlices;
        add_tri(top, j, jn);
        add_tri(top + 1, (rings - 1) * kSlices + j, (rings - 1) * kSlices + jn);
        for (int k = 0; k + 1 < rings; ++k)
          add_quad(k * kSlices + j, k * kSlices + jn, (k + 1) * kSlices + jn, (k + 1) * kSlices + j);
      }
      break;
    }
  }
  // Every primitive is convex and centred on its origin: wind each triangle
  // so that its normal points away from the origin.
  for (auto& t : quads_as_tris) {
    const Eigen::Vector3d n = (v[static_cast<std::size_t>(t[1])] - v[static_cast<std::size_t>(t[0])])
                                  .cross(v[static_cast<std::size_t>(t[2])] - v[static_cast<std::size_t>(t[0])]);
    const Eigen::Vector3d c =
        v[static_cast<std::size_t>(t[0])] + v[static_cast<std::size_t>(t[1])] + v[static_cast<std::size_t>(t[2])];
    if (n.squaredNorm() < 1e-24) continue;  // degenerate (zero-size solid)
    if (n.dot(c) < 0) std::swap(t[1], t[2]);
    m.tri.push_back(t);
  }
  for (const auto& p : v) m.v.push_back(s.pose * p);
  Rng rng(seed);
  for (std::size_t i = 0; i < m.tri.size(); ++i) m.tint.push_back(static_cast<float>(rng.uniform(0.93, 1.07)));
  Eigen::Vector3d lo = m.v.front(), hi = m.v.front();
  for (const auto& p : m.v) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  m.centre = 0.5 * (lo + hi);
  for (const auto& p : m.v) m.radius = std::max(m.radius, (p - m.centre).norm());
  return m;
}

// ---- polygon clipping (Sutherland–Hodgman) ----

/// Keeps the part of a 3-D polygon (camera frame) with z ≥ kNear.
void clip_near(const std::vector<Eigen::Vector3d>& in, std::vector<Eigen::Vector3d>& out) {
  out.clear();
  const std::size_t n = in.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& a = in[i];
    const Eigen::Vector3d& b = in[(i + 1) % n];
    const bool ia = a.z() >= kNear, ib = b.z() >= kNear;
    if (ia) out.push_back(a);
    if (ia != ib) out.push_back(a + (b - a) * ((kNear - a.z()) / (b.z() - a.z())));
  }
}

/// Keeps the part of a 2-D polygon inside [x0, x1] × [y0, y1].
void clip_rect(std::vector<Eigen::Vector2d>& poly, std::vector<Eigen::Vector2d>& tmp, double x0, double y0, double x1,
               double y1) {
  auto pass = [&](int axis, double bound, bool keep_above) {
    tmp.clear();
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = poly[i];
      const Eigen::Vector2d& b = poly[(i + 1) % n];
      const bool ia = keep_above ? a[axis] >= bound : a[axis] <= bound;
      const bool ib = keep_above ? b[axis] >= bound : b[axis] <= bound;
      if (ia) tmp.push_back(a);
      if (ia != ib) tmp.push_back(a + (b - a) * ((bound - a[axis]) / (b[axis] - a[axis])));
    }
    poly.swap(tmp);
  };
  pass(0, x0, true);
  pass(0, x1, false);
  pass(1, y0, true);
  pass(1, y1, false);
}

double shoelace(const std::vector<Eigen::Vector2d>& p) {
  double a = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Eigen::Vector2d& q = p[(i + 1) % p.size()];
    a += p[i].x() * q.y() - q.x() * p[i].y();
  }
  return 0.5 * std::abs(a);
}

// ---- markers ----

/// Marker cells (0 black, 255 white) with the one-cell white margin.
cv::Mat marker_cells(const cv::Ptr<cv::aruco::Dictionary>& dict, int bits, DistractorKind kind, int id,
                     int flipped_bits, int target_id, std::uint64_t flip_seed) {
  const int side = bits + 4;
  cv::Mat cells(side, side, CV_8U, cv::Scalar(255));
  cv::Mat inner = cells(cv::Rect(1, 1, bits + 2, bits + 2));
  if (kind == DistractorKind::wrong_id) {
    cv::Mat drawn;
    cv::aruco::drawMarker(dict, id, bits + 2, drawn, 1);
    drawn.copyTo(inner);
    return cells;
  }
  cv::Mat code(bits, bits, CV_8U);
  if (kind == DistractorKind::lookalike) {
    code = cv::aruco::Dictionary::getBitsFromByteList(dict->bytesList.rowRange(target_id, target_id + 1), bits);
    // Invert `flipped_bits` distinct cells, drawn by a partial Fisher–Yates.
    std::vector<int> order(static_cast<std::size_t>(bits * bits));
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    Rng rng(flip_seed);
    const int flips = std::clamp(flipped_bits, 0, bits * bits);
    for (int i = 0; i < flips; ++i) {
      const auto j = static_cast<std::size_t>(i) +
                     static_cast<std::size_t>(rng.next() % (order.size() - static_cast<std::size_t>(i)));
      std::swap(order[static_cast<std::size_t>(i)], order[j]);
      std::uint8_t& c =
          code.at<std::uint8_t>(order[static_cast<std::size_t>(i)] / bits, order[static_cast<std::size_t>(i)] % bits);
      c = c ? 0 : 1;
    }
  } else {  // pattern: a random grid, seeded by its id
    Rng rng(static_cast<std::uint64_t>(id), 0x9A77E28ull);
    for (int r = 0; r < bits; ++r) {
      for (int c = 0; c < bits; ++c) code.at<std::uint8_t>(r, c) = rng.uniform() < 0.5 ? 1 : 0;
    }
  }
  inner.setTo(0);
  for (int r = 0; r < bits; ++r) {
    for (int c = 0; c < bits; ++c) cells.at<std::uint8_t>(r + 2, c + 2) = code.at<std::uint8_t>(r, c) ? 255 : 0;
  }
  return cells;
}

struct Quad {
  Label label = kMarker;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double cos_yaw = 1, sin_yaw = 0;
  double side = 1;                         // with the margin [m]
  std::array<Eigen::Vector3d, 4> corners;  // world, with margin: TL, TR, BR, BL of the image
  std::vector<cv::Mat> mips;               // BGRA
  std::vector<float> level_scale;          // mips[k].cols / mips[0].cols
};

/// The marker image as printed and lying on the ground: paper white, ink
/// black, then the ground's snow/leaf cover at each texel's world point and
/// the wet darkening.
Quad make_quad(const cv::Mat& cells, Label label, const Eigen::Vector2d& centre, double yaw_deg, double border_size,
               int bits, const CoverSampler& cover, const Eigen::Vector2d& map_shift, const Weather& weather) {
  Quad q;
  q.label = label;
  q.centre = centre;
  q.cos_yaw = std::cos(rad(yaw_deg));
  q.sin_yaw = std::sin(rad(yaw_deg));
  q.side = border_size * (bits + 4) / (bits + 2);
  const Eigen::Vector2d ex(q.cos_yaw, q.sin_yaw), ey(-q.sin_yaw, q.cos_yaw);
  const double h = 0.5 * q.side;
  // Image top = local +y, image right = local +x (reads correctly from above).
  const std::array<Eigen::Vector2d, 4> c2{centre - h * ex + h * ey, centre + h * ex + h * ey, centre + h * ex - h * ey,
                                          centre - h * ex - h * ey};
  for (std::size_t i = 0; i < 4; ++i) q.corners[i] = Eigen::Vector3d(c2[i].x(), c2[i].y(), 0);
  const int m = cells.cols * kMarkerTexelsPerCell;
  cv::Mat big;
  cv::resize(cells, big, cv::Size(m, m), 0, 0, cv::INTER_NEAREST);
  cv::Mat img(m, m, CV_8UC4);
  const float dark = wet_darkening(weather);
  const double texel = q.side / m;
  for (int y = 0; y < m; ++y) {
    const std::uint8_t* b = big.ptr<std::uint8_t>(y);
    cv::Vec4b* o = img.ptr<cv::Vec4b>(y);
    for (int x = 0; x < m; ++x) {
      cv::Vec3f c = b[x] ? cv::Vec3f(228, 232, 232) : cv::Vec3f(28, 28, 30);
      if (!cover.empty()) {
        // World point of this texel → map → cover texel (periodic), bilinear.
        const double lx = (x + 0.5) * texel - h, ly = h - (y + 0.5) * texel;
        const Eigen::Vector2d p = centre + lx * ex + ly * ey + map_shift;
        const cv::Point2f t(static_cast<float>(p.x() / kGroundTexel - 0.5),
                            static_cast<float>(p.y() / kGroundTexel - 0.5));
        const int tx = floor_int(t.x), ty = floor_int(t.y);
        const float fx = t.x - static_cast<float>(tx), fy = t.y - static_cast<float>(ty);
        cv::Vec3f acc(0, 0, 0);
        float acc_a = 0;
        for (int k = 0; k < 4; ++k) {
          const float wgt = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
          cv::Vec3f colour;
          float alpha = 0;
          if (cover.at(tx + (k & 1), ty + (k >> 1), &colour, &alpha)) {
            acc += (wgt * alpha) * colour;
            acc_a += wgt * alpha;
          }
        }
        c = c * (1 - acc_a) + acc;
      }
      c *= dark;
      o[x] = cv::Vec4b(sat8(c[0]), sat8(c[1]), sat8(c[2]), 255);
    }
  }
  q.mips = mip_chain(img, 8);
  for (const cv::Mat& level : q.mips) {
    q.level_scale.push_back(static_cast<float>(level.cols) / static_cast<float>(q.mips.front().cols));
  }
  return q;
}

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

constexpr float kInvTexel0 = static_cast<float>(1 / kGroundTexel);  // 40 texels/m, exact

inline void ground_pixel(const GroundRow& g, int x, std::uint8_t* px, std::uint8_t* mk, float* dp) {
  const float fx_ = static_cast<float>(x);
  const float wdepth = (g.rz0 + g.az * fx_) * -g.inv_h;  // 1/depth
  if (!(wdepth > g.w_min)) {
    px[3 * x] = kSkyBgr[0], px[3 * x + 1] = kSkyBgr[1], px[3 * x + 2] = kSkyBgr[2];
    mk[x] = kSky;
    dp[x] = std::numeric_limits<float>::infinity();
    return;
  }
  const float s = 1.0f / wdepth;
  const float X = g.cxw + s * (g.rx0 + g.ax * fx_), Y = g.cyw + s * (g.ry0 + g.ay * fx_);
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
  mk[x] = kGround;
  dp[x] = s;
}

void ground_row_scalar(const GroundRow& g, int x0, int x1, std::uint8_t* px, std::uint8_t* mk, float* dp) {
  for (int x = x0; x < x1; ++x) ground_pixel(g, x, px, mk, dp);
}

#if defined(__x86_64__) && defined(__GNUC__)
bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}

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
  static_assert(kGround == 0, "the label store below writes 0 for the ground");
  const __m256i sky_label = _mm256_set1_epi32(kSky), label_order = _mm256_setr_epi32(0, 4, 1, 5, 2, 6, 3, 7);
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
    // Labels: kGround (0) where valid, kSky elsewhere; 32 → 8 bits per pixel.
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
/// blur_division_exact below).
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

// ---- process-wide caches (render_cache.hpp) ----

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

/// Bitwise equality of doubles: a NaN key finds itself.
bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

/// Everything a map texture depends on.
struct MapTextureKey {
  MapKind map = MapKind::ground;
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

/// A map kind's ground, the same under every scenario on it (the source's
/// two maps are fixed worlds): built once, from the map's own seed.
std::shared_ptr<const cv::Mat> build_map_ground(MapKind map) {
  cv::RNG rng(map == MapKind::ground ? 0x6A09E667ull : 0xBB67AE85ull);
  return std::make_shared<const cv::Mat>(map == MapKind::ground ? concrete_texture(rng) : lawn_texture(rng));
}

SharedCache<MapKind, cv::Mat>& map_ground_cache() {
  static SharedCache<MapKind, cv::Mat> cache(2);  // 16 MiB each
  return cache;
}
SharedCache<int, CoverBase>& cover_base_cache() {
  static SharedCache<int, CoverBase> cache(1);  // 16.5 MiB
  return cache;
}

/// Where on its map a scenario lies and where on the fixed cover layers its
/// cover is read [texels, in [0, 2048)], from its seed: one periodic map
/// gives 2048² scenes, each with a cover pattern of its own.
struct MapPlacement {
  cv::Point ground, cover;
};
MapPlacement map_placement(std::uint64_t seed) {
  static_assert(kGroundTexels == 1 << 11);
  Rng rng(seed, 0x9A9A0ull);
  const auto draw = [&] { return static_cast<int>(rng.next() >> 53); };
  MapPlacement p;
  p.ground.x = draw(), p.ground.y = draw();
  p.cover.x = draw(), p.cover.y = draw();
  return p;
}

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

/// Unit normal draws of the low-light noise tile (256² × 3), from the seed.
constexpr int kNoiseTile = 256;
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

namespace detail {
void clear_render_caches() {
  map_texture_cache().clear();
  map_ground_cache().clear();
  cover_base_cache().clear();
  unit_noise_cache().clear();
}
std::size_t cached_map_textures() { return map_texture_cache().size(); }
}  // namespace detail

struct Renderer::Impl {
  Scenario scenario;
  CameraOptions cam;
  double f = 0, cx = 0, cy = 0;
  Eigen::Isometry3d T_body_camera;

  std::shared_ptr<const MapTexture> map;                // shared with other renderers of the same map (immutable)
  Eigen::Vector2d map_shift = Eigen::Vector2d::Zero();  // world (x, y) + map_shift = where on the map [m]
  std::vector<Quad> quads;                              // distractors, then the target marker (last)

  std::vector<Mesh> static_meshes;
  std::vector<std::vector<Bgr>> static_shade;  // shaded colour per triangle
  std::vector<std::vector<cv::Point2f>> static_shadow;
  std::vector<std::vector<Mesh>> dynamic_meshes;  // per object, in its frame

  Eigen::Vector3d sun = Eigen::Vector3d::UnitZ();  // towards the sun
  double sun_strength = 0;                         // direct light, 0..1
  int shadow_keep = 256;                           // ×/256 in shadow

  // Fog and dust (Koschmieder): transmission by depth, airlight.
  double beta = 0;
  double lut_scale = 0;
  std::vector<std::int32_t> fog_t;  // transmission ×256 by depth bin; the last bin (and beyond) 0
  std::array<std::int32_t, 3> airlight{200, 200, 200};

  // Low light: gain and noise.
  bool low_light = false;
  std::int32_t gain = 256;  // auto-gain, 8.8 fixed point
  cv::Mat noise_tile;       // CV_16SC3, 256², already × sigma

  // Wet glare: the lobe's brightening by cos² of the angle to the sun's
  // mirror image (no pow per pixel), zero below glare_c2_min.
  std::vector<float> glare_add;
  float glare_c2_min = 1, glare_scale = 0;

  // Scratch (no allocation in steady state).
  std::vector<Eigen::Vector3d> poly3, poly3_clip, verts;
  std::vector<Eigen::Vector2d> poly2, poly2_tmp;
  std::vector<cv::Point2f> shadow_pts, hull;
  std::vector<cv::Point> ipoly;
  cv::Mat shadow_mask, overlay, blur_acc, blur_src;
  std::vector<std::int32_t> row_scratch;

  void render(const SceneState& state, CameraFrame& out);
};

namespace {

struct View {
  Eigen::Matrix3d R_cw;
  Eigen::Vector3d t_cw, c;  // world → camera; camera centre in the world
  double h = 0;             // camera height above the ground (≥ 1 cm)
  // Ray through pixel (x, y) in world axes with unit optical-axis component:
  // ray = A·x + B·y + C.
  Eigen::Vector3d A, B, C;
  [[nodiscard]] Eigen::Vector3d cam(const Eigen::Vector3d& p_world) const { return R_cw * p_world + t_cw; }
};

}  // namespace

Renderer::Renderer(const Scenario& scenario, const CameraOptions& camera) : impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!camera.validate(&why)) throw InvalidArgument("camera." + why);
  const pose::detail::ArucoDictionaryInfo* dict_info = pose::detail::find_aruco_dictionary(scenario.marker.dictionary);
  if (!dict_info) {
    throw InvalidArgument("marker.dictionary: unknown " +
                          pose::detail::unknown_aruco_dictionary(scenario.marker.dictionary));
  }
  auto check_id = [&](const std::string& key, int id) {
    if (id < 0 || id >= dict_info->codes) {
      throw InvalidArgument(key + ": " + std::to_string(id) + " is not in " + std::string(dict_info->name) + " (0.." +
                            std::to_string(dict_info->codes - 1) + ")");
    }
  };
  check_id("marker.id", scenario.marker.id);
  if (!(scenario.marker.size > 0 && std::isfinite(scenario.marker.size))) {
    throw InvalidArgument("marker.size: must be positive");
  }
  for (std::size_t i = 0; i < scenario.distractors.size(); ++i) {
    const Distractor& d = scenario.distractors[i];
    const std::string key = "distractors[" + std::to_string(i) + "]";
    if (d.kind == DistractorKind::wrong_id) check_id(key + ".id", d.id);
    if (!(d.size > 0 && std::isfinite(d.size))) throw InvalidArgument(key + ".size: must be positive");
  }

  Impl& m = *impl_;
  m.scenario = scenario;
  m.cam = camera;
  m.f = camera.fx();
  m.cx = 0.5 * (camera.width - 1);
  m.cy = 0.5 * (camera.height - 1);
  m.T_body_camera = camera.T_body_camera();
  const Weather& w = scenario.weather;

  // Ground texture and cover: shared by every renderer of the same map.
  MapTextureKey key;
  key.map = scenario.map;
  key.ground_snow = w.ground_snow;
  key.ground_leaves = w.ground_leaves;
  key.seed = has_cover(w) ? scenario.seed : 0;  // the cover's placement
  key.dark = wet_darkening(w);
  m.map = map_texture_cache().get(key, [&] { return build_map_texture(key); });
  const cv::Point placement = map_placement(scenario.seed).ground;
  m.map_shift = kGroundTexel * Eigen::Vector2d(placement.x, placement.y);
  const CoverSampler& cover = m.map->cover;

  const auto dict = cv::aruco::getPredefinedDictionary(dict_info->id);
  const int bits = dict_info->bits;
  for (std::size_t i = 0; i < scenario.distractors.size(); ++i) {
    const Distractor& d = scenario.distractors[i];
    const cv::Mat cells = marker_cells(dict, bits, d.kind, d.id, d.flipped_bits, scenario.marker.id,
                                       Rng(scenario.seed, 0xD157ull + i).next());
    m.quads.push_back(make_quad(cells, kDistractor, d.position, d.yaw_deg, d.size, bits, cover, m.map_shift, w));
  }
  const cv::Mat target = marker_cells(dict, bits, DistractorKind::wrong_id, scenario.marker.id, 0, 0, 0);
  m.quads.push_back(make_quad(target, kMarker, scenario.marker.position, scenario.marker.yaw_deg, scenario.marker.size,
                              bits, cover, m.map_shift, w));

  // Sun: azimuth counter-clockwise from +x (east), like every yaw here.
  const double el = rad(w.sun_elevation_deg), az = rad(w.sun_azimuth_deg);
  m.sun = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  if (el > 0) {
    // Direct light: weaker for a low sun, and attenuated through a ~30 m
    // fog/dust layer along the slant path (Beer–Lambert).
    const double beta_air = std::max(0.0, w.fog) + 0.05 * std::max(0.0, w.dust);
    m.sun_strength = std::min(1.0, std::sin(el) / std::sin(rad(15))) * std::exp(-beta_air * 30 / std::sin(el));
  }
  m.shadow_keep = static_cast<int>(std::lround(256 * (1 - 0.55 * m.sun_strength)));

  // Objects: tessellated once.
  std::uint64_t mesh_seed = scenario.seed * 7919;
  for (const auto& o : scenario.static_objects) {
    for (const Solid& s : object_solids(o)) m.static_meshes.push_back(tessellate(s, ++mesh_seed));
  }
  for (const auto& o : scenario.dynamic_objects) {
    auto& meshes = m.dynamic_meshes.emplace_back();
    for (const Solid& s : object_solids(o)) meshes.push_back(tessellate(s, ++mesh_seed));
  }
  auto shade = [&](const Mesh& mesh, std::size_t t, const Eigen::Vector3d& n) {
    // Lambert: sky light (ambient) + sun; a top face under a 50° sun ≈ 1.
    const double lambert = 0.55 + 0.6 * m.sun_strength * std::max(0.0, n.dot(m.sun));
    const double k = lambert * mesh.tint[t];
    return Bgr{sat8(mesh.bgr[0] * k), sat8(mesh.bgr[1] * k), sat8(mesh.bgr[2] * k)};
  };
  for (const Mesh& mesh : m.static_meshes) {
    auto& colours = m.static_shade.emplace_back();
    for (std::size_t t = 0; t < mesh.tri.size(); ++t) {
      const auto& tri = mesh.tri[t];
      const Eigen::Vector3d& a = mesh.v[static_cast<std::size_t>(tri[0])];
      const Eigen::Vector3d n = (mesh.v[static_cast<std::size_t>(tri[1])] - a)
                                    .cross(mesh.v[static_cast<std::size_t>(tri[2])] - a)
                                    .normalized();
      colours.push_back(shade(mesh, t, n));
    }
  }
  // Static shadows: ground polygons, once.
  if (m.sun_strength > 0.02 && m.sun.z() > std::sin(rad(3))) {
    for (const Mesh& mesh : m.static_meshes) {
      std::vector<cv::Point2f> pts, hull;
      for (const auto& p : mesh.v) {
        const Eigen::Vector3d g = p - (std::max(0.0, p.z()) / m.sun.z()) * m.sun;
        pts.emplace_back(static_cast<float>(g.x()), static_cast<float>(g.y()));
      }
      cv::convexHull(pts, hull);
      m.static_shadow.push_back(hull);
    }
  }

  // Fog and dust: extinction coefficients add; the airlight is their
  // extinction-weighted colour (grey fog, tan dust).
  const double beta_dust = 0.05 * std::max(0.0, w.dust);
  m.beta = std::max(0.0, w.fog) + beta_dust;
  if (m.beta > 1e-6) {
    const double range = 12 / m.beta;  // beyond: t < 1e-5
    m.fog_t.resize(4096);
    m.lut_scale = static_cast<double>(m.fog_t.size() - 1) / range;
    for (std::size_t i = 0; i < m.fog_t.size(); ++i) {
      m.fog_t[i] =
          static_cast<std::int32_t>(std::lround(256 * std::exp(-m.beta * static_cast<double>(i) / m.lut_scale)));
    }
    m.fog_t.back() = 0;
    const double wf = std::max(0.0, w.fog) / m.beta, wd = beta_dust / m.beta;
    const std::array<double, 3> fog_a{205, 205, 200}, dust_a{135, 175, 205};
    for (std::size_t c = 0; c < 3; ++c) m.airlight[c] = static_cast<int>(std::lround(wf * fog_a[c] + wd * dust_a[c]));
  }

  // Wet-ground glare (render step 5): brightening = amplitude × lobe(cos a),
  // tabulated over c² = cos² a ∈ [kGlareCut², 1] and interpolated linearly.
  if (w.ground_wetness > 0 && m.sun_strength > 0) {
    const double amplitude = 255 * std::clamp(w.ground_wetness, 0.0, 1.0) * m.sun_strength;
    constexpr int kBins = 4096;
    constexpr double c2_lo = static_cast<double>(kGlareCut) * kGlareCut;
    m.glare_add.resize(kBins + 2);
    m.glare_scale = static_cast<float>(kBins / (1 - c2_lo));
    m.glare_c2_min = 2;  // nothing visible unless a bin says otherwise
    for (int i = 0; i <= kBins + 1; ++i) {
      const double c2 = std::min(1.0, c2_lo + (1 - c2_lo) * i / kBins), cos_a = std::sqrt(c2);
      const double lobe = 0.9 * std::pow(cos_a, 600.0) + 0.35 * std::pow(cos_a, 40.0);
      m.glare_add[static_cast<std::size_t>(i)] = static_cast<float>(amplitude * lobe);
      // Below one level nothing shows (the add is truncated to an integer):
      // the first bin over it bounds the pixels worth looking at.
      if (amplitude * lobe >= 1 && m.glare_c2_min > 1) {
        m.glare_c2_min = static_cast<float>(c2_lo + (1 - c2_lo) * std::max(0, i - 1) / kBins);
      }
    }
  }

  // Low light: the camera's auto-gain makes up part of the missing light
  // (brightness ∝ ambient^0.6) and amplifies read and shot noise with it
  // (sigma grows as 1/sqrt(ambient)).
  const double ambient = std::max(0.0, w.ambient);
  m.low_light = std::abs(ambient - 1.0) > 1e-9;
  if (m.low_light) {
    m.gain = static_cast<std::int32_t>(std::lround(256 * std::pow(std::max(ambient, 1e-3), 0.6)));
    const double sigma = ambient < 1 ? std::min(30.0, 3.0 * (1.0 / std::sqrt(std::max(ambient, 0.01)) - 1.0)) : 0.0;
    m.noise_tile.create(256, 256, CV_16SC3);
    const auto unit = unit_noise_cache().get(scenario.seed, [&] { return build_unit_noise(scenario.seed); });
    const double* n = unit->data();
    for (int y = 0; y < kNoiseTile; ++y) {
      auto* row = m.noise_tile.ptr<std::int16_t>(y);
      for (int x = 0; x < kNoiseTile * 3; ++x) row[x] = static_cast<std::int16_t>(std::lround(sigma * *n++));
    }
  }
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;
const CameraOptions& Renderer::camera() const { return impl_->cam; }

void Renderer::render(const SceneState& state, CameraFrame& out) { impl_->render(state, out); }

void Renderer::Impl::render(const SceneState& state, CameraFrame& out) {
  if (state.T_world_dynamic.size() != scenario.dynamic_objects.size()) {
    throw InvalidArgument("state.T_world_dynamic: " + std::to_string(state.T_world_dynamic.size()) + " poses for " +
                          std::to_string(scenario.dynamic_objects.size()) + " dynamic objects");
  }
  const int W = cam.width, H = cam.height;
  const auto npix = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  out.width = W;
  out.height = H;
  out.image.resize(W, H);
  out.mask.resize(npix);
  out.depth.resize(npix);
  cv::Mat img(H, W, CV_8UC3, out.image.pixels.data());
  std::uint8_t* mask = out.mask.data();
  float* depth = out.depth.data();
  const Weather& weather = scenario.weather;

  View v;
  const Eigen::Isometry3d T_world_camera = state.T_world_body * T_body_camera;
  const Eigen::Matrix3d R_wc = T_world_camera.linear();
  v.R_cw = R_wc.transpose();
  v.c = T_world_camera.translation();
  v.t_cw = -(v.R_cw * v.c);
  // A camera at or below the ground sees it from 1 cm (a landed drone's
  // camera is above it; this only keeps the maths finite).
  v.h = std::max(v.c.z(), 0.01);
  v.A = R_wc.col(0) / f;
  v.B = R_wc.col(1) / f;
  v.C = R_wc.col(2) - v.A * cx - v.B * cy;
  const auto project = [&](const Eigen::Vector3d& pc) {
    return Eigen::Vector2d(f * pc.x() / pc.z() + cx, f * pc.y() / pc.z() + cy);
  };

  // ---- 1. ground ----
  {
    GroundRow g;
    g.texels = map->texels.get();
    g.offsets = map->offsets.data();
    g.levels = map->levels;
    g.inv_h = static_cast<float>(1 / v.h);
    g.w_min = static_cast<float>(1 / kMaxGround);
    g.cxw = static_cast<float>(v.c.x() + map_shift.x());
    g.cyw = static_cast<float>(v.c.y() + map_shift.y());
    g.lod = static_cast<float>(kPrefilterFootprints / (f * kGroundTexel));
    g.ax = static_cast<float>(v.A.x()), g.ay = static_cast<float>(v.A.y()), g.az = static_cast<float>(v.A.z());
    g.width = W;
    const bool avx2 = has_avx2();
    for (int y = 0; y < H; ++y) {
      const Eigen::Vector3d r0 = v.B * y + v.C;
      g.rx0 = static_cast<float>(r0.x()), g.ry0 = static_cast<float>(r0.y()), g.rz0 = static_cast<float>(r0.z());
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      float* dp = depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      // The AVX2 kernel stores 16 bytes per 4 pixels: it leaves the last
      // pixels of the image to the scalar one (same arithmetic, same bits).
      const int done = avx2 ? ground_row_avx2(g, px, mk, dp, y + 1 < H ? W : W - 8) : 0;
      ground_row_scalar(g, done, W, px, mk, dp);
    }
  }

  // Clips a world polygon on the ground to the image; result in poly2.
  const auto ground_polygon_in_image = [&](auto&& world_point, std::size_t count) {
    poly3.clear();
    for (std::size_t i = 0; i < count; ++i) poly3.push_back(v.cam(world_point(i)));
    clip_near(poly3, poly3_clip);
    poly2.clear();
    for (const auto& p : poly3_clip) poly2.push_back(project(p));
    if (poly2.size() >= 3) clip_rect(poly2, poly2_tmp, -0.5, -0.5, W - 0.5, H - 0.5);
    return poly2.size() >= 3;
  };

  // ---- 2. markers and distractors ----
  out.marker_area_truth_px = 0;
  out.marker_area_visible_px = 0;
  cv::Rect marker_box;
  for (const Quad& q : quads) {
    if (!ground_polygon_in_image([&](std::size_t i) { return q.corners[i]; }, 4)) continue;
    if (q.label == kMarker) out.marker_area_truth_px = shoelace(poly2);
    double x0 = W, x1 = -1, y0 = H, y1 = -1;
    for (const auto& p : poly2)
      x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
    const int bx0 = std::max(0, static_cast<int>(std::ceil(x0))),
              bx1 = std::min(W - 1, static_cast<int>(std::floor(x1)));
    const int by0 = std::max(0, static_cast<int>(std::ceil(y0))),
              by1 = std::min(H - 1, static_cast<int>(std::floor(y1)));
    if (q.label == kMarker) marker_box = cv::Rect(bx0, by0, std::max(0, bx1 - bx0 + 1), std::max(0, by1 - by0 + 1));
    const int levels = static_cast<int>(q.mips.size());
    const int m0 = q.mips.front().cols;
    const double texel0 = q.side / m0;
    const float lod = static_cast<float>(kPrefilterFootprints / (f * texel0));
    // World (X, Y) → marker image coordinates at level 0: a = ex·d/texel, b = −ey·d/texel.
    const float inv_t = static_cast<float>(1 / texel0);
    const float ecx = static_cast<float>(q.cos_yaw), esy = static_cast<float>(q.sin_yaw);
    const float half = 0.5f * static_cast<float>(m0);
    const float dx0 = static_cast<float>(v.c.x() - q.centre.x()), dy0 = static_cast<float>(v.c.y() - q.centre.y());
    const float ax = static_cast<float>(v.A.x()), ay = static_cast<float>(v.A.y());
    for (int y = by0; y <= by1; ++y) {
      const Eigen::Vector3d r0 = v.B * y + v.C;
      const float rx0 = static_cast<float>(r0.x()), ry0 = static_cast<float>(r0.y());
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      const float* dp = depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      for (int x = bx0; x <= bx1; ++x) {
        if (mk[x] == kSky) continue;
        const float fx_ = static_cast<float>(x);
        const float s = dp[x];  // the ground pass's depth: the same ray meets the same plane
        const float dX = dx0 + s * (rx0 + ax * fx_), dY = dy0 + s * (ry0 + ay * fx_);
        const float a = (dX * ecx + dY * esy) * inv_t + half;   // along image columns
        const float b = half - (-dX * esy + dY * ecx) * inv_t;  // along image rows
        if (!(a >= 0 && a < static_cast<float>(m0) && b >= 0 && b < static_cast<float>(m0))) continue;
        const int k = mip_level(s * lod, levels);
        const cv::Mat& mip = q.mips[static_cast<std::size_t>(k)];
        const float scale = q.level_scale[static_cast<std::size_t>(k)];
        const float u = std::clamp(a * scale - 0.5f, 0.0f, static_cast<float>(mip.cols - 1));
        const float vv = std::clamp(b * scale - 0.5f, 0.0f, static_cast<float>(mip.rows - 1));
        const int ui = static_cast<int>(u), vi = static_cast<int>(vv);
        const int u1 = std::min(ui + 1, mip.cols - 1), v1 = std::min(vi + 1, mip.rows - 1);
        const auto tu = static_cast<std::uint32_t>((u - static_cast<float>(ui)) * 256.0f);
        const auto tv = static_cast<std::uint32_t>((vv - static_cast<float>(vi)) * 256.0f);
        const auto* r0p = mip.ptr<std::uint32_t>(vi);
        const auto* r1p = mip.ptr<std::uint32_t>(v1);
        const std::uint32_t c = lerp_bgra(lerp_bgra(r0p[ui], r0p[u1], tu), lerp_bgra(r1p[ui], r1p[u1], tu), tv);
        px[3 * x] = static_cast<std::uint8_t>(c);
        px[3 * x + 1] = static_cast<std::uint8_t>(c >> 8);
        px[3 * x + 2] = static_cast<std::uint8_t>(c >> 16);
        mk[x] = q.label;
      }
    }
  }

  // ---- 3. sun shadows of the objects on the ground and markers ----
  // (drawn into shadow_mask first: the wet glare needs the sun, too)
  bool shadows_drawn = false;
  cv::Rect shadow_box;
  if (shadow_keep < 256 && sun.z() > std::sin(rad(3))) {
    if (shadow_mask.rows != H || shadow_mask.cols != W) shadow_mask = cv::Mat::zeros(H, W, CV_8U);
    int sx0 = W, sy0 = H, sx1 = -1, sy1 = -1;
    const auto draw_shadow = [&](const std::vector<cv::Point2f>& ground_hull) {
      if (ground_hull.size() < 3) return;
      const auto corner = [&](std::size_t i) { return Eigen::Vector3d(ground_hull[i].x, ground_hull[i].y, 0); };
      if (!ground_polygon_in_image(corner, ground_hull.size())) return;
      ipoly.clear();
      for (const auto& p : poly2) {
        ipoly.emplace_back(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16)));
        sx0 = std::min(sx0, static_cast<int>(std::floor(p.x()))),
        sx1 = std::max(sx1, static_cast<int>(std::ceil(p.x())));
        sy0 = std::min(sy0, static_cast<int>(std::floor(p.y()))),
        sy1 = std::max(sy1, static_cast<int>(std::ceil(p.y())));
      }
      cv::fillConvexPoly(shadow_mask, ipoly, cv::Scalar(1), cv::LINE_8, 4);
    };
    for (const auto& hull_w : static_shadow) draw_shadow(hull_w);
    for (std::size_t i = 0; i < dynamic_meshes.size(); ++i) {
      const Eigen::Isometry3d& T = state.T_world_dynamic[i];
      for (const Mesh& mesh : dynamic_meshes[i]) {
        shadow_pts.clear();
        for (const auto& p_local : mesh.v) {
          const Eigen::Vector3d p = T * p_local;
          const Eigen::Vector3d g = p - (std::max(0.0, p.z()) / sun.z()) * sun;
          shadow_pts.emplace_back(static_cast<float>(g.x()), static_cast<float>(g.y()));
        }
        cv::convexHull(shadow_pts, hull);
        draw_shadow(hull);
      }
    }
    shadows_drawn = true;
    shadow_box = cv::Rect(sx0, sy0, sx1 - sx0 + 1, sy1 - sy0 + 1);
  }

  // Wet-ground glare: the sun's mirror image in the water film, a Blinn–Phong
  // style lobe about the mirror direction of the view ray (sharp core from a
  // smooth film plus a broad lobe from the rough surface under it).
  const bool shadows_on = shadows_drawn;
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
        const float fx_ = static_cast<float>(x);
        const float rx = rx0 + ax * fx_, ry = ry0 + ay * fx_, rz = rz0 + az * fx_;
        // Mirror of the (downward) ray about the ground normal, dotted with the sun.
        const float num = rx * lx + ry * ly - rz * lz;
        if (num <= 0) continue;
        const float len2 = rx * rx + ry * ry + rz * rz;
        if (num * num < c2_min * len2 || mk[x] > kDistractor) continue;
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

  if (shadows_drawn) {
    int sx0 = shadow_box.x, sy0 = shadow_box.y, sx1 = shadow_box.x + shadow_box.width - 1,
        sy1 = shadow_box.y + shadow_box.height - 1;
    sx0 = std::max(sx0, 0), sy0 = std::max(sy0, 0), sx1 = std::min(sx1, W - 1), sy1 = std::min(sy1, H - 1);
    const auto keep = static_cast<unsigned>(shadow_keep);
    for (int y = sy0; y <= sy1; ++y) {
      std::uint8_t* sm = shadow_mask.ptr<std::uint8_t>(y);
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      const std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      for (int x = sx0; x <= sx1; ++x) {
        if (!sm[x]) continue;
        sm[x] = 0;
        if (mk[x] > kDistractor) continue;  // ground, marker and distractors only
        for (int c = 0; c < 3; ++c) px[3 * x + c] = static_cast<std::uint8_t>((px[3 * x + c] * keep) >> 8);
      }
    }
  }

  // ---- 4. objects: near-plane clipping and a z-buffer ----
  const auto raster = [&](const Eigen::Vector3d& qa, const Eigen::Vector3d& qb, const Eigen::Vector3d& qc,
                          const Bgr& col, std::uint8_t label) {
    // Screen position and 1/z, which is affine in screen space.
    Eigen::Vector3d a(f * qa.x() / qa.z() + cx, f * qa.y() / qa.z() + cy, 1 / qa.z());
    Eigen::Vector3d b(f * qb.x() / qb.z() + cx, f * qb.y() / qb.z() + cy, 1 / qb.z());
    Eigen::Vector3d c(f * qc.x() / qc.z() + cx, f * qc.y() / qc.z() + cy, 1 / qc.z());
    double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) return;
    if (area < 0) std::swap(b, c), area = -area;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(W - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(H - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    if (x0 > x1 || y0 > y1) return;
    // Edge function of P→Q at (x, y): (Q.x − P.x)(y − P.y) − (Q.y − P.y)(x − P.x).
    const auto edge = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    const double ea_dx = -(c.y() - b.y()), eb_dx = -(a.y() - c.y()), ec_dx = -(b.y() - a.y());
    const double inv_area = 1 / area;
    const double w_dx = (ea_dx * a.z() + eb_dx * b.z() + ec_dx * c.z()) * inv_area;
    for (int y = y0; y <= y1; ++y) {
      // The row's span inside all three edges (a pixel wider each side; the
      // test below decides), so thin triangles do not walk their whole box.
      double lo = x0, hi = x1;
      const auto bound = [&](double e0, double dx) {
        if (dx > 0) {
          lo = std::max(lo, x0 - e0 / dx);
        } else if (dx < 0) {
          hi = std::min(hi, x0 - e0 / dx);
        } else if (e0 < 0) {
          hi = -1;
        }
      };
      bound(edge(b, c, x0, y), ea_dx), bound(edge(c, a, x0, y), eb_dx), bound(edge(a, b, x0, y), ec_dx);
      if (!(lo <= hi + 2)) continue;
      const int xs = std::max(x0, static_cast<int>(std::floor(lo)) - 1);
      const int xe = std::min(x1, static_cast<int>(std::ceil(hi)) + 1);
      double ea = edge(b, c, xs, y), eb = edge(c, a, xs, y), ec = edge(a, b, xs, y);
      double wz = (ea * a.z() + eb * b.z() + ec * c.z()) * inv_area;
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      for (int x = xs; x <= xe; ++x, ea += ea_dx, eb += eb_dx, ec += ec_dx, wz += w_dx) {
        if (ea < 0 || eb < 0 || ec < 0 || !(wz > 0)) continue;
        const auto z = static_cast<float>(1 / wz);
        if (!(z < depth[row + static_cast<std::size_t>(x)])) continue;
        depth[row + static_cast<std::size_t>(x)] = z;
        mask[row + static_cast<std::size_t>(x)] = label;
        px[3 * x] = col[0], px[3 * x + 1] = col[1], px[3 * x + 2] = col[2];
      }
    }
  };
  const double tan_x = 0.5 * W / f, tan_y = 0.5 * H / f;
  const double norm_x = std::sqrt(1 + tan_x * tan_x), norm_y = std::sqrt(1 + tan_y * tan_y);
  const auto in_view = [&](const Eigen::Vector3d& centre_world, double r) {
    const Eigen::Vector3d q = v.cam(centre_world);
    if (q.z() < kNear - r) return false;
    if ((std::abs(q.x()) - tan_x * q.z()) / norm_x > r) return false;
    return (std::abs(q.y()) - tan_y * q.z()) / norm_y <= r;
  };
  const auto draw_mesh = [&](const Mesh& mesh, const Eigen::Isometry3d* T, const std::vector<Bgr>* shaded,
                             std::uint8_t label) {
    verts.resize(mesh.v.size());
    for (std::size_t i = 0; i < mesh.v.size(); ++i) verts[i] = T ? (*T) * mesh.v[i] : mesh.v[i];
    for (std::size_t t = 0; t < mesh.tri.size(); ++t) {
      const auto& tri = mesh.tri[t];
      const Eigen::Vector3d& p0 = verts[static_cast<std::size_t>(tri[0])];
      const Eigen::Vector3d& p1 = verts[static_cast<std::size_t>(tri[1])];
      const Eigen::Vector3d& p2 = verts[static_cast<std::size_t>(tri[2])];
      const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
      if (n.dot(p0 - v.c) >= 0) continue;  // back face
      Bgr col;
      if (shaded) {
        col = (*shaded)[t];
      } else {
        const double lambert = 0.55 + 0.6 * sun_strength * std::max(0.0, n.normalized().dot(sun));
        const double k = lambert * mesh.tint[t];
        col = Bgr{sat8(mesh.bgr[0] * k), sat8(mesh.bgr[1] * k), sat8(mesh.bgr[2] * k)};
      }
      const Eigen::Vector3d q0 = v.cam(p0), q1 = v.cam(p1), q2 = v.cam(p2);
      const int inside = (q0.z() >= kNear) + (q1.z() >= kNear) + (q2.z() >= kNear);
      if (inside == 0) continue;
      if (inside == 3) {
        raster(q0, q1, q2, col, label);
        continue;
      }
      poly3.assign({q0, q1, q2});
      clip_near(poly3, poly3_clip);
      for (std::size_t k = 1; k + 1 < poly3_clip.size(); ++k)
        raster(poly3_clip[0], poly3_clip[k], poly3_clip[k + 1], col, label);
    }
  };
  for (std::size_t i = 0; i < static_meshes.size(); ++i) {
    if (in_view(static_meshes[i].centre, static_meshes[i].radius)) {
      draw_mesh(static_meshes[i], nullptr, &static_shade[i], kStaticObject);
    }
  }
  for (std::size_t i = 0; i < dynamic_meshes.size(); ++i) {
    const Eigen::Isometry3d& T = state.T_world_dynamic[i];
    for (const Mesh& mesh : dynamic_meshes[i]) {
      if (in_view(T * mesh.centre, mesh.radius)) draw_mesh(mesh, &T, nullptr, kDynamicObject);
    }
  }

  // The target's visible area: its label survives where nothing covers it.
  for (int y = marker_box.y; y < marker_box.y + marker_box.height; ++y) {
    const std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    int count = 0;
    for (int x = marker_box.x; x < marker_box.x + marker_box.width; ++x) count += mk[x] == kMarker;
    out.marker_area_visible_px += count;
  }

  // ---- 5. weather ----
  // Fog and dust: Koschmieder's law per pixel, sky = airlight.
  row_scratch.resize(static_cast<std::size_t>(W));
  if (beta > 1e-6) {
    const auto last = static_cast<float>(fog_t.size() - 1);
    const float scale = static_cast<float>(lut_scale);
    for (int y = 0; y < H; ++y) {
      fog_row(img.ptr<std::uint8_t>(y), depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W), W,
              fog_t.data(), scale, last, airlight.data(), row_scratch.data());
    }
  }

  // Motion blur: the image moves by the ground's image velocity × exposure;
  // average shifted copies along it (a box kernel along the motion).
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

  // Particles between the camera and the scene, seeded by (seed, frame).
  Rng rng(scenario.seed, 0x5CE9E00000000ull + static_cast<std::uint32_t>(state.frame_index));
  const double exposure = std::max(cam.exposure_s, 1e-3);
  const auto sample = [&](double z_min, double z_max, Eigen::Vector3d& p) {
    const double u = rng.uniform(-0.1 * W, 1.1 * W), vv = rng.uniform(-0.1 * H, 1.1 * H);
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
    const int drops = static_cast<int>(std::lround(3000 * weather.rain));
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
    const int flakes = static_cast<int>(std::lround(2500 * weather.snow));
    for (int i = 0; i < flakes; ++i) {
      Eigen::Vector3d p;
      const bool visible = sample(0.3, 12, p);
      const Eigen::Vector3d vel(rng.normal(0, 0.3), rng.normal(0, 0.3), -rng.uniform(0.7, 1.3));
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
    const int leaves = static_cast<int>(std::lround(40 * weather.leaves));
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

  // Low light: auto-gain brightness and amplified sensor noise (a noise tile
  // at a random offset per frame: cheap, and no two frames alike).
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
