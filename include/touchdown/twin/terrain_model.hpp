#pragma once
/// \file
/// The terrain as the twin sees it: a triangle mesh (world frame, z up) with
/// a 2-D bucket grid for fast, thread-safe spatial queries (surface height,
/// candidate triangles for contact generation).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "touchdown/core/mesh.hpp"
#include "touchdown/core/point_cloud.hpp"
#include "touchdown/terrain/terrain_mesher.hpp"
#include "touchdown/twin/height_field.hpp"

namespace touchdown::twin {

/// Where the terrain was never observed: a regular grid of flags (cell
/// (i, j) covers x ∈ [x0 + i·cell, x0 + (i+1)·cell), the same in y), from the
/// height map's CellState::Unknown cells. Empty: everything is known.
struct UnknownCells {
  double x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  std::vector<std::uint8_t> unknown;  ///< nx·ny, row-major (j·nx + i)
  [[nodiscard]] bool empty() const { return unknown.empty(); }
  /// The unknown cells of a height map (empty when it has none).
  static UnknownCells of(const terrain::HeightMap& map);
};

/// Immutable after construction; every const member is safe to call from
/// many threads at once. Memory: the mesh plus about 160 bytes per triangle
/// (double vertices and normal, bucket entries with the triangle's box).
class TerrainModel {
 public:
  /// Throws touchdown::InvalidArgument for a mesh without triangles or an
  /// `unknown` grid whose size does not match its flags.
  explicit TerrainModel(TriangleMesh mesh, UnknownCells unknown = {});

  [[nodiscard]] const TriangleMesh& mesh() const { return mesh_; }
  [[nodiscard]] const Bounds3& bounds() const { return bounds_; }

  /// Highest surface point on the vertical line through (x, y), if any.
  [[nodiscard]] std::optional<double> top_z(double x, double y) const;

  /// Highest surface point over the disk of `radius` around `centre`
  /// (sampled every `step` metres, plus every mesh vertex inside). Empty if
  /// any sample has no surface under it (the terrain does not cover the disk).
  [[nodiscard]] std::optional<double> max_top_z(const Eigen::Vector2d& centre, double radius, double step = 0.01) const;

  /// Appends the indices of triangles whose bounding box overlaps `box`
  /// (each once, in a deterministic order).
  void triangles_overlapping(const Eigen::AlignedBox3d& box, std::vector<std::uint32_t>& out) const;

  /// Highest terrain point (over whole buckets, so possibly a little more)
  /// whose bucket overlaps the x-y extent of `box`; -inf where there is none.
  /// A cheap test whether anything at all can touch a body in `box`.
  [[nodiscard]] double max_z_near(const Eigen::AlignedBox3d& box) const;

  /// The mesh as a height field (HeightField::detect), or nullptr when it
  /// is not one: contact generation then walks the buckets.
  [[nodiscard]] const HeightField* height_field() const { return height_field_.get(); }

  [[nodiscard]] const UnknownCells& unknown_cells() const { return unknown_; }
  /// True when an unknown cell's square comes within `radius` of the
  /// segment a–b (a capsule; a disk when a == b).
  [[nodiscard]] bool unknown_near(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double radius) const;
  /// True when an unknown cell's square overlaps the rectangle of half
  /// extents `half` centred at `centre` and turned by `yaw` (padded by `pad`).
  [[nodiscard]] bool unknown_in_box(const Eigen::Vector2d& centre, const Eigen::Vector2d& half, double yaw,
                                    double pad) const;

  /// Index of vertex k of triangle `tri` (shared between triangles).
  [[nodiscard]] std::uint32_t vertex_index(std::uint32_t tri, int k) const {
    return mesh_.triangles[tri][static_cast<std::size_t>(k)];
  }
  /// Triangle vertices as doubles.
  [[nodiscard]] const Eigen::Vector3d& vertex(std::uint32_t tri, int k) const {
    return geometry_[tri].v[static_cast<std::size_t>(k)];
  }
  /// Unit normal of triangle `tri` ((v1 - v0) × (v2 - v0), normalised; +z
  /// for a degenerate triangle).
  [[nodiscard]] const Eigen::Vector3d& normal(std::uint32_t tri) const { return geometry_[tri].n; }

 private:
  TriangleMesh mesh_;
  UnknownCells unknown_;
  Bounds3 bounds_;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::uint32_t> start_;  // per cell offsets into items_
  // A triangle in a bucket, with its bounding box (kept beside the index so
  // that a query reads each bucket in one sweep).
  struct Item {
    Eigen::AlignedBox3f box;
    std::uint32_t triangle;
  };
  std::vector<Item> items_;
  std::vector<float> cell_max_z_;             // per bucket: highest point of its triangles
  std::vector<std::array<int, 2>> tri_cell_;  // first bucket of each triangle
  // Per triangle, computed once: its vertices as doubles and its unit
  // normal (contact generation reads them for every candidate every step).
  struct TriangleGeometry {
    std::array<Eigen::Vector3d, 3> v;
    Eigen::Vector3d n;
  };
  std::vector<TriangleGeometry> geometry_;
  // max_z_near's second level: the highest point of each block of
  // kBlock x kBlock buckets.
  static constexpr int kBlock = 8;
  int bx_ = 1, by_ = 1;
  std::vector<float> block_max_z_;
  std::shared_ptr<const HeightField> height_field_;
};

/// A terrain file as read: a mesh (.stl, .obj, .ply with faces) or a point
/// cloud (.pcd, .ply without faces, .xyz/.csv/.txt). A caller can look at
/// it before it becomes a TerrainModel: whether it is a mesh (always world
/// frame, so a camera pose does not apply) and, for a cloud, which frame it
/// looks like (terrain::camera_frame_evidence).
struct TerrainFile {
  std::filesystem::path path;
  std::optional<TriangleMesh> mesh;  ///< set for a mesh file
  PointCloud cloud;                  ///< the points of a cloud file (empty for a mesh)
  [[nodiscard]] bool is_mesh() const { return mesh.has_value(); }
};

/// Reads a terrain file. Throws touchdown::Error subclasses naming the file
/// (an empty cloud included).
TerrainFile read_terrain_file(const std::filesystem::path& path);

/// The twin's terrain from a file read by read_terrain_file: a mesh as is,
/// or a cloud meshed by the terrain stage with `cloud_options` (its camera
/// pose included; the identity takes the cloud to be world-frame as it is:
/// this function does not check the frame). Throws touchdown::Error
/// subclasses naming the file.
std::shared_ptr<const TerrainModel> make_terrain_model(TerrainFile file,
                                                       const terrain::TerrainOptions& cloud_options = {});

/// make_terrain_model(read_terrain_file(path), cloud_options).
std::shared_ptr<const TerrainModel> load_terrain_model(const std::filesystem::path& path,
                                                       const terrain::TerrainOptions& cloud_options = {});

}  // namespace touchdown::twin
