#pragma once
/// \file
/// The renderer's marker and distractor images (render_marker.cpp): their
/// cells, and the mip-mapped image as printed and lying on the ground.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/aruco.hpp>
#include <opencv2/core.hpp>
#include <vector>

#include "scenario/render_texture.hpp"
#include "touchdown/scenario/camera.hpp"

namespace touchdown::scenario::render_detail {

/// Marker cells (0 black, 255 white) with the one-cell white margin.
cv::Mat marker_cells(const cv::Ptr<cv::aruco::Dictionary>& dict, int bits, DistractorKind kind, int id,
                     int flipped_bits, int target_id, std::uint64_t flip_seed);

struct Quad {
  Label label = Label::Marker;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double cos_yaw = 1, sin_yaw = 0;
  double side = 1;                         // with the margin [m]
  std::array<Eigen::Vector3d, 4> corners;  // world, with margin: TL, TR, BR, BL of the image
  std::vector<cv::Mat> mips;               // BGRA
  std::vector<float> level_scale;          // mips[k].cols / mips[0].cols
};

/// The marker image as printed and lying on the ground: paper white, ink
/// black, then the ground's snow/leaf cover at each texel's world point and
/// the wet darkening.
Quad make_quad(const cv::Mat& cells, Label label, const Eigen::Vector2d& centre, double yaw_deg, double border_size,
               int bits, const CoverSampler& cover, const Eigen::Vector2d& map_shift, const Weather& weather);

}  // namespace touchdown::scenario::render_detail
