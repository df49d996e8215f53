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
///               image and trajectory replanning (the paper's multi-module
///               system): every depth frame goes into a persistent
///               world-frame grid of obstacle heights; it follows the
///               marker it tracks (detections of the target id away from
///               its estimate are look-alikes); once the sighting
///               gate has passed it picks the free landing point nearest the
///               marker (no obstacle within the drone's radius plus a
///               margin, at most max_landing_offset from the marker),
///               plans the descent to above it with touchdown::plan
///               (minimum-jerk Bézier in a safe flight corridor around the
///               mapped obstacles as boxes), follows the plan with velocity
///               setpoints, replans about once a second or when the map
///               puts an obstacle on the plan, and commands the land mode
///               only over a free footprint. No free landing point near the
///               marker (an object on it) or no plan: it holds or climbs
///               instead of descending (phases "no-landing-spot",
///               "replan-hold", "replan-climb"), so a covered marker ends
///               as a Type II, not on the object.
///
/// Both systems know the camera's mounting: with a forward-tilted camera
/// they hold the drone tan(tilt)·(altitude − land_altitude) behind the
/// marker estimate along the heading, so that the marker stays near the
/// image centre while tracking and descending, and centre over the marker
/// only for the land mode.
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
  /// Radius of the drone seen from above (rotor tips; run_scenario gives
  /// twin::Airframe::footprint_radius(); the default is the F450's) [m].
  double drone_radius = 0.352;
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
  double obstacle_clearance = 1.5;  ///< outside a planned descent: climb when an obstacle comes this close [m]
  double obstacle_height = 0.3;     ///< depth points higher than this above the ground are obstacles [m]
  double map_cell = 0.25;           ///< obstacle grid cell edge [m]
  double obstacle_margin = 0.2;     ///< kept between the drone's radius and mapped obstacles [m]
  double max_landing_offset = 1.0;  ///< farthest landing point from the marker estimate [m]
  double replan_period = 1.0;       ///< replan the descent at least this often [s]
  /// While the marker is tracked (seen within lost_timeout), a detection of
  /// the target id farther than this from the estimate is another marker and
  /// not a sighting; of several within it the nearest is followed [m].
  double track_gate = 1.0;

  [[nodiscard]] bool validate(std::string* why) const;
};

/// "opencv-mls" or "mm-mls"; throws InvalidArgument for another name.
std::unique_ptr<LandingSystem> make_landing_system(std::string_view name, const MlsOptions& options = {});
std::vector<std::string> landing_system_names();

}  // namespace touchdown::scenario
