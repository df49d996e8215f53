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
#include <cmath>
#include <limits>
#include <memory>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pose/aruco_dictionary.hpp"
#include "scenario/render_internal.hpp"
#include "scenario/render_kernels.hpp"
#include "scenario/render_map.hpp"
#include "scenario/render_marker.hpp"
#include "scenario/render_mesh.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/geometry.hpp"

namespace touchdown::scenario {

using render_detail::add_row;
using render_detail::average_row;
using render_detail::Bgr;
using render_detail::blur_divisor_mul;
using render_detail::clip_near;
using render_detail::clip_rect;
using render_detail::CoverSampler;
using render_detail::fog_row;
using render_detail::ground_row_avx2;
using render_detail::ground_row_scalar;
using render_detail::GroundRow;
using render_detail::has_avx2;
using render_detail::has_cover;
using render_detail::kGlareCut;
using render_detail::kGroundTexel;
using render_detail::kMaxGround;
using render_detail::kNear;
using render_detail::kNoiseTile;
using render_detail::kPrefilterFootprints;
using render_detail::lerp_bgra;
using render_detail::low_light_row;
using render_detail::make_quad;
using render_detail::map_placement;
using render_detail::MapTexture;
using render_detail::MapTextureKey;
using render_detail::marker_cells;
using render_detail::Mesh;
using render_detail::mip_level;
using render_detail::Quad;
using render_detail::rad;
using render_detail::rain_row;
using render_detail::sat8;
using render_detail::sat8i;
using render_detail::shared_map_texture;
using render_detail::shared_unit_noise;
using render_detail::shoelace;
using render_detail::tessellate;
using render_detail::wet_darkening;

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
  m.map = shared_map_texture(key);
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
    const auto unit = shared_unit_noise(scenario.seed);
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
