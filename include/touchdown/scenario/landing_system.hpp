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
#include "touchdown/scenario/marker_detector.hpp"
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
  double confidence = 1;                             ///< the detector's, in [0, 1] (aruco: 1)
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

/// The interface a system under test implements. Its contract (checked
/// for any system by the GoogleTest suite in
/// touchdown/scenario/testing/landing_system_contract.hpp; docs/architecture.md
/// shows how to run it on your own):
///   - name() is non-empty and never changes;
///   - reset() starts a fresh run: nothing of an earlier run carries over
///     (a campaign reuses one object per worker thread for many scenarios);
///   - update() is deterministic: the same setup and the same inputs give
///     the same outputs, bit for bit (runs replay, campaigns are the same
///     for any thread count);
///   - most steps bring no frame (SystemInput::frame == nullptr; the first
///     step after reset() may be one), and every step returns finite
///     commands and targets, with detections only when there was a frame.
///
/// Thread-safety: one object is used by one thread at a time; objects
/// share no state, so a campaign runs one per thread.
class LandingSystem {
 public:
  virtual ~LandingSystem() = default;
  /// Non-empty, the same for the object's whole life.
  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Starts a run; called once before the first update, and again before
  /// each later run on the same object.
  virtual void reset(const SystemSetup& setup) = 0;
  /// One physics step (frames arrive at the camera rate, so most steps
  /// bring none).
  virtual SystemOutput update(const SystemInput& input) = 0;
};

/// Options of the reference systems (defaults after the paper's setup).
/// Every figure that steers their behaviour is here, with its unit; the
/// defaults are the values the systems were tuned and measured with.
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
  /// The marker detector (marker_detector.hpp): ArUco by default, with
  /// its tracking region (detector.roi false: the whole frame every time,
  /// as the published baseline); learned-mls always uses the learned one.
  DetectorOptions detector;
  /// A detection counts as a sighting only at this confidence or above
  /// (the source's TPHYoLo-MLS deployment: 0.70; ArUco's are all 1).
  double min_confidence = 0.7;

  // Guidance of both systems.
  double altitude_gain = 1.0;          ///< vertical velocity per metre of altitude error [1/s]
  double max_vertical_speed = 1.5;     ///< limit of the altitude hold and of a climb back to cruise [m/s]
  double approach_gain = 1.0;          ///< velocity per metre towards the GPS target or the spiral's point [1/s]
  double search_start_distance = 1.0;  ///< the approach turns into the search this close to the GPS target [m]
  double search_growth = 0.25;         ///< the search spiral's radius grows this fast [m/s]
  /// The spiral's point turns at search_speed / max(search_min_radius, r)
  /// [rad/s], r its current radius: search_speed is its speed along the
  /// spiral [m/s] once r ≥ search_min_radius [m].
  double search_speed = 0.4;
  double search_min_radius = 1.0;
  /// Tracking with no sighting for longer than this drops the estimate and
  /// starts the search again [s].
  double track_lost_time = 5.0;
  /// Weight of a new sighting in the marker estimate (the rest is the
  /// previous estimate); a new track starts at its first sighting.
  double estimate_weight = 0.5;
  double land_speed = 0.5;  ///< horizontal speed limit in the land mode [m/s]

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

  // mm-mls: the obstacle map.
  double map_half_extent = 40;  ///< the grid covers this far about the GPS target (the map and the start) [m]
  /// Depth pixels read per frame, whatever the resolution (every 2nd of
  /// every 2nd row at 640×480).
  int depth_samples = 76800;
  int map_ground_hits = 2;          ///< ground samples in a cell for a frame to count it as seen free
  int map_clear_frames = 10;        ///< frames seen free in a row before an obstacle cell is cleared (1 s at 10 Hz)
  double map_change_height = 0.25;  ///< an obstacle cell growing by more than this is a change for the plan [m]
  double box_merge_height = 0.5;    ///< cells merge into one planner box with heights within this of the first [m]
  int max_obstacle_boxes = 24;      ///< more boxes than this around the descent: too cluttered to plan (hold)

  // mm-mls: outside a planned descent.
  double clearance_climb_speed = 1.0;  ///< climb at least this fast when an obstacle comes within the clearance [m/s]
  double clearance_look_ahead = 1.0;   ///< the path checked: one second ahead, at most this far [m]

  // mm-mls: the landing point.
  double landing_ring_step = 0.125;  ///< radial step of the rings searched around the marker estimate [m]
  int landing_bearings = 16;         ///< points per ring
  double landing_hysteresis = 0.25;  ///< a free point must be this much nearer the estimate to replace the current [m]
  double no_spot_speed = 1.0;        ///< horizontal speed limit with no free landing point [m/s]

  // mm-mls: the planned descent (touchdown::plan).
  int plan_order = 6;                  ///< Bézier order, in [5, 20]
  int plan_segments = 2;               ///< Bézier segments, in [2, 16]
  double plan_speed_factor = 1.75;     ///< per-axis speed limit / descent_speed (a min-jerk peak is ~1.875× its mean)
  double plan_max_acceleration = 1.5;  ///< per-axis acceleration limit [m/s²]
  double plan_min_segment_time = 0.3;  ///< time allocation's bounds per segment [s]
  double plan_max_segment_time = 30;   ///< [s]
  int plan_max_evaluations = 40;       ///< time allocation's QP solves per plan
  double plan_start_speed_fraction = 0.95;  ///< a plan from the vehicle's state starts at most this × the speed limit
  double corridor_margin = 2.0;     ///< the corridor's free box around start and goal (CorridorOptions::margin) [m]
  double corridor_deflate = 0.3;    ///< CorridorOptions::deflate [m]
  double corridor_dilate = 0.5;     ///< CorridorOptions::dilate (one dilation step) [m]
  double plan_feedback_gain = 1.0;  ///< velocity per metre from the plan's reference position [1/s]
  double receding_tolerance = 0.5;  ///< a replan starts from the plan's reference state within this of it [m]
  double replan_retry = 0.5;        ///< a failed plan is tried again after this [s]
  double landing_move = 0.2;        ///< the landing point moving by more than this drops the plan [m]
  double plan_check_step = 0.2;     ///< the rest of a plan is checked against the map at this time step [s]
  /// The plan counts as flown within this of the landing point and of the
  /// land altitude [m].
  double land_tolerance = 0.3;
  /// With no plan: climb (at least replan_climb_speed [m/s]) while a mapped
  /// obstacle near the drone reaches above its altitude less its radius
  /// less replan_climb_clearance [m], else hold.
  double replan_climb_clearance = 1.0;
  double replan_climb_speed = 0.5;

  /// False (with "key: what is wrong" in *why) for a NaN or out-of-range value.
  [[nodiscard]] bool validate(std::string* why) const;
};

/// A system from a spec (system_registry.hpp): a registered name —
/// "opencv-mls", "learned-mls" (opencv-mls on the learned detector,
/// whatever options.detector.kind says: the source's TPHYoLo-MLS), "mm-mls"
/// or a loaded plug-in's — or "plugin:PATH[:NAME]". Throws InvalidArgument
/// for an unknown name (listing the known ones), invalid options, a
/// plug-in that cannot be loaded or a learned model that cannot be loaded
/// (naming the file).
std::unique_ptr<LandingSystem> make_landing_system(std::string_view spec, const MlsOptions& options = {});
/// The registered systems' names, sorted.
std::vector<std::string> landing_system_names();

}  // namespace touchdown::scenario
