#pragma once
// Frames are never guessed (issue 11), shared by terrain_mesh and
// landing_sweep: a camera pose file's warnings go to stderr, and a cloud
// that looks like a camera frame is refused unless its pose is given.
#include <iostream>
#include <string>

#include "app_common.hpp"
#include "touchdown/core/error.hpp"
#include "touchdown/core/point_cloud.hpp"
#include "touchdown/terrain/extrinsics.hpp"
#include "touchdown/terrain/frame_check.hpp"

namespace touchdown::app {

/// Loads a camera pose YAML and prints each of its warnings on stderr as
/// "APP: warning: FILE:LINE: key: ...".
inline terrain::Extrinsics load_extrinsics_with_warnings(const std::string& app, const std::string& path) {
  terrain::Extrinsics e = terrain::load_extrinsics(path);
  print_warnings(app, e.warnings);
  return e;
}

/// Throws InvalidArgument (exit 2, one line) when `cloud`, read from `path`
/// without a camera pose, looks like a camera frame: the message says why
/// and names the two ways out.
inline void require_world_frame(const std::string& path, const PointCloud& cloud) {
  const terrain::FrameEvidence e = terrain::camera_frame_evidence(cloud);
  if (!e.camera_frame()) return;
  throw InvalidArgument(path + ": looks like a camera-frame point cloud: " + e.reason +
                        "; give the camera pose with --extrinsics FILE, or pass --assume-world-frame if it is "
                        "already in the world frame (z up)");
}

}  // namespace touchdown::app
