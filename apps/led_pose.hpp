#pragma once
// led_pose's modes, a group per source file (led_pose.cpp: main, the
// command line and the pieces the modes share; _render: render and
// benchmark; _sequence: the sequence mode).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "app_common.hpp"
#include "touchdown/pose/camera.hpp"
#include "touchdown/pose/constellation.hpp"
#include "touchdown/pose/sim/aruco_baseline.hpp"
#include "touchdown/pose/sim/synthetic.hpp"
#include "touchdown/pose/sim/trajectory.hpp"

namespace touchdown::app::led_pose_app {

namespace tp = touchdown::pose;

// The command line of the three modes: sequence (the default), render and
// benchmark. Some options are shared: the ArUco marker (sequence, render),
// the rendering choices (render, benchmark), depth and fusion (sequence,
// benchmark).
struct Args {
  // Sequence mode.
  std::string sequence_dir, camera_file, constellation_file, method = "led";
  tp::ArucoOptions aruco;
  // Given on the command line: checked against the sequence's own marker.
  CLI::Option *aruco_dict_opt = nullptr, *aruco_id_opt = nullptr, *aruco_size_opt = nullptr;
  bool no_depth = false, jsonl = false, fuse = false;
  std::string attitude_file;
  std::vector<double> max_sigma;  // --max-sigma POSITION_M,ROTATION_RAD (empty: the tracker's default)
  // render; benchmark shares the camera, constellation, geometry, tilt,
  // seed and profile.
  CLI::App* render = nullptr;
  std::string out_dir, r_camera, r_constellation;
  bool overwrite = false;
  tp::TrajectoryKind trajectory = tp::TrajectoryKind::Static;
  tp::CameraGeometry geometry = tp::CameraGeometry::Facing;
  double camera_tilt_deg = 20;
  int frames = 300;
  std::uint64_t seed = 1;
  double min_distance = 0.4, max_distance = 3.0;
  tp::RenderOptions ropt;
  tp::RenderProfile profile = tp::RenderProfile::Clean;
  CLI::Option* render_tilt = nullptr;
  // Set explicitly, these override the profile's values.
  CLI::Option *noise_opt = nullptr, *distractors_opt = nullptr, *dropout_opt = nullptr;
  // benchmark.
  CLI::App* bench = nullptr;
  bool json = false;
  int bench_frames = 300;
  CLI::Option *bench_geometry = nullptr, *bench_tilt = nullptr, *bench_profile = nullptr;
};

int run_render(const Args& a);
int run_benchmark(const Args& a);
int run_sequence(const Args& a);

/// The renderer's image limit, checked before anything is allocated, naming
/// the camera file (`what`: "--camera FILE").
void check_render_size(const tp::CameraModel& c, const std::string& what);
/// "848x480".
std::string size_text(const tp::CameraModel& c);
/// A library message in the flags' terms (`noise_sigma` -> `--noise`).
std::string in_flag_terms(std::string message);
tp::CameraModel camera_or_default(const std::string& f);
tp::Constellation constellation_or_default(const std::string& f);
/// Options that would be silently ignored are errors (issue 11).
void refuse_unused(const CLI::Option* opt, const std::string& why);

}  // namespace touchdown::app::led_pose_app
