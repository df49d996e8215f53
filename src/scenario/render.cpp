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
//     image (so the marker stays sharp from 1 m), label Label::Marker/Distractor;
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
//
// The renderer's files: render.cpp (construction; render() as the sequence
// of passes), render_passes.cpp (passes 1–4), render_weather.cpp (pass 5),
// render_kernels.cpp (the row kernels and their AVX2 dispatch),
// render_texture.cpp (ground textures and cover), render_marker.cpp (marker
// images), render_mesh.cpp (tessellation and clipping), render_cache.cpp
// (the process-wide caches) and camera.cpp (CameraOptions).
#include <algorithm>
#include <cmath>
#include <memory>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>

#include "scenario/render_impl.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/geometry.hpp"

namespace touchdown::scenario {

using render_detail::Bgr;
using render_detail::CoverSampler;
using render_detail::has_cover;
using render_detail::kGlareCut;
using render_detail::kGroundTexel;
using render_detail::kNoiseTile;
using render_detail::make_quad;
using render_detail::map_placement;
using render_detail::MapTextureKey;
using render_detail::marker_cells;
using render_detail::Mesh;
using render_detail::sat8;
using render_detail::shared_map_texture;
using render_detail::shared_unit_noise;
using render_detail::tessellate;
using render_detail::wet_darkening;

namespace {

/// Checks the camera options and the scenario's marker and distractors
/// (throws InvalidArgument); returns the marker's dictionary.
const pose::ArucoDictionaryInfo* checked_dictionary(const Scenario& scenario, const CameraOptions& camera) {
  std::string why;
  if (!camera.validate(&why)) throw InvalidArgument("camera." + why);
  const pose::ArucoDictionaryInfo* dict_info = pose::find_aruco_dictionary(scenario.marker.dictionary);
  if (!dict_info) {
    throw InvalidArgument("marker.dictionary: unknown " + pose::unknown_aruco_dictionary(scenario.marker.dictionary));
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
    if (d.kind == DistractorKind::WrongId) check_id(key + ".id", d.id);
    if (!(d.size > 0 && std::isfinite(d.size))) throw InvalidArgument(key + ".size: must be positive");
  }
  return dict_info;
}

}  // namespace

ParticleWindow particle_window(const CameraOptions& camera) {
  // The same expressions for the default camera and any other, so that the
  // default's window is the one it always had ([−0.1 W, 1.1 W] ×
  // [−0.1 H, 1.1 H]) and its scale exactly 1.
  const auto window = [](const CameraOptions& c, const CameraOptions& reference) {
    ParticleWindow w;
    const double f = c.fx(), f0 = reference.fx();
    const double mx = 0.1 * reference.width * (f / f0), my = 0.1 * reference.height * (f / f0);
    if (0.1 * c.width >= mx && 0.1 * c.height >= my) {
      w.u_lo = -0.1 * c.width, w.u_hi = 1.1 * c.width;
      w.v_lo = -0.1 * c.height, w.v_hi = 1.1 * c.height;
    } else {
      const double ax = std::max(mx, 0.1 * c.width), ay = std::max(my, 0.1 * c.height);
      w.u_lo = -ax, w.u_hi = c.width + ax;
      w.v_lo = -ay, w.v_hi = c.height + ay;
    }
    w.scale = (w.u_hi - w.u_lo) * (w.v_hi - w.v_lo) / (f * f);
    return w;
  };
  const CameraOptions reference;
  ParticleWindow w = window(camera, reference);
  w.scale /= window(reference, reference).scale;
  return w;
}

Renderer::Renderer(const Scenario& scenario, const CameraOptions& camera) : impl_(std::make_unique<Impl>()) {
  const pose::ArucoDictionaryInfo* dict_info = checked_dictionary(scenario, camera);

  Impl& m = *impl_;
  m.scenario = scenario;
  m.cam = camera;
  m.f = camera.fx();
  m.cx = 0.5 * (camera.width - 1);
  m.cy = 0.5 * (camera.height - 1);
  m.particles = particle_window(camera);
  m.T_body_camera = camera.T_body_camera();
  Impl::build_ground_and_markers(m, scenario, dict_info);
  Impl::build_sun(m, scenario);
  Impl::build_objects(m, scenario);
  Impl::build_fog(m, scenario);
  Impl::build_glare(m, scenario);
  Impl::build_low_light(m, scenario);
}

void Renderer::Impl::build_ground_and_markers(Impl& m, const Scenario& scenario,
                                              const pose::ArucoDictionaryInfo* dict_info) {
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

  const auto dict = cv::aruco::getPredefinedDictionary(dict_info->opencv_id);
  const int bits = dict_info->bits;
  for (std::size_t i = 0; i < scenario.distractors.size(); ++i) {
    const Distractor& d = scenario.distractors[i];
    const cv::Mat cells = marker_cells(dict, bits, d.kind, d.id, d.flipped_bits, scenario.marker.id,
                                       Rng(scenario.seed, 0xD157ull + i).next());
    m.quads.push_back(make_quad(cells, Label::Distractor, d.position, d.yaw_deg, d.size, bits, cover, m.map_shift, w));
  }
  const cv::Mat target = marker_cells(dict, bits, DistractorKind::WrongId, scenario.marker.id, 0, 0, 0);
  m.quads.push_back(make_quad(target, Label::Marker, scenario.marker.position, scenario.marker.yaw_deg,
                              scenario.marker.size, bits, cover, m.map_shift, w));
}

void Renderer::Impl::build_sun(Impl& m, const Scenario& scenario) {
  const Weather& w = scenario.weather;
  // Sun: azimuth counter-clockwise from +x (east), like every yaw here.
  const double el = deg_to_rad(w.sun_elevation_deg), az = deg_to_rad(w.sun_azimuth_deg);
  m.sun = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  if (el > 0) {
    // Direct light: weaker for a low sun, and attenuated through a ~30 m
    // fog/dust layer along the slant path (Beer–Lambert).
    const double beta_air = std::max(0.0, w.fog) + 0.05 * std::max(0.0, w.dust);
    m.sun_strength = std::min(1.0, std::sin(el) / std::sin(deg_to_rad(15))) * std::exp(-beta_air * 30 / std::sin(el));
  }
  m.shadow_keep = static_cast<int>(std::lround(256 * (1 - 0.55 * m.sun_strength)));
}

void Renderer::Impl::build_objects(Impl& m, const Scenario& scenario) {
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
  if (m.sun_strength > 0.02 && m.sun.z() > std::sin(deg_to_rad(3))) {
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
}

void Renderer::Impl::build_fog(Impl& m, const Scenario& scenario) {
  const Weather& w = scenario.weather;
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
}

void Renderer::Impl::build_glare(Impl& m, const Scenario& scenario) {
  const Weather& w = scenario.weather;
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
}

void Renderer::Impl::build_low_light(Impl& m, const Scenario& scenario) {
  const Weather& w = scenario.weather;
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
  Frame fr = begin_frame(state, out);
  ground_pass(fr);
  const cv::Rect marker_box = markers_pass(fr, out);
  // Sun shadows go into shadow_mask first: the wet glare needs to know where
  // the sun shines. Then they darken the ground, markers and distractors.
  const std::optional<cv::Rect> shadow_box = shadows_pass(fr, state);
  glare_pass(fr, shadow_box.has_value());
  if (shadow_box) apply_shadows(fr, *shadow_box);
  objects_pass(fr, state);
  count_visible_marker(fr, marker_box, out);
  fog_pass(fr);
  motion_blur_pass(fr, state);
  // Particles between the camera and the scene, seeded by (seed, frame).
  Rng rng(scenario.seed, 0x5CE9E00000000ull + static_cast<std::uint32_t>(state.frame_index));
  particles_pass(fr, state, rng);
  low_light_pass(fr, rng);
}

/// Sizes the output, wraps its buffers and places the camera.
Renderer::Impl::Frame Renderer::Impl::begin_frame(const SceneState& state, CameraFrame& out) {
  const int W = cam.width, H = cam.height;
  const auto npix = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  out.width = W;
  out.height = H;
  out.image.resize(W, H);
  out.mask.resize(npix);
  out.depth.resize(npix);
  Frame fr;
  fr.width = W, fr.height = H;
  fr.img = cv::Mat(H, W, CV_8UC3, out.image.pixels.data());
  fr.mask = out.mask.data();
  fr.depth = out.depth.data();

  View& v = fr.v;
  const Eigen::Isometry3d T_world_camera = state.T_world_body * T_body_camera;
  fr.R_wc = T_world_camera.linear();
  const Eigen::Matrix3d& R_wc = fr.R_wc;
  v.R_cw = R_wc.transpose();
  v.c = T_world_camera.translation();
  v.t_cw = -(v.R_cw * v.c);
  // A camera at or below the ground sees it from 1 cm (a landed drone's
  // camera is above it; this only keeps the maths finite).
  v.h = std::max(v.c.z(), 0.01);
  v.A = R_wc.col(0) / f;
  v.B = R_wc.col(1) / f;
  v.C = R_wc.col(2) - v.A * cx - v.B * cy;
  return fr;
}

}  // namespace touchdown::scenario
