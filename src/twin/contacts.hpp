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
#include <limits>
#include <utility>
#include <vector>

#include "touchdown/twin/airframe.hpp"
#include "touchdown/twin/terrain_model.hpp"

namespace touchdown::twin::detail {

struct Contact {
  Eigen::Vector3d position;
  Eigen::Vector3d normal;  // unit, from the terrain into the drone part
  double depth = 0;        // penetration, > 0
  /// Its spring as a multiple of one contact's: a merged patch
  /// (merge_patch_contacts) pushes as hard as the contacts it stands for,
  /// Σ depth_i / depth (continuous as one of them comes or goes).
  double weight = 1;
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
  /// The run's candidate query: the terrain's height field (issue 57), or
  /// nullptr for its buckets. Either gives the same triangles near the top
  /// surface; the height field leaves out the solid's bottom.
  const HeightField* height_field = nullptr;
  /// This step's highest terrain point (or above) under the whole twin
  /// (TerrainModel::max_z_near): a part's query above it finds nothing
  /// and is not made.
  double z_top = std::numeric_limits<double>::infinity();
  std::vector<std::uint32_t> triangles;
  std::vector<std::pair<std::uint32_t, Eigen::Vector3d>> vertex_normals;
  std::vector<Contact> contacts;
  std::vector<double> gap;  // collide_box's farthest-point sampling
  std::vector<bool> taken;
};

/// The terrain triangles whose boxes overlap `box`, into scratch.triangles
/// (cleared first), by the query scratch.height_field picks.
void candidate_triangles(const TerrainModel& terrain, const Eigen::AlignedBox3d& box, Scratch& scratch);

/// Merges the contacts of one part (out[first..]) that stand for one patch
/// of surface: within `distance` of a deeper one with a normal within the
/// angle whose cosine is `cos_angle` of it. Keeps the deepest of each, in
/// order of depth (ties in the order found), its weight grown by theirs.
void merge_patch_contacts(std::vector<Contact>& out, std::size_t first, double distance, double cos_angle);

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
