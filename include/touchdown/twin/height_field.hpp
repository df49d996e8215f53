#pragma once
/// \file
/// A terrain mesh that is a height field (issue 57, item 3): its top
/// surface a regular grid of vertices with two triangles per quad, closed by
/// vertical walls along its boundary and a flat bottom below — what
/// terrain::triangulate_solid makes of a depth camera's cloud, whether it
/// comes straight from the cloud or from a mesh file written from one.
/// Contact generation then finds its candidate triangles by indexing the
/// grid instead of walking buckets (docs/architecture.md, "Contacts").
#include <Eigen/Geometry>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "touchdown/core/mesh.hpp"

namespace touchdown::twin {

class HeightField {
 public:
  /// The height field of `mesh` (whose triangles' unit normals are
  /// `normals`), or nullptr when the mesh is not one: a top triangle off the
  /// grid, a quad with one triangle or two that do not tile it, a wall that
  /// is not a vertical strip along a grid edge, or a downward face above the
  /// lowest top vertex.
  static std::shared_ptr<const HeightField> detect(const TriangleMesh& mesh,
                                                   const std::vector<Eigen::Vector3d>& normals);

  /// Appends the top and wall triangles whose bounding box overlaps `box`
  /// (each once, in the grid's order). The solid's bottom is left out: a
  /// part reaches it only through the top surface, having fallen through.
  void triangles_overlapping(const Eigen::AlignedBox3d& box, std::vector<std::uint32_t>& out) const;

  [[nodiscard]] double cell() const { return cell_; }
  [[nodiscard]] int quads_x() const { return qx_; }
  [[nodiscard]] int quads_y() const { return qy_; }
  [[nodiscard]] std::size_t wall_count() const { return wall_items_.size(); }

 private:
  HeightField() = default;
  struct Lattice;
  static bool fit_lattice(const std::vector<std::uint32_t>& top, Lattice& g);
  bool place_top(const std::vector<std::uint32_t>& top, const Lattice& g);
  bool place_walls(const std::vector<std::uint32_t>& wall, const Lattice& g);
  void build_blocks();
  double x0_ = 0, y0_ = 0, cell_ = 1;  // grid vertex (i, j) at (x0 + i·cell, y0 + j·cell)
  double inv_cell_ = 1;
  int qx_ = 0, qy_ = 0;  // quads (i, j) span vertices i..i+1, j..j+1
  static constexpr std::uint32_t kNone = 0xffffffffU;
  struct Quad {
    std::uint32_t tri[2] = {kNone, kNone};  // its two top triangles, or none
  };
  std::vector<Quad> quads_;
  std::vector<float> zmax_;  // per quad: the highest point of its triangles and the walls listed under it
  // The highest point of each block of kBlock × kBlock quads: a query skips
  // a block under its box at once.
  static constexpr int kBlock = 4;
  int bx_ = 0, by_ = 0;
  std::vector<float> block_zmax_;
  std::vector<Eigen::AlignedBox3f> tri_box_;  // per quad, its two top triangles' boxes
  // Wall triangles by quad slot (CSR); a wall sits on the edge between two
  // slots and is listed under both, reported from the first in the query.
  struct Wall {
    std::uint32_t triangle;
    std::uint32_t slot[2];  // the two quad slots beside its edge; slot[1] may be kNone (off the grid)
    Eigen::AlignedBox3f box;
  };
  std::vector<std::uint32_t> wall_start_;
  std::vector<std::uint32_t> wall_items_;  // indices into walls_
  std::vector<Wall> walls_;
};

}  // namespace touchdown::twin
