#pragma once
/// \file
/// The renderer's state (Renderer::Impl) and the passes of one frame, shared
/// by render.cpp (construction; render(), the frame as a sequence of passes),
/// render_passes.cpp (ground, markers, shadows, objects) and
/// render_weather.cpp (wet glare, fog and dust, motion blur, particles, low
/// light).
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "scenario/render_internal.hpp"
#include "scenario/render_map.hpp"
#include "scenario/render_marker.hpp"
#include "scenario/render_mesh.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"
#include "touchdown/scenario/camera.hpp"

namespace touchdown::scenario {

/// Where a frame's rain drops, snow flakes and falling leaves are drawn,
/// and how many: the image and a margin around it (particles just outside
/// streak or spread into it), in pixels, and the count relative to the
/// default camera's (CameraOptions{}: 640 × 480, 90°).
struct ParticleWindow {
  double u_lo = 0, u_hi = 0, v_lo = 0, v_hi = 0;  ///< [px]
  /// The window's solid angle, (width / f)(height / f), over the default
  /// camera's: exactly 1 for it. The particles fill the air at a fixed
  /// density, so a narrower view (the oracle's 128 × 128 probe) holds fewer.
  double scale = 1;
};
/// The default camera's margin is a tenth of its image (64 and 48 px);
/// every camera gets at least that angle (0.2 rad, 0.15 rad), so a narrow
/// view still draws the near particles that streak into it.
ParticleWindow particle_window(const CameraOptions& camera);

struct Renderer::Impl {
  Scenario scenario;
  CameraOptions cam;
  double f = 0, cx = 0, cy = 0;
  ParticleWindow particles;  ///< particle_window(cam)
  Eigen::Isometry3d T_body_camera;

  std::shared_ptr<const render_detail::MapTexture> map;  // shared with other renderers of the same map (immutable)
  Eigen::Vector2d map_shift = Eigen::Vector2d::Zero();   // world (x, y) + map_shift = where on the map [m]
  std::vector<render_detail::Quad> quads;                // distractors, then the target marker (last)

  std::vector<render_detail::Mesh> static_meshes;
  std::vector<std::vector<render_detail::Bgr>> static_shade;  // shaded colour per triangle
  std::vector<std::vector<cv::Point2f>> static_shadow;
  std::vector<std::vector<render_detail::Mesh>> dynamic_meshes;  // per object, in its frame

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

  struct View {
    Eigen::Matrix3d R_cw;
    Eigen::Vector3d t_cw, c;  // world → camera; camera centre in the world
    double h = 0;             // camera height above the ground (≥ 1 cm)
    // Ray through pixel (x, y) in world axes with unit optical-axis component:
    // ray = A·x + B·y + C.
    Eigen::Vector3d A, B, C;
    [[nodiscard]] Eigen::Vector3d cam(const Eigen::Vector3d& p_world) const { return R_cw * p_world + t_cw; }
  };

  /// One frame in the making: the output's buffers and the camera.
  struct Frame {
    int width = 0, height = 0;
    cv::Mat img;                   // out.image's pixels (BGR)
    std::uint8_t* mask = nullptr;  // out.mask
    float* depth = nullptr;        // out.depth
    Eigen::Matrix3d R_wc;          // camera axes in the world
    View v;
  };

  void render(const SceneState& state, CameraFrame& out);

  // Construction (render.cpp), in this order.
  static void build_ground_and_markers(Impl& m, const Scenario& scenario, const pose::ArucoDictionaryInfo* dict_info);
  static void build_sun(Impl& m, const Scenario& scenario);
  static void build_objects(Impl& m, const Scenario& scenario);
  static void build_fog(Impl& m, const Scenario& scenario);
  static void build_glare(Impl& m, const Scenario& scenario);
  static void build_low_light(Impl& m, const Scenario& scenario);

  // The passes of one frame, in the order render() calls them.
  Frame begin_frame(const SceneState& state, CameraFrame& out);              // render.cpp
  void ground_pass(Frame& fr);                                               // render_passes.cpp
  cv::Rect markers_pass(Frame& fr, CameraFrame& out);                        // the target's box
  std::optional<cv::Rect> shadows_pass(Frame& fr, const SceneState& state);  // into shadow_mask
  void glare_pass(Frame& fr, bool shadows_on);                               // render_weather.cpp
  void apply_shadows(Frame& fr, const cv::Rect& shadow_box);                 // render_passes.cpp
  void objects_pass(Frame& fr, const SceneState& state);
  void count_visible_marker(Frame& fr, const cv::Rect& marker_box, CameraFrame& out);
  void fog_pass(Frame& fr);  // render_weather.cpp
  void motion_blur_pass(Frame& fr, const SceneState& state);
  void particles_pass(Frame& fr, const SceneState& state, Rng& rng);
  void low_light_pass(Frame& fr, Rng& rng);

  /// The pixel of a point in the camera frame.
  [[nodiscard]] Eigen::Vector2d project(const Eigen::Vector3d& pc) const {
    return Eigen::Vector2d(f * pc.x() / pc.z() + cx, f * pc.y() / pc.z() + cy);
  }
  /// Clips a world polygon on the ground to the image; result in poly2
  /// (render_passes.cpp).
  template <class WorldPoint>
  bool ground_polygon_in_image(const Frame& fr, WorldPoint&& world_point, std::size_t count);
};

}  // namespace touchdown::scenario
