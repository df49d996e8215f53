#pragma once
/// \file
/// The observability oracle (issue 52): from the world's ground truth, could
/// a camera have read the target marker in this frame? A violation search
/// that counts every no-landing as the system's fault measures the world's
/// hardness (a marker under snow, a grey frame in thick fog) instead of the
/// system's defects; the oracle tells the two apart.
///
/// Per frame (TargetOracle::observe), in this order, the first test that
/// fails names the frame's Sight:
///   out-of-view   a corner of the printed marker (the black-bordered code
///                 and its one-cell white margin) outside the image (or
///                 behind the camera);
///   too-small     a cell narrower than min_cell_px (ArUco reads a cell
///                 from about 2 pixels up; 12 px for a 4×4 code's side, the
///                 reference systems' min_quality_px);
///   oblique       the line of sight more than max_view_angle_deg from the
///                 marker's normal;
///   hidden        less than min_visible_fraction of the code's pixels
///                 (those whose ray meets the ground inside it) showing the
///                 code in the mask: the rest are objects in front of it;
///   low-contrast  the mean grey of its white cells minus that of its black
///                 cells, measured in the rendered image (after fog, dust,
///                 light, glare, snow and rain), under min_contrast;
///   noisy         that contrast under min_snr times the pixels' noise (the
///                 spread within each cell: sensor noise, streaks, flakes);
///   covered       a cell of the white margin or of the black border, or
///                 more code cells than the dictionary corrects, reading
///                 the wrong colour (ground snow or leaves on it) or not
///                 seen at all (ArUco finds the border as a dark contour
///                 inside a light one);
///   observable    none of these.
/// Each cell is read as ArUco reads it: its pixels (the middle 60 % of the
/// cell, the edges blur) averaged and compared with the mid-grey between
/// the white and the black cells' means.
///
/// Per run (run.hpp, ScenarioRun): the run's own camera frames, and a probe,
/// a nadir view from probe_altitude above the marker at probe_rate_hz with
/// the run's focal length, rendered in the same world at the same instants
/// (objects where they are, the same weather). The probe answers "could a
/// system searching where it should have looked have seen the target?",
/// whatever the system under test did: a system that hovers in light fog
/// instead of searching fails a fair test; a marker under snow is unfair to
/// every system. A no-landing (Type II) is fair when either view had the
/// target observable for sighting_time without a gap over max_gap.
///
/// Thread-safety: a TargetOracle is immutable after construction; observe()
/// is const and allocates nothing that outlives the call.
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::scenario {

/// The oracle's thresholds (docs/architecture.md, "Observability oracle":
/// where each figure comes from).
struct OracleOptions {
  bool enabled = true;
  /// Continuous sighting a system needs before it may descend [s]: the
  /// reference systems' MlsOptions::seen_time.
  double sighting_time = 5.0;
  double max_gap = 0.3;                ///< a stretch of observable frames survives gaps up to this [s]
  double min_cell_px = 2.0;            ///< narrowest readable cell [px]
  double min_visible_fraction = 0.97;  ///< of the marker's area, not hidden by objects
  /// White cells' mean grey minus black cells': 2 × the constant (7) of
  /// ArUco's adaptive threshold, below which its border does not segment.
  double min_contrast = 14;
  double min_snr = 2.5;            ///< contrast / pixel noise
  double noise_floor = 1.0;        ///< added (in quadrature) to the measured noise [grey levels]
  double max_view_angle_deg = 70;  ///< from the marker's normal
  double probe_altitude = 10;      ///< the probe's height above the marker [m] (the reference systems' cruise)
  double probe_rate_hz = 2;        ///< probe frames per second
  int probe_size_px = 128;         ///< the probe image's edge [px]

  /// False, with "key: what" in *why, for a value out of range.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// Why a frame could or could not show the target (the first failing test).
enum class Sight { Observable, OutOfView, TooSmall, Oblique, Hidden, LowContrast, Noisy, Covered };

}  // namespace touchdown::scenario

template <>
struct touchdown::EnumNames<touchdown::scenario::Sight> {
  static constexpr std::array<std::string_view, 8> names{"observable", "out-of-view",  "too-small", "oblique",
                                                         "hidden",     "low-contrast", "noisy",     "covered"};
};

namespace touchdown::scenario {

inline std::string_view to_string(Sight s) { return enum_name(s); }

/// One frame's view of the target marker.
struct TargetView {
  Sight sight = Sight::OutOfView;
  double side_px = 0;           ///< shortest projected side of the black-bordered code [px]
  double view_angle_deg = 0;    ///< line of sight against the marker's normal
  double visible_fraction = 0;  ///< of the marker's area in the image, not hidden by objects
  double contrast = 0;          ///< mean grey of white cells − of black cells (cell means averaged)
  double noise = 0;             ///< pixel spread within a cell, pooled [grey levels]
  int misread_border = 0;       ///< margin cells reading dark, border cells reading white, or not seen
  int misread_code = 0;         ///< code cells reading the wrong colour or not seen
  [[nodiscard]] bool observable() const { return sight == Sight::Observable; }
};

/// The target's code as printed, and the tests of one frame.
class TargetOracle {
 public:
  /// Throws InvalidArgument for invalid options or an unknown dictionary or id.
  TargetOracle(const Scenario& scenario, const OracleOptions& options);

  /// `frame` rendered by a camera `camera` at `T_world_camera` (optical
  /// frame: x right, y down, z forward).
  [[nodiscard]] TargetView observe(const CameraFrame& frame, const Eigen::Isometry3d& T_world_camera,
                                   const CameraOptions& camera) const;

  [[nodiscard]] const OracleOptions& options() const { return options_; }
  [[nodiscard]] int cells() const { return n_; }  ///< bordered code's side in cells (bits + 2)
  [[nodiscard]] int correctable() const { return correctable_; }

 private:
  OracleOptions options_;
  Eigen::Vector2d centre_;
  double cos_yaw_ = 1, sin_yaw_ = 0, size_ = 1;
  int n_ = 6, correctable_ = 0;
  std::vector<unsigned char> white_;  ///< (n_ + 2)² with the white margin, row 0 at the marker image's top
};

/// The longest stretch of `ok` samples at times `t` (ascending), each
/// standing for `period` seconds, a stretch surviving gaps (between the
/// samples it joins) of up to max_gap [s]: (last − first) + period; 0 when
/// no sample is ok.
double longest_stretch(const std::vector<double>& t, const std::vector<char>& ok, double period, double max_gap);

/// A run's observability (ScenarioOutcome::observability).
struct Observability {
  bool measured = false;     ///< the oracle ran (RunOptions::oracle.enabled)
  double sighting_time = 0;  ///< [s] what "long enough" meant
  double observable_s = 0;   ///< the run's camera: observable frames × frame period [s]
  double longest_s = 0;      ///< the run's camera: longest observable stretch [s]
  double probe_observable_s = 0;
  double probe_longest_s = 0;
  /// The probe's most frequent reason for not seeing the target (Observable
  /// when it always did).
  Sight probe_failure = Sight::Observable;
  double probe_contrast = 0;  ///< the probe's median contrast [grey levels]
  /// Either view had the target observable for sighting_time: a no-landing
  /// is the system's doing. True when not measured (nothing known against it).
  [[nodiscard]] bool observable_long_enough() const {
    return !measured || std::max(longest_s, probe_longest_s) >= sighting_time - 1e-9;
  }
};

}  // namespace touchdown::scenario
