#pragma once
/// \file
/// Landing systems under test, behind one small interface: camera frames
/// and the drone's state in, a velocity setpoint or a land command out.
/// Users plug their own by implementing LandingSystem. Two reference
/// systems after the RLaGA paper:
///   opencv-mls  ArUco detection of the target id, approach, descend once
///               the marker has been seen continuously for 5 s above a
///               detection-quality threshold, re-centring on the way down;
///   mm-mls      the same detector plus obstacle avoidance from the depth
///               image and replanning (the paper's multi-module system).
#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/scenario/camera.hpp"
#include "touchdown/scenario/world.hpp"

namespace touchdown::scenario {

/// What the system is told before the run (a real system's configuration).
struct SystemSetup {
  CameraOptions camera;               ///< intrinsics and mounting
  std::string dictionary = "4X4_50";  ///< marker to look for
  int marker_id = 0;
  double marker_size = 1.0;          ///< [m]
  Eigen::Vector2d gps_target{0, 0};  ///< approximate marker position [m]
};

struct Detection {
  int id = -1;
  std::array<Eigen::Vector2d, 4> corners;            ///< image pixels, ArUco corner order
  double quality = 0;                                ///< the system's own measure (opencv-mls: side length [px])
  bool accepted = false;                             ///< counted as a sighting of the target
  Eigen::Vector2d ground = Eigen::Vector2d::Zero();  ///< estimated marker centre on the ground [m]
};

struct SystemInput {
  const CameraFrame* frame = nullptr;  ///< a new frame this step, else nullptr
  DroneState state;                    ///< position, velocity, yaw (as GPS/odometry would give)
};

struct SystemOutput {
  DroneCommand command;
  std::string_view phase = "";        ///< for logs ("approach", "search", "descend", "land", ...)
  std::vector<Detection> detections;  ///< of this frame (empty when no frame)
  /// The system committed to a descent this step on the strength of a
  /// detection at `target` (for classifying false-positive landings).
  bool descent_started = false;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();
};

class LandingSystem {
 public:
  virtual ~LandingSystem() = default;
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Starts a run; called once before the first update.
  virtual void reset(const SystemSetup& setup) = 0;
  /// One physics step (frames arrive at the camera rate).
  virtual SystemOutput update(const SystemInput& input) = 0;
};

/// Options of the reference systems (defaults after the paper's setup).
struct MlsOptions {
  double cruise_altitude = 10;  ///< approach and search altitude [m]
  double approach_speed = 3;    ///< [m/s]
  double seen_time = 5;         ///< continuous sighting before descending [s]
  double min_quality_px = 12;   ///< marker side in pixels to count as a sighting
  double lost_timeout = 1.0;    ///< a gap longer than this restarts the 5 s [s]
  double descent_speed = 0.8;   ///< while re-centring [m/s]
  double land_altitude = 1.5;   ///< below this the land command is given [m]
  double centring_gain = 0.8;   ///< horizontal velocity per metre of offset [1/s]
  double search_radius = 6;     ///< spiral search around the GPS target [m]
  /// While the target is tracked, detect in a region around its last
  /// position first (the whole frame when that misses it, and every 10th
  /// frame); false: the whole frame every time, as the published baseline.
  bool detection_roi = true;
  // mm-mls only
  double obstacle_clearance = 1.5;  ///< keep this far above/away from obstacles in the depth image [m]

  [[nodiscard]] bool validate(std::string* why) const;
};

/// "opencv-mls" or "mm-mls"; throws InvalidArgument for another name.
std::unique_ptr<LandingSystem> make_landing_system(std::string_view name, const MlsOptions& options = {});
std::vector<std::string> landing_system_names();

}  // namespace touchdown::scenario
