#include "touchdown/twin/height_field.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

namespace touchdown::twin {
namespace {

// Corner c = di + 2·dj of a quad; the two diagonals as corner masks.
constexpr unsigned kDiagonal03 = 0b1001, kDiagonal12 = 0b0110;

}  // namespace

std::shared_ptr<const HeightField> HeightField::detect(const TriangleMesh& mesh,
                                                       const std::vector<Eigen::Vector3d>& normals) {
  const auto& V = mesh.vertices;
  const auto& T = mesh.triangles;
  std::vector<std::uint32_t> top, wall, bottom;
  for (std::size_t t = 0; t < T.size(); ++t) {
    const double nz = normals[t].z();
    (nz > 1e-9 ? top : nz < -1e-9 ? bottom : wall).push_back(static_cast<std::uint32_t>(t));
  }
  if (top.empty()) return nullptr;
  auto vert = [&](std::uint32_t t, int k) -> const Eigen::Vector3f& { return V[T[t][static_cast<std::size_t>(k)]]; };
  // The grid: its spacing from the first top triangle, its origin at the
  // lowest top vertex in x and in y.
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, zmin_top = x0;
  for (std::uint32_t t : top) {
    for (int k = 0; k < 3; ++k) {
      x0 = std::min(x0, static_cast<double>(vert(t, k).x()));
      y0 = std::min(y0, static_cast<double>(vert(t, k).y()));
      zmin_top = std::min(zmin_top, static_cast<double>(vert(t, k).z()));
    }
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (int k = 0; k < 3; ++k) {
    lo = std::min(lo, static_cast<double>(vert(top[0], k).x()));
    hi = std::max(hi, static_cast<double>(vert(top[0], k).x()));
  }
  // Refined over the whole extent (one triangle's float width is off by
  // up to an ulp, which 300 cells multiply past the tolerance below).
  double xmax = -std::numeric_limits<double>::infinity(), ymax = xmax;
  for (std::uint32_t t : top) {
    for (int k = 0; k < 3; ++k) {
      xmax = std::max(xmax, static_cast<double>(vert(t, k).x()));
      ymax = std::max(ymax, static_cast<double>(vert(t, k).y()));
    }
  }
  const double cell0 = hi - lo;
  if (!(cell0 > 0) || !std::isfinite(cell0)) return nullptr;
  const double span = std::max(xmax - x0, ymax - y0);
  const double cells = std::round(span / cell0);
  const double cell = cells >= 1 ? span / cells : cell0;
  // Float vertices: within a thousandth of a cell of a grid line.
  const double tol = 1e-3;
  auto on_grid = [&](double v, double origin, int& index) {
    const double q = (v - origin) / cell;
    if (!(q > -0.5 && q < 1e8)) return false;
    index = static_cast<int>(std::lround(q));
    return std::abs(q - index) <= tol;
  };
  auto grid_of = [&](std::uint32_t t, int k, int& i, int& j) {
    return on_grid(vert(t, k).x(), x0, i) && on_grid(vert(t, k).y(), y0, j);
  };

  auto hf = std::shared_ptr<HeightField>(new HeightField());
  int imax = 0, jmax = 0;
  for (std::uint32_t t : top) {
    for (int k = 0; k < 3; ++k) {
      int i = 0, j = 0;
      if (!grid_of(t, k, i, j)) return nullptr;
      imax = std::max(imax, i);
      jmax = std::max(jmax, j);
    }
  }
  if (imax < 1 || jmax < 1 || static_cast<double>(imax) * jmax > 5e7) return nullptr;
  hf->x0_ = x0;
  hf->y0_ = y0;
  hf->cell_ = cell;
  hf->inv_cell_ = 1.0 / cell;
  hf->qx_ = imax;
  hf->qy_ = jmax;
  const std::size_t nq = static_cast<std::size_t>(imax) * jmax;
  hf->quads_.assign(nq, Quad{});
  hf->zmax_.assign(nq, -std::numeric_limits<float>::infinity());
  hf->tri_box_.assign(2 * nq, Eigen::AlignedBox3f());
  std::vector<std::uint8_t> mask(2 * nq, 0);
  for (std::uint32_t t : top) {
    int i[3] = {0, 0, 0}, j[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k) grid_of(t, k, i[k], j[k]);
    const int il = std::min({i[0], i[1], i[2]}), jl = std::min({j[0], j[1], j[2]});
    if (std::max({i[0], i[1], i[2]}) != il + 1 || std::max({j[0], j[1], j[2]}) != jl + 1) return nullptr;
    unsigned m = 0;
    for (int k = 0; k < 3; ++k) m |= 1U << static_cast<unsigned>((i[k] - il) + 2 * (j[k] - jl));
    if (std::popcount(m) != 3) return nullptr;
    const std::size_t q = static_cast<std::size_t>(jl) * imax + il;
    Quad& quad = hf->quads_[q];
    const int slot = quad.tri[0] == kNone ? 0 : quad.tri[1] == kNone ? 1 : -1;
    if (slot < 0) return nullptr;
    quad.tri[slot] = t;
    mask[2 * q + static_cast<std::size_t>(slot)] = static_cast<std::uint8_t>(m);
    Eigen::AlignedBox3f& box = hf->tri_box_[2 * q + static_cast<std::size_t>(slot)];
    for (int k = 0; k < 3; ++k) box.extend(vert(t, k));
    hf->zmax_[q] = std::max(hf->zmax_[q], box.max().z());
  }
  // Every quad holds none or two triangles that tile it along a diagonal.
  for (std::size_t q = 0; q < nq; ++q) {
    const Quad& quad = hf->quads_[q];
    if (quad.tri[0] == kNone) continue;
    if (quad.tri[1] == kNone) return nullptr;
    const unsigned a = mask[2 * q], b = mask[2 * q + 1];
    const unsigned shared = a & b;
    if ((a | b) != 0b1111U || (shared != kDiagonal03 && shared != kDiagonal12)) return nullptr;
  }
  // Walls: vertical strips over one grid edge, listed under the two quad
  // slots beside it.
  std::vector<std::uint32_t> count(nq + 1, 0);
  for (std::uint32_t t : wall) {
    int pi[2] = {0, 0}, pj[2] = {0, 0}, points = 0;
    for (int k = 0; k < 3; ++k) {
      int i = 0, j = 0;
      if (!grid_of(t, k, i, j)) return nullptr;
      bool seen = false;
      for (int p = 0; p < points; ++p) seen = seen || (pi[p] == i && pj[p] == j);
      if (seen) continue;
      if (points == 2) return nullptr;
      pi[points] = i;
      pj[points] = j;
      ++points;
    }
    if (points != 2 || std::abs(pi[0] - pi[1]) + std::abs(pj[0] - pj[1]) != 1) return nullptr;
    const int il = std::min(pi[0], pi[1]), jl = std::min(pj[0], pj[1]);
    // An edge along x (row jl) has quads (il, jl-1) and (il, jl) beside it;
    // an edge along y (column il), (il-1, jl) and (il, jl).
    const bool along_x = pj[0] == pj[1];
    const int ai = along_x ? il : il - 1, aj = along_x ? jl - 1 : jl;
    auto slot_of = [&](int i, int j) {
      return i >= 0 && j >= 0 && i < imax && j < jmax ? static_cast<std::uint32_t>(j * imax + i) : kNone;
    };
    Wall w{t, {slot_of(ai, aj), slot_of(il, jl)}, Eigen::AlignedBox3f()};
    if (w.slot[0] == kNone) std::swap(w.slot[0], w.slot[1]);
    if (w.slot[0] == kNone) return nullptr;
    for (int k = 0; k < 3; ++k) w.box.extend(vert(t, k));
    for (std::uint32_t s : w.slot) {
      if (s == kNone) continue;
      ++count[s + 1];
      hf->zmax_[s] = std::max(hf->zmax_[s], w.box.max().z());
    }
    hf->walls_.push_back(w);
  }
  // The bottom lies under the whole top surface.
  for (std::uint32_t t : bottom) {
    for (int k = 0; k < 3; ++k) {
      if (vert(t, k).z() > zmin_top) return nullptr;
    }
  }
  hf->bx_ = (imax + kBlock - 1) / kBlock;
  hf->by_ = (jmax + kBlock - 1) / kBlock;
  hf->block_zmax_.assign(static_cast<std::size_t>(hf->bx_) * hf->by_, -std::numeric_limits<float>::infinity());
  for (int j = 0; j < jmax; ++j) {
    for (int i = 0; i < imax; ++i) {
      float& b = hf->block_zmax_[static_cast<std::size_t>(j / kBlock) * hf->bx_ + i / kBlock];
      b = std::max(b, hf->zmax_[static_cast<std::size_t>(j) * imax + i]);
    }
  }
  for (std::size_t q = 0; q < nq; ++q) count[q + 1] += count[q];
  hf->wall_start_ = count;
  hf->wall_items_.resize(count.back());
  for (std::uint32_t w = 0; w < hf->walls_.size(); ++w) {
    for (std::uint32_t s : hf->walls_[w].slot) {
      if (s != kNone) hf->wall_items_[count[s]++] = w;
    }
  }
  return hf;
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
