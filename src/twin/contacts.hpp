#pragma once
// Narrow-phase contact generation between the twin's primitives and the
// terrain triangles (internal). Thread-safe: pure functions over const data.
//
// Why not ODE's own trimesh colliders: Debian's libode is built without
// ODE_EXT_mt_collisions, so its OPCODE trimesh colliders share one global
// cache and may not run from several threads at once; the sweep runs its
// landings in parallel. ODE's manual allows any collision system that
// supplies contact points; ODE still does all the dynamics.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/terrain_model.hpp"

namespace touchdown::twin::detail {

struct Contact {
  Eigen::Vector3d position;
  Eigen::Vector3d normal;  // unit, from the terrain into the drone part
  double depth = 0;        // penetration, > 0
};

/// Closest point of triangle (a, b, c) to p.
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                          const Eigen::Vector3d& c);

/// Closest points between segment p0-p1 and triangle (a, b, c); returns
/// the squared distance, with the points in `on_segment`, `on_triangle`.
double closest_segment_triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b, const Eigen::Vector3d& c, Eigen::Vector3d& on_segment,
                                Eigen::Vector3d& on_triangle);

struct Scratch {
  std::vector<std::uint32_t> triangles;
  std::vector<std::pair<std::uint32_t, Eigen::Vector3d>> vertex_normals;
  std::vector<Contact> contacts;
  std::vector<double> gap;  // collide_box's farthest-point sampling
  std::vector<bool> taken;
};

/// World-frame primitives → contacts appended to `out`.
void collide_sphere(const TerrainModel& terrain, const Eigen::Vector3d& centre, double radius, Scratch& scratch,
                    std::vector<Contact>& out);
void collide_capsule(const TerrainModel& terrain, const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                     Scratch& scratch, std::vector<Contact>& out);
void collide_disk(const TerrainModel& terrain, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                  double radius, double half_thickness, Scratch& scratch, std::vector<Contact>& out);
/// Most contacts collide_box gives.
inline constexpr std::size_t kMaxBoxContacts = 8;
/// Box contacts: its corners inside the terrain and the terrain's vertices
/// inside the box (points fixed to one body, so a resting box keeps its
/// support), or, when neither touches, MPR contacts (an edge across an
/// edge); at most kMaxBoxContacts, spread over the contact area.
void collide_box(const TerrainModel& terrain, const Eigen::Vector3d& centre, const Eigen::Matrix3d& axes,
                 const Eigen::Vector3d& half_extents, Scratch& scratch, std::vector<Contact>& out);

}  // namespace touchdown::twin::detail
