#pragma once
/// \file
/// The renderer's solids as triangle meshes, and the polygon clipping of the
/// ground and object passes (render_mesh.cpp).
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "scenario/render_internal.hpp"
#include "touchdown/scenario/geometry.hpp"

namespace touchdown::scenario::render_detail {

struct Mesh {
  std::vector<Eigen::Vector3d> v;  // vertices (world for static objects, object frame for dynamic ones)
  std::vector<std::array<int, 3>> tri;
  std::vector<float> tint;  // per-triangle colour variation
  Bgr bgr{128, 128, 128};
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // bounding sphere
  double radius = 0;
};

/// A convex solid as triangles in its parent frame, wound outwards.
Mesh tessellate(const Solid& s, std::uint64_t seed);

// Polygon clipping (Sutherland–Hodgman).

/// Keeps the part of a 3-D polygon (camera frame) with z ≥ kNear.
void clip_near(const std::vector<Eigen::Vector3d>& in, std::vector<Eigen::Vector3d>& out);

/// Keeps the part of a 2-D polygon inside [x0, x1] × [y0, y1].
void clip_rect(std::vector<Eigen::Vector2d>& poly, std::vector<Eigen::Vector2d>& tmp, double x0, double y0, double x1,
               double y1);

/// The area of a simple polygon (shoelace formula).
double shoelace(const std::vector<Eigen::Vector2d>& p);

}  // namespace touchdown::scenario::render_detail
