#pragma once
/// \file
/// Part of touchdown::pose.
/// LED blob detection in a low-exposure colour image: threshold on the
/// brightest channel, connected blobs (8-connectivity) by run-length
/// labelling, sub-pixel centre by intensity weighting, the LED colour class
/// from the blob's hue, and — with an aligned depth image — a distance gate
/// and the back-projected 3-D centre.
///
/// Colour: a real camera at normal exposure clips an LED's core to white
/// and records its colour in the halo around it. The
/// class is therefore read from the unclipped pixels (every channel below
/// `saturation_level`), each pixel's hue weighted by its chroma (the hue
/// vector α = R − (G + B)/2, β = √3/2 (G − B) summed over pixels); from the
/// clipped core only when the halo carries too little light, and never from
/// pixels clipped in all three channels (a clipped core can be any LED).
/// Weak or incoherent hue evidence gives `Unknown` (compatible with every
/// LED) rather than a confident wrong class.
///
/// Allocation: the detector keeps its buffers; once they have grown to the
/// scene's needs, detect() does not allocate. Thread-safety: one detector
/// per thread.
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "touchdown/core/image.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"

namespace touchdown::pose {

struct Blob {
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();           ///< centre in the (distorted) image [px]
  Eigen::Vector2d uv_undistorted = Eigen::Vector2d::Zero();  ///< the same through the inverse distortion
  double area = 0;                                           ///< pixels at or above the threshold
  double intensity = 0;  ///< summed brightness above the background (the centre's weights)
  /// The colour evidence the class was read from: H = the chroma-weighted
  /// mean hue [deg], S = chroma / brightness, V = mean brightness in [0, 1].
  Eigen::Vector3d hsv = Eigen::Vector3d::Zero();
  LedColor color = LedColor::Unknown;
  bool has_point = false;  ///< a valid depth was found at the centre
  /// Split from a blob that held more spots (DetectorOptions::split_prominence):
  /// its centre is pulled by its neighbour's glow (up to a pixel), so a pose
  /// fit leaves it out when enough other LEDs are matched.
  bool split = false;
  Eigen::Vector3d p_camera = Eigen::Vector3d::Zero();  ///< back-projected centre [m]
};

struct DetectorOptions {
  int threshold = 200;    ///< a pixel is lit if its brightest channel reaches this [DN]
  int background = 24;    ///< brightness subtracted for the centre's weights [DN]
  int min_area = 1;       ///< smaller blobs are noise [px]
  int max_area = 5000;    ///< larger blobs are lamps or reflections [px]
  int refine_margin = 2;  ///< the centre and colour use the bounding box grown by this [px]
  /// A blob holding two spots (an LED merged with its reflection, a lamp or
  /// a neighbour) is split where the channel sum B+G+R dips between them
  /// by at least this [DN of the sum, 0..765] and 10 % of the lower peak
  /// (a watershed); 0 = never split.
  int split_prominence = 60;
  double white_saturation = 0.3;  ///< chroma / brightness of the evidence below this is white
  int saturation_level = 250;     ///< a channel at or above this is clipped [DN]
  /// Least summed brightness above the background [DN] of the pixels a
  /// class is read from (else the core, else Unknown).
  double min_colour_evidence = 100;
  /// Least coherence of the hue evidence, |Σ(α, β)| / Σ|(α, β)| in [0, 1],
  /// for a colour class (else Unknown).
  double min_hue_coherence = 0.7;
  double min_depth = 0.15;  ///< depth gate [m] (blobs with a valid depth outside it are dropped)
  double max_depth = 4.0;
  int depth_window = 2;        ///< median of the valid depths in a (2w+1)² window
  std::size_t max_blobs = 64;  ///< keep at most this many (the brightest)
  /// Drop a blob whose lit pixels reach the image's border: the spot runs
  /// on outside the image, so its centre is pulled inward by up to the
  /// spot's radius — an LED just outside the frame whose halo shows would
  /// otherwise be matched 10 px off and pull the pose (seen: 0.22 rad wrong
  /// at 0.4 m on an independent renderer's sequence, σ 0.002 rad). Such an
  /// LED then counts as unseen.
  bool drop_border_blobs = true;
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Colour class of a mean colour (H in degrees, S, V in [0, 1]): White when
/// S < white_saturation, else by hue (red < 30° or ≥ 330°, green 75–165°,
/// blue 195–265°), else Unknown.
LedColor classify_color(const Eigen::Vector3d& hsv, double white_saturation);
/// HSV (H in degrees) of a BGR colour in [0, 255].
Eigen::Vector3d bgr_to_hsv(const Eigen::Vector3d& bgr);

class LedDetector {
 public:
  LedDetector(const CameraModel& camera, const DetectorOptions& options = {});
  ~LedDetector();
  LedDetector(LedDetector&&) noexcept;
  LedDetector& operator=(LedDetector&&) noexcept;

  /// Detects blobs, brightest first, into `out` (its storage is reused).
  /// `depth` may be null; if given, it must have the colour image's size
  /// (InvalidArgument otherwise).
  void detect(const BgrImageView& colour, const DepthImageView* depth, std::vector<Blob>& out);

  [[nodiscard]] const DetectorOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::pose
