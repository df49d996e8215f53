// Detector datasets from the test world (touchdown/scenario/dataset.hpp).
#include "touchdown/scenario/dataset.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "touchdown/core/error.hpp"
#include "touchdown/core/random.hpp"
#include "touchdown/core/units.hpp"
#include "touchdown/pose/sim/aruco_dictionary.hpp"

namespace touchdown::scenario {

namespace {

/// The four ground corners of a square of side `size` about `centre`.
std::array<Eigen::Vector2d, 4> square(const Eigen::Vector2d& centre, double yaw_deg, double size) {
  const double c = std::cos(deg_to_rad(yaw_deg)), s = std::sin(deg_to_rad(yaw_deg)), h = 0.5 * size;
  const Eigen::Vector2d ex(c, s), ey(-s, c);
  return {centre + h * (-ex + ey), centre + h * (ex + ey), centre + h * (ex - ey), centre + h * (-ex - ey)};
}

/// Whether `p` is inside the convex quadrilateral `q` (either winding).
bool inside_quad(const std::array<Eigen::Vector2d, 4>& q, const Eigen::Vector2d& p) {
  int sign = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = q[i], b = q[(i + 1) % 4];
    const double cross = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    const int s = cross > 0 ? 1 : (cross < 0 ? -1 : 0);
    if (s == 0) continue;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

/// The outline of a ground square in the frame; visible_fraction from the
/// mask pixels of `label` inside it (sampled, ≤ ~4096 pixels).
QuadLabel project(const std::array<Eigen::Vector2d, 4>& ground, const Eigen::Isometry3d& T_world_camera,
                  const CameraOptions& camera, const CameraFrame& frame, Label label) {
  QuadLabel q;
  // The renderer's pinhole: principal point at the image centre.
  const double f = camera.fx(), cx = 0.5 * (camera.width - 1), cy = 0.5 * (camera.height - 1);
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  q.in_front = true;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector3d pc = T_camera_world * Eigen::Vector3d(ground[i].x(), ground[i].y(), 0);
    if (pc.z() <= 1e-3) q.in_front = false;
    q.corners[i] = Eigen::Vector2d(f * pc.x() / pc.z() + cx, f * pc.y() / pc.z() + cy);
  }
  if (!q.in_front) {
    q.corners = {};
    return q;
  }
  // Clockwise on the screen (y down: a positive shoelace sum), from the
  // corner nearest the top-left.
  double area2 = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = q.corners[i], b = q.corners[(i + 1) % 4];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  if (area2 < 0) std::swap(q.corners[1], q.corners[3]);
  std::size_t first = 0;
  for (std::size_t i = 1; i < 4; ++i) {
    if (q.corners[i].sum() < q.corners[first].sum()) first = i;
  }
  std::rotate(q.corners.begin(), q.corners.begin() + static_cast<std::ptrdiff_t>(first), q.corners.end());
  Eigen::Vector2d lo = q.corners[0], hi = q.corners[0];
  for (const Eigen::Vector2d& c : q.corners) lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
  const double whole = (hi - lo).prod();
  q.box_min = lo.cwiseMax(Eigen::Vector2d::Zero());
  q.box_max = hi.cwiseMin(Eigen::Vector2d(camera.width, camera.height));
  if (!(q.box_max.x() > q.box_min.x() && q.box_max.y() > q.box_min.y())) {
    q.box_min = q.box_max = Eigen::Vector2d::Zero();
    return q;
  }
  q.inside_fraction = whole > 0 ? (q.box_max - q.box_min).prod() / whole : 0;
  const int x0 = static_cast<int>(std::floor(q.box_min.x())), x1 = static_cast<int>(std::ceil(q.box_max.x())) - 1;
  const int y0 = static_cast<int>(std::floor(q.box_min.y())), y1 = static_cast<int>(std::ceil(q.box_max.y())) - 1;
  const int step = std::max(1, static_cast<int>(std::sqrt((x1 - x0 + 1.0) * (y1 - y0 + 1.0) / 4096.0)));
  int in = 0, shown = 0;
  for (int y = y0; y <= y1; y += step) {
    for (int x = x0; x <= x1; x += step) {
      if (!inside_quad(q.corners, Eigen::Vector2d(x, y))) continue;
      ++in;
      const std::size_t k =
          static_cast<std::size_t>(y) * static_cast<std::size_t>(frame.width) + static_cast<std::size_t>(x);
      shown += frame.mask[k] == mask_value(label) ? 1 : 0;
    }
  }
  q.visible_fraction = in > 0 ? static_cast<double>(shown) / in : 0;
  return q;
}

/// A point in the disc of `radius` about the origin, uniform by area.
Eigen::Vector2d in_disc(Rng& r, double radius) {
  const double rho = radius * std::sqrt(r.uniform()), a = r.uniform(0, 2 * std::numbers::pi);
  return {rho * std::cos(a), rho * std::sin(a)};
}

}  // namespace

DatasetFrame label_frame(const Scenario& s, const CameraOptions& camera, const SceneState& state) {
  DatasetFrame out;
  out.scenario = s;
  out.weather = dominant_weather(s.weather);
  out.camera = camera;
  out.T_world_camera = state.T_world_body * camera.T_body_camera();
  Renderer renderer(s, camera);
  renderer.render(state, out.frame);
  out.distance =
      (Eigen::Vector3d(s.marker.position.x(), s.marker.position.y(), 0) - out.T_world_camera.translation()).norm();
  out.target = project(square(s.marker.position, s.marker.yaw_deg, s.marker.size), out.T_world_camera, camera,
                       out.frame, Label::Marker);
  for (const Distractor& d : s.distractors) {
    out.distractors.push_back({d.kind, project(square(d.position, d.yaw_deg, d.size), out.T_world_camera, camera,
                                               out.frame, Label::Distractor)});
  }
  out.view = TargetOracle(s, OracleOptions{}).observe(out.frame, out.T_world_camera, camera);
  return out;
}

bool DatasetOptions::validate(std::string* why) const {
  const auto* dict = pose::find_aruco_dictionary(dictionary);
  if (!dict) return invalid(why, "marker: unknown dictionary " + dictionary);
  if (marker_id < 0 || marker_id >= dict->codes)
    return invalid(why, "marker: " + dictionary + " has ids 0.." + std::to_string(dict->codes - 1));
  if (!camera.validate(why)) return false;
  if (!(std::isfinite(max_tilt_deg) && max_tilt_deg >= 0 && max_tilt_deg <= 60))
    return invalid(why, "max_tilt_deg: must be in [0, 60]");
  if (!(std::isfinite(validation_fraction) && std::isfinite(test_fraction) && validation_fraction >= 0 &&
        test_fraction >= 0 && validation_fraction + test_fraction <= 1))
    return invalid(why, "validation_fraction, test_fraction: must be ≥ 0 and sum to ≤ 1");
  return true;
}

namespace {

// Frame `index`'s generator, its options and index checked.
Rng frame_rng(const DatasetOptions& options, int index) {
  std::string why;
  if (!options.validate(&why)) throw InvalidArgument("dataset: " + why);
  if (index < 0) throw InvalidArgument("dataset: frame index must be ≥ 0");
  return Rng(options.seed, static_cast<std::uint64_t>(index));
}

// The split of a frame whose first draw is `u`.
DatasetSplit split_of(const DatasetOptions& options, double u) {
  return u < options.test_fraction                                 ? DatasetSplit::Test
         : u < options.test_fraction + options.validation_fraction ? DatasetSplit::Validation
                                                                   : DatasetSplit::Train;
}

}  // namespace

DatasetSplit dataset_split(const DatasetOptions& options, int index) {
  Rng r = frame_rng(options, index);
  return split_of(options, r.uniform());
}

DatasetFrame render_dataset_frame(const DatasetOptions& options, int index) {
  Rng r = frame_rng(options, index);
  DatasetFrame out;
  out.index = index;
  out.split = split_of(options, r.uniform());
  const MapKind map = r.uniform() < 0.5 ? MapKind::Ground : MapKind::Lawn;
  out.scenario_seed = r.next();
  Scenario s = random_scenario(out.scenario_seed, map);
  set_target(s, options.dictionary, options.marker_id);

  // The camera where a system would have it.
  out.camera = options.camera;
  out.camera.tilt_deg = r.uniform() < 0.2 ? r.uniform(0, options.max_tilt_deg) : 0;
  const double u = r.uniform();
  // Horizontal speeds follow the phase: cruise while searching and
  // approaching, re-centring while descending (descent_speed 0.8 m/s,
  // mm-mls's plan up to 1.75× that), creeping when about to land.
  double altitude = 10, reach = 0, max_speed = 3;
  if (u < 0.35) {
    out.phase = "search", altitude = r.uniform(8, 12), reach = 12;
  } else if (u < 0.45) {
    out.phase = "approach", altitude = r.uniform(9, 13), reach = 25;
  } else if (u < 0.85) {
    out.phase = "descent", altitude = r.uniform(1.5, 8), reach = 0.5 * altitude, max_speed = 1.5;
  } else {
    out.phase = "land", altitude = r.uniform(0.6, 1.5), reach = 0.4, max_speed = 0.8;
  }
  const Eigen::Vector2d xy = s.marker.position + in_disc(r, reach);
  const double yaw = r.uniform(-180, 180);
  SceneState state;
  state.T_world_body =
      Eigen::Translation3d(xy.x(), xy.y(), altitude) * Eigen::AngleAxisd(deg_to_rad(yaw), Eigen::Vector3d::UnitZ());
  const double speed = r.uniform(0, max_speed), heading = r.uniform(0, 2 * std::numbers::pi);
  state.v_world = Eigen::Vector3d(speed * std::cos(heading), speed * std::sin(heading), 0);
  state.t = r.uniform(0, 40);
  state.frame_index = static_cast<int>(r.next() % 100000);
  // The moving objects at their starts (as World places them), one of them
  // sometimes moved over the target.
  for (const DynamicObject& o : s.dynamic_objects) {
    const double z = o.kind == DynamicKind::Bird ? o.altitude : 0.0;
    state.T_world_dynamic.push_back(Eigen::Translation3d(o.position.x(), o.position.y(), z) *
                                    Eigen::AngleAxisd(deg_to_rad(o.heading_deg), Eigen::Vector3d::UnitZ()));
  }
  if (!s.dynamic_objects.empty() && r.uniform() < 0.3) {
    const auto k = static_cast<std::size_t>(r.next() % s.dynamic_objects.size());
    const Eigen::Vector2d at = s.marker.position + in_disc(r, 0.6 * s.marker.size);
    state.T_world_dynamic[k].translation().head<2>() = at;
    out.occluder =
        "dynamic_objects[" + std::to_string(k) + "] (" + std::string(to_string(s.dynamic_objects[k].kind)) + ")";
  }
  DatasetFrame labelled = label_frame(s, out.camera, state);
  labelled.index = out.index;
  labelled.scenario_seed = out.scenario_seed;
  labelled.split = out.split;
  labelled.phase = out.phase;
  labelled.occluder = out.occluder;
  out = std::move(labelled);
  return out;
}

}  // namespace touchdown::scenario
