#pragma once
/// \file
/// The drone's downward camera, rendered headless with OpenCV
/// (src/scenario/render.cpp). A pinhole camera (CameraOptions): each pixel's
/// ray is cast onto the ground plane z = 0, where it samples the map's
/// mip-mapped ground texture and the markers' images (exact perspective per
/// pixel; no image is warped); objects are rasterised from their tessellated
/// solids into a z-buffer; then sun shadows, and weather as image effects
/// (fog by depth, rain and snow streaks, dust haze, falling leaves, ground
/// snow/leaves/wetness with sun glare, low-light noise), motion blur at
/// speed. Each frame also gives the semantic mask, the depth image and the
/// marker's visible and true areas (the RLaGA paper's eq. 5 reward inputs).
///
/// Thread-safety: one Renderer per thread. render() reuses its buffers.
/// Renderers on the same map share its texture (immutable, through a
/// thread-safe process-wide cache of a few maps), so constructing renderers
/// from several threads at once is safe and the second one on a map is fast.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/image.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

/// Pinhole camera under the drone: optical axis down (−z body) tilted
/// forward by tilt_deg, image "up" towards the body's +x.
struct CameraOptions {
  int width = 640;
  int height = 480;
  double hfov_deg = 90;                      ///< horizontal field of view (fx = width/2 / tan(hfov/2))
  double tilt_deg = 0;                       ///< forward tilt from nadir
  double rate_hz = 10;                       ///< frames per second delivered to the landing system
  double exposure_s = 0.02;                  ///< motion blur = speed × exposure
  Eigen::Vector3d offset_body{0, 0, -0.05};  ///< optical centre in the body frame [m]

  [[nodiscard]] bool validate(std::string* why) const;
  [[nodiscard]] double fx() const;
  /// Intrinsic matrix (square pixels, principal point at the image centre).
  [[nodiscard]] Eigen::Matrix3d K() const;
  /// Camera (optical: x right, y down, z forward) → body.
  [[nodiscard]] Eigen::Isometry3d T_body_camera() const;
};

/// Semantic mask labels; CameraFrame::mask holds their values (a byte per
/// pixel: ground 0, marker 1, ..., sky 5).
enum class Label : std::uint8_t {
  Ground = 0,
  Marker = 1,      ///< the target marker (with its white margin)
  Distractor = 2,  ///< distractor markers and patterns
  StaticObject = 3,
  DynamicObject = 4,
  Sky = 5,
};

}  // namespace touchdown::scenario

template <>
struct touchdown::EnumNames<touchdown::scenario::Label> {
  static constexpr std::array<std::string_view, 6> names{"ground",        "marker",         "distractor",
                                                         "static_object", "dynamic_object", "sky"};
};

namespace touchdown::scenario {

inline std::string_view to_string(Label label) { return enum_name(label); }
/// The byte CameraFrame::mask stores for `label`.
constexpr std::uint8_t mask_value(Label label) { return static_cast<std::uint8_t>(label); }

/// What the world looks like at one instant.
struct SceneState {
  double t = 0;
  int frame_index = 0;  ///< seeds the frame's particles and noise
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  ///< drone velocity (motion blur)
  std::vector<Eigen::Isometry3d> T_world_dynamic;     ///< one per scenario dynamic object
};

struct CameraFrame {
  int width = 0;
  int height = 0;
  touchdown::BgrImage image;
  std::vector<std::uint8_t> mask;  ///< mask_value(Label) per pixel, row-major
  std::vector<float> depth;        ///< along the optical axis [m]; +inf for sky
  /// Target-marker pixels visible in the mask (occlusion by objects counts,
  /// weather does not) and the area its quadrilateral would cover with
  /// nothing in the way, clipped to the image [px] (eq. 5 inputs).
  double marker_area_visible_px = 0;
  double marker_area_truth_px = 0;
};

class Renderer {
 public:
  /// Throws InvalidArgument for invalid camera options or scenario.
  Renderer(const Scenario& scenario, const CameraOptions& camera);
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  void render(const SceneState& state, CameraFrame& out);
  [[nodiscard]] const CameraOptions& camera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::scenario
