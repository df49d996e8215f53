#pragma once
/// \file
/// A pose estimate as one JSON line (`led_pose --jsonl`; docs/formats.md,
/// "Pose estimates"): frame, ok, translation, quaternion (w ≥ 0), 1-σ,
/// reprojection error, LEDs and blobs, time and the 6×6 twist covariance;
/// for a frame without a pose its reason (and the σ that failed the gate).
#include <string>
#include <string_view>

#include "touchdown/pose/pose_estimate.hpp"

namespace touchdown::pose {

/// One line, no newline. `ms` is the estimate's time.
[[nodiscard]] std::string pose_json(std::string_view frame, const PoseEstimate& e, double ms);

}  // namespace touchdown::pose
