#pragma once
/// \file
/// Part of touchdown::pose_sim.
/// A synthetic camera for the LED pose pipeline: renders what the ground
/// vehicle's low-exposure colour camera (with an aligned 16-bit depth image,
/// RealSense-like) sees of a drone carrying an LED constellation, for tests,
/// benchmarks and users without hardware. Trajectories to render are in
/// trajectory.hpp, the sequence writer in sequence.hpp.
///
/// Image model (all in the struct defaults of RenderOptions):
/// - background: a dark, noisy frame (level + Gaussian sensor noise);
/// - LEDs: a Gaussian spot per LED whose sigma combines the optics blur and
///   the LED's projected physical radius (so spots grow as the drone comes
///   close), soft-saturating so that the core reaches the LED's core colour
///   (255 in its dominant channel) and the fringe is dimmer; a wide faint
///   bloom halo; smeared along the image motion during the exposure;
/// - the ArUco marker of the baseline as a planar, ambient-lit printed card
///   (dim: white ≈ 110 DN, below the LED threshold);
/// - ceiling lamps as distractors: large bright blobs 4–6 m away;
/// - depth: ceiling plane, the drone body (box + a disc around each LED),
///   lamps; noise sigma = k·z², quantised to the camera's depth_scale, a
///   fraction of invalid (zero) pixels.
/// No occlusion model for LEDs (the body never hides an LED); lamps are hidden
/// behind the drone's body.
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/core/image.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/sim/trajectory.hpp"

namespace touchdown::pose {

/// Rendering parameters. Intensities in digital numbers (DN, 0–255),
/// lengths in metres, image sizes in pixels.
struct RenderOptions {
  // --- sensor ---
  double noise_sigma = 2.0;       ///< [DN] additive Gaussian sensor noise per channel
  double background_level = 6.0;  ///< [DN] dark background (low exposure)

  // --- LEDs ---
  /// [m] physical radius of an LED's emitting area: its image radius
  /// f·r/z widens the spot at short range.
  double led_radius = 0.0025;
  double optics_blur_sigma = 0.8;  ///< [px] smallest spot sigma (lens blur)
  /// Unclipped spot peak relative to saturation (> 1: the core saturates to
  /// the LED's core colour, the fringe falls off as a Gaussian). Core colours
  /// (BGR): red (40, 50, 255), green (70, 255, 60), blue (255, 110, 40),
  /// white (255, 255, 255).
  double led_gain = 4.0;
  double bloom_fraction = 0.1;  ///< peak of the wide halo relative to saturation
  double bloom_sigma = 4.0;     ///< [px] halo sigma
  /// Probability that an LED is missing from a frame (flicker, occlusion,
  /// a lost detection); drawn per LED per frame.
  double led_dropout_probability = 0.01;

  // --- motion blur ---
  /// [s] exposure time; the exposure is centred on the frame's pose and the
  /// motion between the previous and the current pose is extrapolated at
  /// constant velocity over it.
  double exposure_s = 0.004;
  double frame_rate_hz = 30.0;  ///< frame rate the previous pose was taken at
  int motion_blur_samples = 5;  ///< poses summed over the exposure (1 = no blur; rounded up to odd)
  /// [s] rolling shutter: the readout from the first row to the last (0: a
  /// global shutter). Row v is exposed δ = rolling_shutter_s (v / (h − 1) −
  /// ½) after the frame's time, at the pose extrapolated as for the motion
  /// blur: a LED moving across the image is drawn where it was when its row
  /// was read, ≤ 1 / frame_rate_hz.
  double rolling_shutter_s = 0;

  // --- depth ---
  /// Depth noise sigma = k·z² [m]; 0.0025 = 2.5 mm at 1 m (stereo depth).
  double depth_noise_k = 0.0025;
  double depth_invalid_fraction = 0.02;  ///< fraction of pixels with no depth (0)
  double ceiling_distance = 5.5;         ///< [m] background plane (beyond the depth gate)
  double body_half_size = 0.075;         ///< [m] the body box is 2·this square in x, y
  double body_z_min = -0.05;             ///< [m] body box extent along body z
  double body_z_max = 0.0;
  double led_disc_radius = 0.015;  ///< [m] depth disc around each LED (its housing)

  // --- distractors ---
  /// Bright ceiling lamps (white or yellowish, larger than an LED, some
  /// saturating) at random image positions fixed per seed, depth in
  /// [distractor_min_depth, distractor_max_depth].
  int distractor_count = 2;
  double distractor_min_depth = 4.0;
  double distractor_max_depth = 6.0;

  // --- ArUco marker (baseline) ---
  /// Rendered at Constellation::T_body_marker when it faces the camera, as a
  /// printed card: the marker (side aruco_size, black border included, OpenCV
  /// aruco's convention) on a white margin one cell wide.
  bool render_marker = true;
  std::string aruco_dictionary = "4X4_50";  ///< "NXN_M" (N 4–7, M 50/100/250/1000) or "ARUCO_ORIGINAL"
  int aruco_id = 3;
  double aruco_size = 0.10;     ///< [m] side of the marker's outer black square
  double marker_white = 110.0;  ///< [DN] white of the card (below the LED threshold)
  double marker_black = 12.0;   ///< [DN]

  // --- harsh conditions (all off by default; RenderProfile::Harsh) ---
  /// LED light is linear in each channel and clips per channel at the
  /// sensor, as a real camera at normal exposure records it: a bright core
  /// clips to white and only the halo keeps the LED's hue, the halo growing
  /// with the gain. False: the core clips to the LED's core colour.
  bool white_cores = false;
  /// Brightness spread between LEDs: each LED's gain is multiplied by 2^u,
  /// u uniform in [−s, s], fixed per seed [stops].
  double led_gain_spread_stops = 0;
  /// Exposure steps (auto-exposure): every light (LEDs, lamps, the card) is
  /// multiplied by 2^k, k a uniform integer in [−s, s] drawn per run of
  /// exposure_step_frames frames [stops].
  int exposure_step_stops = 0;
  int exposure_step_frames = 30;
  /// Rolling drop-outs: an LED that drops out stays out for a run of this
  /// many frames (runs staggered per LED); the fraction of frames an LED is
  /// missing stays led_dropout_probability.
  int led_dropout_frames = 1;
  /// Reflections of LEDs off the airframe: with this probability (per LED,
  /// fixed per seed) a dimmer, wider spot of the LED's colour at
  /// reflection_offset from it on the airframe (with the airframe's depth).
  double reflection_probability = 0;
  /// The light a reflection returns (summed over its spot) relative to its
  /// LED's direct light. A passive surface returns a fraction: glossy
  /// plastic reflects 4–10 % specularly (more at grazing incidence), so
  /// 0.3 is a harsh case. Its spot is wider (σ_q = 1.5 σ + 1 px), so its
  /// peak is lower than the LED's by 0.3 (σ/σ_q)².
  double reflection_gain = 0.3;
  double reflection_offset = 0.03;  ///< [m] LED–reflection distance on the airframe
  /// Fraction of the lamps that look like LEDs: LED-sized (2–5 px) and of an
  /// LED class's colour.
  double distractor_led_like_fraction = 0;
  /// The detector threshold [DN] the merge flags (RenderedFrame::led_merged)
  /// assume: a spot's lit disc is where its brightest channel reaches this.
  double merge_threshold_dn = 200;

  /// False with a reason naming the option if a value is out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Named sets of RenderOptions.
enum class RenderProfile {
  Clean,  ///< the defaults: cores clip to the LED's colour, steady exposure
  /// What real cameras record: white-clipping cores with hue halos of
  /// varying size, exposure steps, LED-coloured lamps, reflections off the
  /// airframe, long motion-blur streaks, rolling drop-outs.
  Harsh,
};

}  // namespace touchdown::pose

template <>
struct touchdown::EnumNames<touchdown::pose::RenderProfile> {
  static constexpr std::array<std::string_view, 2> names{"clean", "harsh"};
};

namespace touchdown::pose {

inline std::string_view to_string(RenderProfile profile) { return enum_name(profile); }
/// `base` with the profile's settings applied (Clean: unchanged).
RenderOptions apply_profile(RenderOptions base, RenderProfile profile);

/// A random LED board for robustness tests (RandomConstellationOptions):
/// 5–8 LEDs on a 0.2 × 0.15 m board in the plane normal to a random facing
/// direction, 0.1 m in front of the body origin, quasi-planar (±2.5 mm of
/// relief) or 3-D (±3 cm) with equal odds, LEDs ≥ 3 cm apart, random
/// colours (red, green, blue, white), every LED's normal the facing, half
/// angle 50–90°. Deterministic in `seed`; always valid.
Constellation random_constellation(std::uint64_t seed);

/// One rendered frame.
struct RenderedFrame {
  BgrImage colour;
  DepthImage depth;               ///< aligned with `colour`, units of CameraModel::depth_scale
  std::vector<bool> led_visible;  ///< per LED: drawn in this frame
  /// Per visible LED: its lit disc touches another drawn spot's (an LED or
  /// a reflection), so the detector sees one blob with a biased centre.
  std::vector<bool> led_merged;
  bool marker_visible = false;  ///< the marker faces the camera and all its corners are in the image
};

/// Renders frames of a drone's constellation seen by a camera.
///
/// An LED is drawn when it is in front of the camera, projects (through
/// CameraModel::project, i.e. with lens distortion) inside the image, was not
/// dropped this frame, and emits toward the camera (Led::emits_toward: the
/// camera inside its emission cone; an LED without a normal shines
/// everywhere).
///
/// Thread-safety: render() is const and may run concurrently on one
/// instance (each thread uses its own scratch buffers). Allocation: after
/// the first frame of a given size on a thread, render() reuses `out`'s and
/// its scratch storage; only the marker's window (and OpenCV's blur inside
/// it) may allocate.
class SyntheticCamera {
 public:
  /// Largest image the renderer takes (4096 x 4096; 3840 x 2160 fits): a
  /// frame needs about kBytesPerPixel of working memory per pixel, so this
  /// is ~0.5 GB.
  static constexpr long long kMaxPixels = 4096LL * 4096;
  /// Working memory per pixel: BGR light and depth buffers (16 bytes), the
  /// undistortion rays (8), the output images (5).
  static constexpr double kBytesPerPixel = 29;

  /// Throws InvalidArgument naming the option when the camera (also one of
  /// more than kMaxPixels pixels), the constellation or the options are
  /// invalid.
  SyntheticCamera(CameraModel camera, Constellation constellation, RenderOptions options = {});
  ~SyntheticCamera();
  SyntheticCamera(SyntheticCamera&&) noexcept;
  SyntheticCamera& operator=(SyntheticCamera&&) noexcept;
  SyntheticCamera(const SyntheticCamera&) = delete;
  SyntheticCamera& operator=(const SyntheticCamera&) = delete;

  /// Renders the frame at `T_camera_body`. `T_camera_body_previous` is the
  /// pose one frame earlier (1 / frame_rate_hz), for motion blur; pass the
  /// same pose for none. Deterministic: the same (seed, frame_index) gives
  /// byte-identical images on every platform (touchdown::Rng(seed,
  /// frame_index)); lamp positions depend on the seed only. Throws
  /// InvalidArgument when a pose is not finite.
  void render(const Eigen::Isometry3d& T_camera_body, const Eigen::Isometry3d& T_camera_body_previous,
              std::uint64_t seed, std::uint64_t frame_index, RenderedFrame& out) const;

  [[nodiscard]] const CameraModel& camera() const;
  [[nodiscard]] const Constellation& constellation() const;
  [[nodiscard]] const RenderOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
