#include "touchdown/pose/sim/pose_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "touchdown/core/error.hpp"
#include "touchdown/core/statistics.hpp"
#include "touchdown/pose/epnp.hpp"

namespace touchdown::pose {

bool PoseBenchmarkOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  std::string w;
  if (!camera.validate(&w)) return fail("camera: " + w);
  if (static_cast<long long>(camera.width) * camera.height > SyntheticCamera::kMaxPixels) {
    return fail("camera: " + std::to_string(camera.width) + " x " + std::to_string(camera.height) +
                " pixels is more than the renderer's limit of " + std::to_string(SyntheticCamera::kMaxPixels) +
                " (4096 x 4096)");
  }
  if (scenarios.empty() && !constellation.validate(&w)) return fail("constellation: " + w);
  for (const auto& sc : scenarios) {
    if (!sc.constellation.validate(&w)) return fail("scenarios[" + sc.name + "].constellation: " + w);
    if (!(sc.camera_tilt_deg >= 0 && sc.camera_tilt_deg <= 80))
      return fail("scenarios[" + sc.name + "].camera_tilt_deg: must be in [0, 80]");
  }
  if (frames < 1 || frames > kMaxTrajectoryFrames) {
    return fail("frames: must be in 1.." + std::to_string(kMaxTrajectoryFrames));
  }
  if (!(min_distance > 0 && max_distance > min_distance && max_distance <= kMaxTrajectoryDistance)) {
    return fail("distances: need 0 < min < max <= " + std::to_string(static_cast<int>(kMaxTrajectoryDistance)) + " m");
  }
  if (!(success_px > 0)) return fail("success_px: must be positive");
  if (!aruco.validate(&w)) return fail("aruco: " + w);
  if (!rendered_options().validate(&w)) return fail("render: " + w);
  for (const auto& sc : scenarios) {
    if (!apply_profile(rendered_options(), sc.profile).validate(&w)) {
      return fail("scenarios[" + sc.name + "].profile: " + w);
    }
  }
  if (!tracker.validate(&w)) return fail("tracker: " + w);
  return true;
}

RenderOptions PoseBenchmarkOptions::rendered_options() const {
  RenderOptions r = render;
  r.aruco_dictionary = aruco.dictionary;
  r.aruco_id = aruco.marker_id;
  r.aruco_size = aruco.marker_size;
  return r;
}

std::vector<BenchmarkScenario> default_benchmark_scenarios() {
  return {{"f450 below", default_constellation(), CameraGeometry::Facing, 20, RenderProfile::Clean},
          {"paper chase", front_board_constellation(), CameraGeometry::Chase, 20, RenderProfile::Clean},
          {"paper chase", front_board_constellation(), CameraGeometry::Chase, 20, RenderProfile::Harsh}};
}

std::pair<double, double> pose_error(const Eigen::Isometry3d& e, const Eigen::Isometry3d& t) {
  return {(e.translation() - t.translation()).norm(), Eigen::AngleAxisd(e.linear().transpose() * t.linear()).angle()};
}

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct Accumulator {
  MethodStats s;
  std::vector<double> pos, rot, ms;
  void add(const PoseEstimate& e, const Eigen::Isometry3d& truth, double elapsed_ms, double success_px) {
    ++s.frames;
    ms.push_back(elapsed_ms);
    if (!e.ok()) return;
    const auto [p, r] = pose_error(e.T_camera_body, truth);
    if (p > 0.1 || r > 0.1) ++s.wrong_ok;
    if (!(e.rms_px < success_px)) return;
    ++s.successes;
    pos.push_back(p);
    rot.push_back(r);
  }
  MethodStats finish() {
    auto mean_std = [](const std::vector<double>& v, double& mean, double& sd) {
      mean = sd = 0;
      if (v.empty()) return;
      for (double x : v) mean += x;
      mean /= static_cast<double>(v.size());
      for (double x : v) sd += (x - mean) * (x - mean);
      sd = std::sqrt(sd / static_cast<double>(v.size()));
    };
    mean_std(pos, s.position_mean_m, s.position_std_m);
    mean_std(rot, s.orientation_mean_rad, s.orientation_std_rad);
    s.position_max_m = pos.empty() ? 0 : *std::max_element(pos.begin(), pos.end());
    s.success_rate = s.frames ? static_cast<double>(s.successes) / s.frames : 0;
    s.wrong_ok_rate = s.frames ? static_cast<double>(s.wrong_ok) / s.frames : 0;
    s.ms_median = quantile(ms, 0.5);
    s.ms_p90 = quantile(ms, 0.9);
    return s;
  }
};

template <typename F>
double time_us(F&& f) {
  const auto t0 = Clock::now();
  f();
  return std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
}

}  // namespace

PoseBenchmarkResult run_pose_benchmark(const PoseBenchmarkOptions& o) {
  std::string why;
  if (!o.validate(&why)) throw InvalidArgument("benchmark options: " + why);
  std::vector<BenchmarkScenario> scenarios = o.scenarios;
  if (scenarios.empty()) scenarios.push_back({"custom", o.constellation, CameraGeometry::Facing, 20});
  PoseBenchmarkResult result;
  std::vector<double> ours_us, iter_us, sqp_us, epnp_us;
  const PinholeCamera pin = o.camera.pinhole();
  const cv::Matx33d K(pin.fx, 0, pin.cx, 0, pin.fy, pin.cy, 0, 0, 1);
  RenderedFrame frame;
  int sequence_index = 0;
  for (const BenchmarkScenario& scenario : scenarios) {
    const Constellation& k = scenario.constellation;
    const SyntheticCamera synth(o.camera, k, apply_profile(o.rendered_options(), scenario.profile));
    TrajectoryOptions to;
    to.min_distance = o.min_distance;
    to.max_distance = o.max_distance;
    to.geometry = scenario.geometry;
    to.camera_tilt_deg = scenario.camera_tilt_deg;
    for (const TrajectoryKind kind : {TrajectoryKind::Static, TrajectoryKind::Moving}) {
      const std::string name(to_string(kind));
      const std::uint64_t seed = o.seed * 1000003ull + static_cast<std::uint64_t>(sequence_index++);
      const auto trajectory = make_trajectory(kind, o.frames, seed, o.camera, k, to);
      LedTracker tracker(o.camera, k, o.tracker);
      ArucoPoseEstimator aruco(o.camera, k.T_body_marker, o.aruco);
      Accumulator led, marker;
      led.s.method = "led";
      marker.s.method = "aruco";
      led.s.sequence = marker.s.sequence = name;
      led.s.scenario = marker.s.scenario = scenario.name;
      led.s.profile = marker.s.profile = std::string(to_string(scenario.profile));
      for (std::size_t i = 0; i < trajectory.size(); ++i) {
        synth.render(trajectory[i].T_camera_body, motion_blur_start(trajectory, i), seed, i, frame);
        const DepthImageView depth = frame.depth.view();
        auto t0 = Clock::now();
        const PoseEstimate& e = tracker.track(frame.colour.view(), o.use_depth ? &depth : nullptr);
        led.add(e, trajectory[i].T_camera_body, ms_since(t0), o.success_px);
        // Solver comparison on the matched LEDs (undistorted pixels).
        if (e.ok()) {
          std::vector<Eigen::Vector3d> p;
          std::vector<Eigen::Vector2d> uv;
          std::vector<cv::Point3d> obj;
          std::vector<cv::Point2d> img;
          for (std::size_t l = 0; l < k.leds.size(); ++l) {
            const int b = tracker.led_to_blob()[l];
            const auto held = tracker.led_to_blob().begin() + static_cast<std::ptrdiff_t>(k.leds.size());
            if (b < 0 || std::count(tracker.led_to_blob().begin(), held, b) > 1) continue;  // a merged spot
            p.push_back(k.leds[l].p_body);
            uv.push_back(tracker.blobs()[static_cast<std::size_t>(b)].uv_undistorted);
            obj.emplace_back(p.back().x(), p.back().y(), p.back().z());
            img.emplace_back(uv.back().x(), uv.back().y());
          }
          if (p.size() >= 6) {  // OpenCV's ITERATIVE needs 6 non-coplanar points
            ++result.solver_samples;
            ours_us.push_back(time_us([&] { (void)solve_pnp(pin, p, uv, o.tracker.correspondence.refine); }));
            cv::Mat rvec, tvec;
            iter_us.push_back(
                time_us([&] { cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_ITERATIVE); }));
            sqp_us.push_back(
                time_us([&] { cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_SQPNP); }));
            epnp_us.push_back(
                time_us([&] { cv::solvePnP(obj, img, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_EPNP); }));
          }
        }
        t0 = Clock::now();
        const PoseEstimate a = aruco.estimate(frame.colour.view());
        marker.add(a, trajectory[i].T_camera_body, ms_since(t0), o.success_px);
      }
      result.rows.push_back(led.finish());
      result.rows.push_back(marker.finish());
    }
  }
  for (const MethodStats& row : result.rows) {
    if (row.successes > 0) continue;
    result.status = PoseBenchmarkStatus::NoSuccessfulFrames;
    result.message += (result.message.empty() ? "" : "; ") + row.method + " on the " + row.scenario + " " +
                      row.profile + " " + row.sequence + " sequence: no successful frame of " +
                      std::to_string(row.frames) + " (its error statistics are undefined)";
  }
  result.epnp_gn_us_median = quantile(ours_us, 0.5);
  result.opencv_iterative_us_median = quantile(iter_us, 0.5);
  result.opencv_sqpnp_us_median = quantile(sqp_us, 0.5);
  result.opencv_epnp_us_median = quantile(epnp_us, 0.5);
  return result;
}

}  // namespace touchdown::pose
