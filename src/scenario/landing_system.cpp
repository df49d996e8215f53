// The reference landing systems under test (landing_system.hpp), after the
// RLaGA paper's OpenCV-MLS (the industry baseline: ArUco detection with
// OpenCV's default detector parameters, approach, a continuous-sighting
// gate before descending, re-centring on the way down, PX4 land mode for
// the last metres) and MM-MLS (the same with an obstacle map from the depth
// image and a descent planned and replanned around it with touchdown::plan).
#include "touchdown/scenario/landing_system.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "pose/aruco_dictionary.hpp"
#include "scenario/marker_detector.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/plan/planner.hpp"

namespace touchdown::scenario {

namespace {

bool in_range(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

/// Ground point (z = 0) seen at pixel `uv`, or false when the ray misses it.
bool ground_point(const Eigen::Isometry3d& T_world_camera, const Eigen::Matrix3d& K_inv, const Eigen::Vector2d& uv,
                  Eigen::Vector2d* out) {
  const Eigen::Vector3d ray = T_world_camera.linear() * (K_inv * Eigen::Vector3d(uv.x(), uv.y(), 1.0));
  const Eigen::Vector3d o = T_world_camera.translation();
  if (ray.z() >= -1e-9) return false;
  const double s = -o.z() / ray.z();
  *out = (o + s * ray).head<2>();
  return true;
}

Eigen::Vector2d limit(const Eigen::Vector2d& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Eigen::Vector2d(v * (max_norm / n)) : v;
}

/// MM-MLS's obstacle map: a world-frame grid of the highest obstacle point
/// seen in each cell, built from the depth images and kept across frames
/// (what the camera saw a moment ago is still there when it is out of view
/// or hidden by the descent). A depth pixel is a world point o + depth·R
/// K⁻¹ (u, v, 1) (depth along the optical axis, camera.hpp); points more
/// than `min_height` above the ground plane are obstacles, the others
/// ground. A cell seen as ground in kClearFrames frames with no obstacle
/// point in between is cleared again, so that a person or a dog that walked
/// away does not leave a wall behind; a thin pole hit now and then keeps
/// its cell. Overhangs (a tree crown) count as solid down to the ground: the
/// map is 2.5-D, which is what a descent needs.
class ObstacleGrid {
 public:
  static constexpr int kClearFrames = 10;    // 1 s at the default 10 Hz camera
  static constexpr double kHalfExtent = 40;  // [m] about the GPS target: the whole map and the start

  void reset(const Eigen::Vector2d& centre, double cell, double min_height) {
    cell_ = cell;
    min_height_ = min_height;
    n_ = static_cast<int>(std::ceil(2 * kHalfExtent / cell));
    origin_ = centre - Eigen::Vector2d::Constant(0.5 * n_ * cell);
    const auto count = static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_);
    height_.assign(count, 0.0f);
    free_frames_.assign(count, 0);
    stamp_.assign(count, 0);
    frame_max_.assign(count, 0.0f);
    frame_ground_.assign(count, 0);
    touched_.clear();
    touched_.reserve(8192);
    frame_ = 0;
    changes_ = 0;
  }

  /// Adds one depth image (about 77 000 samples whatever the resolution:
  /// every 2nd pixel of each 2nd row at 640×480).
  void integrate(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera, const Eigen::Matrix3d& K_inv) {
    ++frame_;
    const int stride = std::max(1, static_cast<int>(std::lround(std::sqrt(f.width * f.height / 76800.0))));
    const Eigen::Matrix3d M = T_world_camera.linear() * K_inv;
    const Eigen::Vector3d o = T_world_camera.translation();
    const Eigen::Vector3d dx = M.col(0) * static_cast<double>(stride);
    const double inv_cell = 1.0 / cell_;
    for (int y = 0; y < f.height; y += stride) {
      Eigen::Vector3d ray = M * Eigen::Vector3d(0, y, 1);  // the ray of pixel (x, y), moved along the row
      const float* row = f.depth.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width);
      for (int x = 0; x < f.width; x += stride, ray += dx) {
        const float d = row[x];
        if (!(d > 0 && d < std::numeric_limits<float>::max())) continue;  // sky (+inf) or no return
        const Eigen::Vector3d p = o + static_cast<double>(d) * ray;
        const double gx = (p.x() - origin_.x()) * inv_cell, gy = (p.y() - origin_.y()) * inv_cell;
        if (!(gx >= 0 && gy >= 0 && gx < n_ && gy < n_)) continue;
        const std::size_t i = index(static_cast<int>(gx), static_cast<int>(gy));
        if (stamp_[i] != frame_) {
          stamp_[i] = frame_;
          frame_max_[i] = 0;
          frame_ground_[i] = 0;
          touched_.push_back(i);
        }
        if (p.z() > min_height_) {
          frame_max_[i] = std::max(frame_max_[i], static_cast<float>(p.z()));
        } else if (frame_ground_[i] < 255) {
          ++frame_ground_[i];
        }
      }
    }
    for (const std::size_t i : touched_) {
      if (frame_max_[i] > 0) {
        // New, or clearly higher than mapped: the planner must look again.
        if (height_[i] == 0 || frame_max_[i] > height_[i] + 0.25f) ++changes_;
        height_[i] = std::max(height_[i], frame_max_[i]);
        free_frames_[i] = 0;
      } else if (height_[i] > 0 && frame_ground_[i] >= 2 && ++free_frames_[i] >= kClearFrames) {
        height_[i] = 0;
        free_frames_[i] = 0;
        ++changes_;
      }
    }
    touched_.clear();
  }

  /// Counts the changes that matter to a plan (an obstacle cell appeared,
  /// grew or was cleared).
  [[nodiscard]] std::uint64_t changes() const { return changes_; }

  /// The highest obstacle with a cell (a square) within `radius` of p; 0 when none.
  [[nodiscard]] double max_height_near(const Eigen::Vector2d& p, double radius) const {
    int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
    cell_range(p - Eigen::Vector2d::Constant(radius), p + Eigen::Vector2d::Constant(radius), &i0, &j0, &i1, &j1);
    double h = 0;
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const float hc = height_[index(i, j)];
        if (hc <= h) continue;
        const Eigen::Vector2d lo = origin_ + cell_ * Eigen::Vector2d(i, j);
        const Eigen::Vector2d hi = lo + Eigen::Vector2d::Constant(cell_);
        const Eigen::Vector2d q = p.cwiseMax(lo).cwiseMin(hi);  // nearest point of the cell
        if ((q - p).squaredNorm() <= radius * radius) h = hc;
      }
    }
    return h;
  }

  /// The obstacle cells in [lo, hi] merged into axis-aligned boxes from the
  /// ground to their highest cell, each grown by `inflate` (also upwards).
  /// Greedy: a run of cells along x, extended along y while the whole run
  /// stays occupied; cells merge only with heights within 0.5 m of the
  /// first, so that a pole does not raise a whole box. Returns false (and
  /// leaves *out partial) beyond `max_boxes`.
  bool boxes(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, double inflate, std::size_t max_boxes,
             std::vector<plan::Box>* out) {
    out->clear();
    int i0 = 0, j0 = 0, i1 = -1, j1 = -1;
    cell_range(lo, hi, &i0, &j0, &i1, &j1);
    if (i1 < i0 || j1 < j0) return true;
    const int w = i1 - i0 + 1;
    used_.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(j1 - j0 + 1), 0);
    const auto used = [&](int i, int j) -> std::uint8_t& {
      return used_[static_cast<std::size_t>(j - j0) * static_cast<std::size_t>(w) + static_cast<std::size_t>(i - i0)];
    };
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const float h0 = height_[index(i, j)];
        if (h0 <= 0 || used(i, j)) continue;
        const auto fits = [&](int a, int b) {
          const float h = height_[index(a, b)];
          return h > 0 && !used(a, b) && std::abs(h - h0) <= 0.5f;
        };
        int ie = i;
        while (ie + 1 <= i1 && fits(ie + 1, j)) ++ie;
        int je = j;
        for (;;) {
          if (je + 1 > j1) break;
          bool row_ok = true;
          for (int a = i; a <= ie && row_ok; ++a) row_ok = fits(a, je + 1);
          if (!row_ok) break;
          ++je;
        }
        double top = 0;
        for (int b = j; b <= je; ++b) {
          for (int a = i; a <= ie; ++a) {
            used(a, b) = 1;
            top = std::max(top, static_cast<double>(height_[index(a, b)]));
          }
        }
        if (out->size() == max_boxes) return false;
        plan::Box box;
        box.min = Eigen::Vector3d(origin_.x() + i * cell_ - inflate, origin_.y() + j * cell_ - inflate, 0);
        box.max = Eigen::Vector3d(origin_.x() + (ie + 1) * cell_ + inflate, origin_.y() + (je + 1) * cell_ + inflate,
                                  top + inflate);
        out->push_back(box);
      }
    }
    return true;
  }

 private:
  [[nodiscard]] std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(i);
  }
  void cell_range(const Eigen::Vector2d& lo, const Eigen::Vector2d& hi, int* i0, int* j0, int* i1, int* j1) const {
    const auto clampi = [&](double g) { return static_cast<int>(std::clamp(std::floor(g), 0.0, n_ - 1.0)); };
    const Eigen::Vector2d a = (lo - origin_) / cell_, b = (hi - origin_) / cell_;
    if (b.x() < 0 || b.y() < 0 || a.x() >= n_ || a.y() >= n_) return;  // empty range
    *i0 = clampi(a.x());
    *j0 = clampi(a.y());
    *i1 = clampi(b.x());
    *j1 = clampi(b.y());
  }

  double cell_ = 0.25;
  double min_height_ = 0.3;
  int n_ = 0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::vector<float> height_;  // highest obstacle point [m]; 0 = free or never seen
  std::vector<std::uint8_t> free_frames_;
  std::vector<std::uint32_t> stamp_;  // the frame that last touched the cell
  std::vector<float> frame_max_;      // this frame's highest obstacle point per cell
  std::vector<std::uint8_t> frame_ground_;
  std::vector<std::size_t> touched_;
  std::vector<std::uint8_t> used_;
  std::uint32_t frame_ = 0;
  std::uint64_t changes_ = 0;
};

/// OpenCV-MLS and, with `avoid_obstacles`, MM-MLS.
class MarkerLandingSystem final : public LandingSystem {
 public:
  MarkerLandingSystem(const MlsOptions& options, bool avoid_obstacles) : options_(options), avoid_(avoid_obstacles) {}

  std::string_view name() const override { return avoid_ ? "mm-mls" : "opencv-mls"; }

  void reset(const SystemSetup& setup) override {
    std::string why;
    if (!setup.camera.validate(&why)) throw InvalidArgument("landing system: camera: " + why);
    if (!in_range(setup.drone_radius, 0.01, 5))
      throw InvalidArgument("landing system: drone_radius: must be in [0.01, 5] m");
    const auto* dict = pose::detail::find_aruco_dictionary(setup.dictionary);
    if (!dict) throw InvalidArgument("landing system: dictionary: unknown " + setup.dictionary);
    setup_ = setup;
    detector_.emplace(cv::aruco::getPredefinedDictionary(dict->id), options_.detection_roi);
    K_inv_ = setup.camera.K().inverse();
    T_body_camera_ = setup.camera.T_body_camera();
    tan_tilt_ = std::tan(setup.camera.tilt_deg * std::numbers::pi / 180.0);
    phase_ = Phase::approach;
    have_estimate_ = false;
    track_exact_ = false;
    reacquired_ = false;
    seen_since_ = -1;
    last_seen_ = -1e9;
    search_angle_ = 0;
    last_t_ = -1;
    if (avoid_) map_.reset(setup.gps_target, options_.map_cell, options_.obstacle_height);
    have_landing_ = false;
    have_plan_ = false;
    next_plan_try_ = 0;
    mm_phase_ = "descend";
  }

  SystemOutput update(const SystemInput& in) override {
    SystemOutput out;
    const DroneState& s = in.state;
    const double dt = in_dt(s);
    if (in.frame) detect(*in.frame, s, out);
    const double t = s.t;
    const bool seen_recently = t - last_seen_ <= options_.lost_timeout;
    if (!seen_recently) seen_since_ = -1;
    if (reacquired_) {
      // A descent on the marker it followed before is dropped: back to
      // tracking (at the cruise altitude) until the re-acquired marker has
      // been seen for seen_time. The land mode is committed.
      reacquired_ = false;
      if (phase_ == Phase::descend) {
        phase_ = Phase::track;
        have_plan_ = false;
        have_landing_ = false;
      }
    }

    const Eigen::Vector2d p = s.position.head<2>();
    Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
    double v_z = 0;
    const double altitude = s.position.z();
    const auto hold_altitude = [&](double z) { return std::clamp(1.0 * (z - altitude), -1.5, 1.5); };
    bool planned = false;  // mm-mls descent: the velocity comes from its plan (or its refusal)

    switch (phase_) {
      case Phase::approach: {
        // To the GPS target at cruise altitude; a sighting on the way takes over.
        const Eigen::Vector2d to = setup_.gps_target - p;
        v_xy = limit(to * 1.0, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        if (have_estimate_) {
          phase_ = Phase::track;
        } else if (to.norm() < 1.0) {
          phase_ = Phase::search;
          search_start_ = t;
        }
        break;
      }
      case Phase::search: {
        // An expanding spiral about the GPS target until the marker is seen.
        if (have_estimate_) {
          phase_ = Phase::track;
          break;
        }
        const double r = std::min(options_.search_radius, 0.25 * (t - search_start_));
        search_angle_ += 0.4 * (1.0 / std::max(1.0, r)) * dt;
        const Eigen::Vector2d goal =
            setup_.gps_target + r * Eigen::Vector2d(std::cos(search_angle_), std::sin(search_angle_));
        v_xy = limit((goal - p) * 1.0, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        break;
      }
      case Phase::track: {
        // Hover where the camera sees the estimate near the image centre
        // until it has been seen for seen_time.
        v_xy = limit((hover_point(estimate_, s) - p) * options_.centring_gain, options_.approach_speed);
        v_z = hold_altitude(options_.cruise_altitude);
        if (seen_since_ >= 0 && t - seen_since_ >= options_.seen_time) {
          phase_ = Phase::descend;
          out.descent_started = true;
          out.target = estimate_;
          have_plan_ = false;
          have_landing_ = false;
          next_plan_try_ = t;
        } else if (!seen_recently && t - last_seen_ > 5.0) {
          phase_ = Phase::search;  // lost it for good
          search_start_ = t;
          have_estimate_ = false;
        }
        break;
      }
      case Phase::descend: {
        if (avoid_) {
          const Eigen::Vector3d v = planned_descent(s);
          v_xy = v.head<2>();
          v_z = v.z();
          planned = true;
          break;
        }
        v_xy = limit((hover_point(estimate_, s) - p) * options_.centring_gain, options_.approach_speed);
        // Committed: re-centre while the marker is in sight, else keep
        // descending on the last estimate (PX4 precision landing's
        // opportunistic fallback: the marker often leaves the view or is
        // occluded near the ground).
        v_z = -options_.descent_speed;
        if (altitude < options_.land_altitude) phase_ = Phase::land;
        break;
      }
      case Phase::land: {
        // Over the marker (mm-mls: over its free landing point).
        if (avoid_) {
          v_xy = limit((landing_ - p) * options_.centring_gain, 0.5);
        } else if (seen_recently) {
          v_xy = limit((estimate_ - p) * options_.centring_gain, 0.5);
        }
        out.command.land = true;
        break;
      }
    }
    if (avoid_ && !planned && phase_ != Phase::land) keep_clear(p, altitude, &v_xy, &v_z);
    out.command.velocity_world = Eigen::Vector3d(v_xy.x(), v_xy.y(), v_z);
    out.phase = phase_name();
    return out;
  }

 private:
  enum class Phase { approach, search, track, descend, land };

  std::string_view phase_name() const {
    switch (phase_) {
      case Phase::approach:
        return "approach";
      case Phase::search:
        return "search";
      case Phase::track:
        return "track";
      case Phase::descend:
        return avoid_ ? mm_phase_ : "descend";
      case Phase::land:
        return "land";
    }
    return "";
  }

  double in_dt(const DroneState& s) {
    const double dt = last_t_ < 0 ? 0.0 : s.t - last_t_;
    last_t_ = s.t;
    return dt;
  }

  /// Where to hold the drone so that a forward-tilted camera sees `target`
  /// near the image centre: tan(tilt)·h behind it along the heading, h the
  /// height above the land altitude, so that the offset shrinks on the way
  /// down and is zero when the land mode takes over (then the marker is
  /// below the view anyway). At nadir: the target itself.
  Eigen::Vector2d hover_point(const Eigen::Vector2d& target, const DroneState& s) const {
    if (tan_tilt_ == 0) return target;
    const double yaw = s.yaw_deg * std::numbers::pi / 180.0;
    const double back = tan_tilt_ * std::max(0.0, s.position.z() - options_.land_altitude);
    return target - back * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
  }

  void detect(const CameraFrame& f, const DroneState& s, SystemOutput& out) {
    const cv::Mat bgr(f.height, f.width, CV_8UC3, const_cast<std::uint8_t*>(f.image.pixels.data()));
    cv::cvtColor(bgr, gray_, cv::COLOR_BGR2GRAY);
    detector_->detect(gray_, setup_.marker_id, corners_, ids_);
    const Eigen::Isometry3d T_world_camera = s.T_world_body() * T_body_camera_;
    int best = -1;
    std::size_t best_index = 0;
    bool best_exact = false, best_reacquires = false;
    // mm-mls follows the marker it tracks: while the track is alive, a
    // detection of the target id whose ground point is more than the gate
    // from the estimate is another marker (a look-alike the decoder's error
    // correction reads as the target) and is not a sighting. It also reads
    // each sighting's code itself: a track that never read exactly (it may
    // follow a look-alike seen first) gives way to an exact reading of the
    // target outside the gate — the re-acquisition.
    const bool gated = avoid_ && have_estimate_ && s.t - last_seen_ <= options_.lost_timeout;
    for (std::size_t i = 0; i < ids_.size(); ++i) {
      Detection d;
      d.id = ids_[i];
      double perimeter = 0;
      for (int k = 0; k < 4; ++k) {
        d.corners[static_cast<std::size_t>(k)] =
            Eigen::Vector2d(corners_[i][static_cast<std::size_t>(k)].x, corners_[i][static_cast<std::size_t>(k)].y);
      }
      for (int k = 0; k < 4; ++k)
        perimeter += (d.corners[static_cast<std::size_t>(k)] - d.corners[static_cast<std::size_t>((k + 1) % 4)]).norm();
      d.quality = perimeter / 4;  // mean side length [px]
      const Eigen::Vector2d centre = 0.25 * (d.corners[0] + d.corners[1] + d.corners[2] + d.corners[3]);
      const bool on_ground = ground_point(T_world_camera, K_inv_, centre, &d.ground);
      d.accepted = d.id == setup_.marker_id && d.quality >= options_.min_quality_px && on_ground;
      // The code is read while it can still matter: not for a track that
      // has read exactly (it keeps its gate and stays exact).
      const bool exact = avoid_ && d.accepted && !(gated && track_exact_) &&
                         detector_->code_errors(gray_, corners_[i], setup_.marker_id) == 0;
      bool reacquires = false;
      if (gated && d.accepted && (d.ground - estimate_).norm() > options_.track_gate)
        d.accepted = reacquires = exact && !track_exact_;
      // Several accepted: the baseline follows the largest; mm-mls a
      // re-acquisition first, else while tracking the one nearest its
      // estimate, else an exact reading before a corrected one, then the
      // largest.
      const auto better = [&](const Detection& o) {
        if (reacquires != best_reacquires) return reacquires;
        if (gated && !reacquires) return (d.ground - estimate_).norm() < (o.ground - estimate_).norm();
        if (exact != best_exact) return exact;
        return d.quality > o.quality;
      };
      if (d.accepted && (best < 0 || better(out.detections[static_cast<std::size_t>(best)]))) {
        best = static_cast<int>(out.detections.size());
        best_index = i;
        best_exact = exact;
        best_reacquires = reacquires;
      }
      out.detections.push_back(d);
    }
    if (avoid_) map_obstacles(f, T_world_camera);
    detector_->track(best < 0 ? nullptr : &corners_[best_index]);
    if (best < 0) return;
    const Detection& d = out.detections[static_cast<std::size_t>(best)];
    const bool new_track = seen_since_ < 0 || s.t - last_seen_ > options_.lost_timeout;
    if (new_track || best_reacquires) seen_since_ = s.t;
    last_seen_ = s.t;
    estimate_ = have_estimate_ && !best_reacquires ? Eigen::Vector2d(0.5 * estimate_ + 0.5 * d.ground) : d.ground;
    have_estimate_ = true;
    track_exact_ = (track_exact_ && !new_track) || best_exact;
    reacquired_ = reacquired_ || best_reacquires;
  }

  // MM-MLS: every depth frame goes into the obstacle grid.
  void map_obstacles(const CameraFrame& f, const Eigen::Isometry3d& T_world_camera) {
    map_.integrate(f, T_world_camera, K_inv_);
  }

  // MM-MLS outside a planned descent (approach, search, track at cruise
  // altitude): an obstacle within the clearance of the drone's radius that
  // reaches within the clearance of its altitude stops the horizontal
  // motion towards it and makes it climb.
  void keep_clear(const Eigen::Vector2d& p, double altitude, Eigen::Vector2d* v_xy, double* v_z) const {
    const double reach = setup_.drone_radius + options_.obstacle_clearance;
    if (map_.max_height_near(p, reach) <= altitude - options_.obstacle_clearance) return;
    *v_z = std::max(*v_z, 1.0);
    const Eigen::Vector2d ahead = p + limit(*v_xy, 1.0);  // where it is heading in the next second
    if (map_.max_height_near(ahead, reach) > altitude - options_.obstacle_clearance) v_xy->setZero();
  }

  /// The free landing point nearest the marker estimate: no mapped obstacle
  /// within the drone's radius plus the margin, on rings of 1/8 m up to
  /// max_landing_offset (16 bearings each). The current one is kept while
  /// it stays free and no free point is 0.25 m nearer the estimate. False
  /// when there is none (an object on or around the marker).
  bool choose_landing_point() {
    const double clear = setup_.drone_radius + options_.obstacle_margin;
    const auto free = [&](const Eigen::Vector2d& c) { return map_.max_height_near(c, clear) <= 0; };
    bool found = false;
    Eigen::Vector2d best = estimate_;
    double best_rho = 0;
    const int rings = static_cast<int>(std::floor(options_.max_landing_offset / 0.125 + 1e-9));
    for (int k = 0; k <= rings && !found; ++k) {
      const double rho = 0.125 * k;
      const int bearings = k == 0 ? 1 : 16;
      for (int b = 0; b < bearings && !found; ++b) {
        const double a = 2 * std::numbers::pi * b / bearings;
        const Eigen::Vector2d c = estimate_ + rho * Eigen::Vector2d(std::cos(a), std::sin(a));
        if (free(c)) {
          found = true;
          best = c;
          best_rho = rho;
        }
      }
    }
    const double current_rho = (landing_ - estimate_).norm();
    if (have_landing_ && current_rho <= options_.max_landing_offset + 1e-9 && free(landing_) &&
        (!found || current_rho <= best_rho + 0.25))
      return true;
    have_landing_ = found;
    if (found) landing_ = best;
    return found;
  }

  /// MM-MLS after the sighting gate: to above the free landing point on a
  /// planned trajectory, replanned about once a second, when the landing
  /// point moves, or when the map puts an obstacle on the rest of the plan;
  /// the land mode over a free footprint only. Returns the velocity setpoint.
  Eigen::Vector3d planned_descent(const DroneState& s) {
    const double t = s.t;
    const Eigen::Vector2d p = s.position.head<2>();
    const double altitude = s.position.z();
    const auto climb_to_cruise = [&]() {
      return std::clamp(1.0 * (options_.cruise_altitude - altitude), 0.0, 1.5);  // never down
    };
    const Eigen::Vector2d before = landing_;
    const bool had_landing = have_landing_;
    if (!choose_landing_point()) {
      // An object on the marker (or all round it): refuse to land there.
      // Back up to the cruise altitude above the marker, keep mapping and
      // looking; should the object move away, the descent resumes.
      mm_phase_ = "no-landing-spot";
      have_plan_ = false;
      const Eigen::Vector2d v = limit((hover_point(estimate_, s) - p) * options_.centring_gain, 1.0);
      return {v.x(), v.y(), climb_to_cruise()};
    }
    const bool moved = !had_landing || (landing_ - before).norm() > 0.2;
    const double remaining = have_plan_ ? plan_duration_ - (t - plan_t0_) : 0;
    const bool stale = remaining > options_.replan_period && t - plan_t0_ >= options_.replan_period;
    const bool blocked = have_plan_ && map_.changes() != plan_changes_ && plan_blocked(t);
    // A plan that leads elsewhere or into a mapped obstacle is dropped; a
    // stale one is kept until a new one succeeds.
    if (moved || blocked) have_plan_ = false;
    if ((!have_plan_ || stale) && t >= next_plan_try_) replan(s);
    if (!have_plan_) {
      // No plan into the landing point: do not descend into the unknown.
      // Climb while something mapped is close below, else hold.
      const double reach = setup_.drone_radius + options_.obstacle_margin + options_.map_cell;
      const bool close = map_.max_height_near(p, reach) > altitude - setup_.drone_radius - 1.0;
      mm_phase_ = close ? "replan-climb" : "replan-hold";
      return {0, 0, close ? std::max(0.5, climb_to_cruise()) : 0.0};
    }
    // Follow the plan: its velocity as feed-forward, position feedback.
    const double tau = std::min(t - plan_t0_, plan_duration_);
    const Eigen::Vector3d p_ref = c3_plan_ + trajectory_.evaluate(tau);
    const Eigen::Vector3d v_ref = trajectory_.evaluate(tau, 1);
    Eigen::Vector3d v = v_ref + 1.0 * (p_ref - s.position);
    v.head<2>() = limit(v.head<2>(), options_.approach_speed);
    mm_phase_ = "descend";
    const bool done =
        t - plan_t0_ >= plan_duration_ && (p - landing_).norm() < 0.3 && altitude < options_.land_altitude + 0.3;
    // The land mode only with nothing mapped under the footprint.
    if (done && map_.max_height_near(p, setup_.drone_radius) <= 0) phase_ = Phase::land;
    return v;
  }

  /// The rest of the plan passes within the drone's radius of a mapped obstacle.
  bool plan_blocked(double t) const {
    for (double tau = std::max(0.0, t - plan_t0_); tau < plan_duration_ + 0.1; tau += 0.2) {
      const Eigen::Vector3d q = c3_plan_ + trajectory_.evaluate(std::min(tau, plan_duration_));
      if (map_.max_height_near(q.head<2>(), setup_.drone_radius) > q.z() - setup_.drone_radius) return true;
    }
    return false;
  }

  /// Plans from the drone's state to above the landing point (the pad frame
  /// of touchdown::plan: origin on the ground at the landing point, a
  /// static pad) inside a safe flight corridor around the mapped obstacles,
  /// grown by the margin (the corridor adds the drone's radius).
  void replan(const DroneState& s) {
    const double t = s.t;
    next_plan_try_ = t + 0.5;  // a failed plan is tried again twice a second
    const Eigen::Vector3d c3(landing_.x(), landing_.y(), 0);
    plan::PlannerOptions po;
    po.order = 6;
    po.segments = 2;
    // A minimum-jerk descent peaks at about 1.875× its mean speed: this
    // keeps the mean near descent_speed.
    po.v_max = 1.75 * options_.descent_speed;
    po.a_max = 1.5;
    po.time.min = 0.3;
    po.time.max = 30;
    po.time.max_evaluations = 40;
    plan::CorridorOptions co;
    co.h_touchdown = options_.land_altitude;
    co.radius = setup_.drone_radius;
    co.margin = 2.0;
    co.deflate = 0.3;
    co.dilate = 0.5;
    po.corridor = co;
    plan::KinematicState start;
    const double tau = t - plan_t0_;
    if (have_plan_ && tau <= plan_duration_ && (c3_plan_ + trajectory_.evaluate(tau) - s.position).norm() < 0.5) {
      // Receding horizon: from the current plan's reference state while the
      // drone follows it, so that a replan continues the motion instead of
      // starting over from the vehicle's lagging state.
      start.p = c3_plan_ + trajectory_.evaluate(tau) - c3;
      start.v = trajectory_.evaluate(tau, 1);
      start.a = trajectory_.evaluate(tau, 2);
    } else {
      // The vehicle's velocity follows its setpoint within a fraction of a
      // second (FlightOptions::velocity_time_constant): the plan starts from
      // its position and velocity at rest acceleration, which also keeps the
      // third control point near the start for long segments.
      start.p = s.position - c3;
      start.v = s.velocity.cwiseMax(-0.95 * po.v_max).cwiseMin(0.95 * po.v_max);
    }
    plan::KinematicState goal;
    goal.p = Eigen::Vector3d(0, 0, options_.land_altitude);
    // The obstacles the corridor can meet: around start and goal.
    const double reach = co.margin + co.radius + options_.obstacle_margin;
    const Eigen::Vector2d lo = p_min(s.position.head<2>(), landing_) - Eigen::Vector2d::Constant(reach);
    const Eigen::Vector2d hi = p_max(s.position.head<2>(), landing_) + Eigen::Vector2d::Constant(reach);
    plan_changes_ = map_.changes();
    if (!map_.boxes(lo, hi, options_.obstacle_margin, 24, &boxes_)) return;  // too cluttered to plan: hold
    for (plan::Box& b : boxes_) {
      b.min -= c3;
      b.max -= c3;
    }
    po.obstacles = boxes_;
    // The corridor's split between the approach part and the column above
    // the landing point: just over the highest obstacle, so that the two
    // parts overlap after a dilation step or two (from the land altitude
    // it would take one 0.5 m step per half metre of obstacle, each costing
    // a few hundred µs of polytope work).
    double top = 0;
    for (const plan::Box& b : boxes_) top = std::max(top, b.max.z());
    po.corridor->h_touchdown =
        std::clamp(top + co.radius, options_.land_altitude, std::max(options_.land_altitude, start.p.z()));
    plan::PlanResult r;
    try {
      r = plan::plan(start, goal, plan::PadMotion{}, po);
    } catch (const Error&) {
      return;  // a state the planner refuses (e.g. outside its corridor): hold, try again
    }
    if (!r.ok()) return;
    trajectory_ = std::move(r.trajectory);
    c3_plan_ = c3;
    plan_duration_ = trajectory_.total_duration();
    plan_t0_ = t;
    have_plan_ = true;
  }

  static Eigen::Vector2d p_min(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.cwiseMin(b); }
  static Eigen::Vector2d p_max(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.cwiseMax(b); }

  MlsOptions options_;
  bool avoid_;
  SystemSetup setup_;
  std::optional<detail::MarkerDetector> detector_;
  Eigen::Matrix3d K_inv_ = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d T_body_camera_ = Eigen::Isometry3d::Identity();
  double tan_tilt_ = 0;
  Phase phase_ = Phase::approach;
  Eigen::Vector2d estimate_ = Eigen::Vector2d::Zero();
  bool have_estimate_ = false;
  bool track_exact_ = false;  // mm-mls: the track has read the target's code exactly
  bool reacquired_ = false;   // mm-mls: it moved to an exact reading outside the gate
  double seen_since_ = -1;
  double last_seen_ = -1e9;
  double search_start_ = 0;
  double search_angle_ = 0;
  double last_t_ = -1;
  cv::Mat gray_;
  std::vector<std::vector<cv::Point2f>> corners_;
  std::vector<int> ids_;
  // mm-mls
  ObstacleGrid map_;
  std::string_view mm_phase_ = "descend";
  bool have_landing_ = false;
  Eigen::Vector2d landing_ = Eigen::Vector2d::Zero();
  bool have_plan_ = false;
  plan::PiecewiseBezier trajectory_;
  Eigen::Vector3d c3_plan_ = Eigen::Vector3d::Zero();  // the plan's origin: its landing point on the ground
  double plan_t0_ = 0;
  double plan_duration_ = 0;
  double next_plan_try_ = 0;
  std::uint64_t plan_changes_ = 0;
  std::vector<plan::Box> boxes_;
};

}  // namespace

bool MlsOptions::validate(std::string* why) const {
  if (!in_range(cruise_altitude, 2, 100)) return invalid(why, "cruise_altitude: must be in [2, 100] m");
  if (!in_range(approach_speed, 0.1, 20)) return invalid(why, "approach_speed: must be in [0.1, 20] m/s");
  if (!in_range(seen_time, 0, 60)) return invalid(why, "seen_time: must be in [0, 60] s");
  if (!in_range(min_quality_px, 0, 10000)) return invalid(why, "min_quality_px: must be in [0, 10000] px");
  if (!in_range(lost_timeout, 0, 60)) return invalid(why, "lost_timeout: must be in [0, 60] s");
  if (!in_range(descent_speed, 0.05, 10)) return invalid(why, "descent_speed: must be in [0.05, 10] m/s");
  if (!in_range(land_altitude, 0, 20)) return invalid(why, "land_altitude: must be in [0, 20] m");
  if (!in_range(centring_gain, 0.01, 10)) return invalid(why, "centring_gain: must be in [0.01, 10] 1/s");
  if (!in_range(search_radius, 0, 100)) return invalid(why, "search_radius: must be in [0, 100] m");
  if (!in_range(obstacle_clearance, 0, 20)) return invalid(why, "obstacle_clearance: must be in [0, 20] m");
  if (!in_range(obstacle_height, 0.05, 5)) return invalid(why, "obstacle_height: must be in [0.05, 5] m");
  if (!in_range(map_cell, 0.05, 2)) return invalid(why, "map_cell: must be in [0.05, 2] m");
  if (!in_range(obstacle_margin, 0, 5)) return invalid(why, "obstacle_margin: must be in [0, 5] m");
  if (!in_range(max_landing_offset, 0, 10)) return invalid(why, "max_landing_offset: must be in [0, 10] m");
  if (!in_range(replan_period, 0.1, 60)) return invalid(why, "replan_period: must be in [0.1, 60] s");
  if (!in_range(track_gate, 0.1, 100)) return invalid(why, "track_gate: must be in [0.1, 100] m");
  return true;
}

std::unique_ptr<LandingSystem> make_landing_system(std::string_view name, const MlsOptions& options) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("landing system options: " + why);
  if (name == "opencv-mls") return std::make_unique<MarkerLandingSystem>(options, false);
  if (name == "mm-mls") return std::make_unique<MarkerLandingSystem>(options, true);
  throw InvalidArgument("landing system: unknown '" + std::string(name) + "' (known: opencv-mls, mm-mls)");
}

std::vector<std::string> landing_system_names() { return {"opencv-mls", "mm-mls"}; }

}  // namespace touchdown::scenario
