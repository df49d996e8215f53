#include "touchdown/twin/height_field.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace touchdown::twin {
namespace {

// Corner c = di + 2·dj of a quad; the two diagonals as corner masks.
constexpr unsigned kDiagonal03 = 0b1001, kDiagonal12 = 0b0110;

}  // namespace

// The mesh's vertices in grid terms, during detection.
struct HeightField::Lattice {
  const TriangleMesh& mesh;
  double x0 = 0, y0 = 0, cell = 1, zmin_top = 0;
  [[nodiscard]] const Eigen::Vector3f& vert(std::uint32_t t, int k) const {
    return mesh.vertices[mesh.triangles[t][static_cast<std::size_t>(k)]];
  }
  // Vertex k of triangle t on a grid line in x and in y (within a
  // thousandth of a cell: float vertices), and its indices.
  bool grid_of(std::uint32_t t, int k, int& i, int& j) const {
    return on_grid(vert(t, k).x(), x0, i) && on_grid(vert(t, k).y(), y0, j);
  }
  [[nodiscard]] bool on_grid(double v, double origin, int& index) const {
    const double q = (v - origin) / cell;
    if (!(q > -0.5 && q < 1e8)) return false;
    index = static_cast<int>(std::lround(q));
    return std::abs(q - index) <= 1e-3;
  }
};

std::shared_ptr<const HeightField> HeightField::detect(const TriangleMesh& mesh,
                                                       const std::vector<Eigen::Vector3d>& normals) {
  std::vector<std::uint32_t> top, wall, bottom;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const double nz = normals[t].z();
    (nz > 1e-9 ? top : nz < -1e-9 ? bottom : wall).push_back(static_cast<std::uint32_t>(t));
  }
  Lattice g{mesh};
  auto hf = std::shared_ptr<HeightField>(new HeightField());
  if (top.empty() || !fit_lattice(top, g) || !hf->place_top(top, g) || !hf->place_walls(wall, g)) return nullptr;
  // The bottom lies under the whole top surface.
  for (std::uint32_t t : bottom) {
    for (int k = 0; k < 3; ++k) {
      if (g.vert(t, k).z() > g.zmin_top) return nullptr;
    }
  }
  hf->build_blocks();
  return hf;
}

bool HeightField::fit_lattice(const std::vector<std::uint32_t>& top, Lattice& g) {
  // The origin at the lowest top vertex in x and in y; the spacing from the
  // first top triangle's width, refined over the whole extent (one float
  // width is off by up to an ulp, which 300 cells multiply past the
  // tolerance of Lattice::on_grid).
  const double inf = std::numeric_limits<double>::infinity();
  double x0 = inf, y0 = inf, zmin = inf, xmax = -inf, ymax = -inf;
  for (std::uint32_t t : top) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d v = g.vert(t, k).cast<double>();
      x0 = std::min(x0, v.x());
      y0 = std::min(y0, v.y());
      zmin = std::min(zmin, v.z());
      xmax = std::max(xmax, v.x());
      ymax = std::max(ymax, v.y());
    }
  }
  double lo = inf, hi = -inf;
  for (int k = 0; k < 3; ++k) {
    lo = std::min(lo, static_cast<double>(g.vert(top[0], k).x()));
    hi = std::max(hi, static_cast<double>(g.vert(top[0], k).x()));
  }
  const double cell0 = hi - lo;
  if (!(cell0 > 0) || !std::isfinite(cell0)) return false;
  const double span = std::max(xmax - x0, ymax - y0);
  const double cells = std::round(span / cell0);
  g.x0 = x0;
  g.y0 = y0;
  g.zmin_top = zmin;
  g.cell = cells >= 1 ? span / cells : cell0;
  return true;
}

bool HeightField::place_top(const std::vector<std::uint32_t>& top, const Lattice& g) {
  int imax = 0, jmax = 0;
  for (std::uint32_t t : top) {
    for (int k = 0; k < 3; ++k) {
      int i = 0, j = 0;
      if (!g.grid_of(t, k, i, j)) return false;
      imax = std::max(imax, i);
      jmax = std::max(jmax, j);
    }
  }
  if (imax < 1 || jmax < 1 || static_cast<double>(imax) * jmax > 5e7) return false;
  x0_ = g.x0;
  y0_ = g.y0;
  cell_ = g.cell;
  inv_cell_ = 1.0 / g.cell;
  qx_ = imax;
  qy_ = jmax;
  const std::size_t nq = static_cast<std::size_t>(imax) * jmax;
  quads_.assign(nq, Quad{});
  zmax_.assign(nq, -std::numeric_limits<float>::infinity());
  tri_box_.assign(2 * nq, Eigen::AlignedBox3f());
  std::vector<std::uint8_t> mask(2 * nq, 0);
  for (std::uint32_t t : top) {
    int i[3] = {0, 0, 0}, j[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) g.grid_of(t, k, i[k], j[k]);
    const int il = std::min({i[0], i[1], i[2]}), jl = std::min({j[0], j[1], j[2]});
    if (std::max({i[0], i[1], i[2]}) != il + 1 || std::max({j[0], j[1], j[2]}) != jl + 1) return false;
    unsigned m = 0;
    for (int k = 0; k < 3; ++k) m |= 1U << static_cast<unsigned>((i[k] - il) + 2 * (j[k] - jl));
    if (std::popcount(m) != 3) return false;
    const std::size_t q = static_cast<std::size_t>(jl) * imax + il;
    Quad& quad = quads_[q];
    const int slot = quad.tri[0] == kNone ? 0 : quad.tri[1] == kNone ? 1 : -1;
    if (slot < 0) return false;
    const std::size_t at = 2 * q + static_cast<std::size_t>(slot);
    quad.tri[slot] = t;
    mask[at] = static_cast<std::uint8_t>(m);
    for (int k = 0; k < 3; ++k) tri_box_[at].extend(g.vert(t, k));
    zmax_[q] = std::max(zmax_[q], tri_box_[at].max().z());
  }
  // Every quad holds none or two triangles that tile it along a diagonal.
  for (std::size_t q = 0; q < nq; ++q) {
    if (quads_[q].tri[0] == kNone) continue;
    if (quads_[q].tri[1] == kNone) return false;
    const unsigned a = mask[2 * q], b = mask[2 * q + 1];
    const unsigned shared = a & b;
    if ((a | b) != 0b1111U || (shared != kDiagonal03 && shared != kDiagonal12)) return false;
  }
  return true;
}

bool HeightField::place_walls(const std::vector<std::uint32_t>& wall, const Lattice& g) {
  // Vertical strips over one grid edge, listed under the two quad slots
  // beside it.
  const std::size_t nq = quads_.size();
  std::vector<std::uint32_t> count(nq + 1, 0);
  auto slot_of = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < qx_ && j < qy_ ? static_cast<std::uint32_t>(j * qx_ + i) : kNone;
  };
  for (std::uint32_t t : wall) {
    int pi[2] = {0, 0}, pj[2] = {0, 0}, points = 0;
    for (int k = 0; k < 3; ++k) {
      int i = 0, j = 0;
      if (!g.grid_of(t, k, i, j)) return false;
      bool seen = false;
      for (int p = 0; p < points; ++p) seen = seen || (pi[p] == i && pj[p] == j);
      if (seen) continue;
      if (points == 2) return false;
      pi[points] = i;
      pj[points] = j;
      ++points;
    }
    if (points != 2 || std::abs(pi[0] - pi[1]) + std::abs(pj[0] - pj[1]) != 1) return false;
    const int il = std::min(pi[0], pi[1]), jl = std::min(pj[0], pj[1]);
    // An edge along x (row jl) has quads (il, jl-1) and (il, jl) beside it;
    // an edge along y (column il), (il-1, jl) and (il, jl).
    const bool along_x = pj[0] == pj[1];
    Wall w{t, {slot_of(along_x ? il : il - 1, along_x ? jl - 1 : jl), slot_of(il, jl)}, Eigen::AlignedBox3f()};
    if (w.slot[0] == kNone) std::swap(w.slot[0], w.slot[1]);
    if (w.slot[0] == kNone) return false;
    for (int k = 0; k < 3; ++k) w.box.extend(g.vert(t, k));
    for (std::uint32_t s : w.slot) {
      if (s == kNone) continue;
      ++count[s + 1];
      zmax_[s] = std::max(zmax_[s], w.box.max().z());
    }
    walls_.push_back(w);
  }
  for (std::size_t q = 0; q < nq; ++q) count[q + 1] += count[q];
  wall_start_ = count;
  wall_items_.resize(count.back());
  for (std::uint32_t w = 0; w < walls_.size(); ++w) {
    for (std::uint32_t s : walls_[w].slot) {
      if (s != kNone) wall_items_[count[s]++] = w;
    }
  }
  return true;
}

void HeightField::build_blocks() {
  bx_ = (qx_ + kBlock - 1) / kBlock;
  by_ = (qy_ + kBlock - 1) / kBlock;
  block_zmax_.assign(static_cast<std::size_t>(bx_) * by_, -std::numeric_limits<float>::infinity());
  for (int j = 0; j < qy_; ++j) {
    for (int i = 0; i < qx_; ++i) {
      float& b = block_zmax_[static_cast<std::size_t>(j / kBlock) * bx_ + i / kBlock];
      b = std::max(b, zmax_[static_cast<std::size_t>(j) * qx_ + i]);
    }
  }
}

void HeightField::triangles_overlapping(const Eigen::AlignedBox3d& box, std::vector<std::uint32_t>& out) const {
  // Outside the grid (a wall on its outer edge is listed under the quad inside).
  const double xe = x0_ + qx_ * cell_, ye = y0_ + qy_ * cell_;
  if (!(box.max().x() >= x0_ && box.min().x() <= xe && box.max().y() >= y0_ && box.min().y() <= ye)) return;
  // Truncation is the floor here: everything below 0 is clamped to 0.
  auto index = [this](double v, double origin, int n) {
    return static_cast<int>(std::clamp((v - origin) * inv_cell_, 0.0, n - 1.0));
  };
  const int i0 = index(box.min().x(), x0_, qx_), i1 = index(box.max().x(), x0_, qx_);
  const int j0 = index(box.min().y(), y0_, qy_), j1 = index(box.max().y(), y0_, qy_);
  const Eigen::AlignedBox3f fb = box.cast<float>();
  auto in_range = [&](std::uint32_t slot) {
    const int i = static_cast<int>(slot % static_cast<std::uint32_t>(qx_)), j = static_cast<int>(slot / qx_);
    return i >= i0 && i <= i1 && j >= j0 && j <= j1;
  };
  const float zlow = fb.min().z();
  for (int bj = j0 / kBlock; bj <= j1 / kBlock; ++bj) {
    for (int bi = i0 / kBlock; bi <= i1 / kBlock; ++bi) {
      if (block_zmax_[static_cast<std::size_t>(bj) * bx_ + bi] < zlow) continue;
      const int ja = std::max(j0, bj * kBlock), jb = std::min(j1, bj * kBlock + kBlock - 1);
      const int ia = std::max(i0, bi * kBlock), ib = std::min(i1, bi * kBlock + kBlock - 1);
      for (int j = ja; j <= jb; ++j) {
        for (int i = ia; i <= ib; ++i) {
          const std::size_t q = static_cast<std::size_t>(j) * qx_ + i;
          if (zmax_[q] < zlow) continue;
          const Quad& quad = quads_[q];
          for (std::size_t k = 0; k < 2; ++k) {
            if (quad.tri[k] != kNone && tri_box_[2 * q + k].intersects(fb)) out.push_back(quad.tri[k]);
          }
          for (std::uint32_t s = wall_start_[q]; s < wall_start_[q + 1]; ++s) {
            const Wall& w = walls_[wall_items_[s]];
            // Listed under both slots beside it: reported from the first in range.
            if (w.box.intersects(fb) && (w.slot[0] == q || !in_range(w.slot[0]))) out.push_back(w.triangle);
          }
        }
      }
    }
  }
}

}  // namespace touchdown::twin
