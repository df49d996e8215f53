// The renderer's passes 1–4 (render.cpp has the whole frame): the ground,
// the markers and distractors, the objects' sun shadows, and the objects.
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "scenario/render_impl.hpp"
#include "scenario/render_kernels.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::scenario {

using render_detail::Bgr;
using render_detail::clip_near;
using render_detail::clip_rect;
using render_detail::ground_row_avx2;
using render_detail::ground_row_scalar;
using render_detail::GroundRow;
using render_detail::has_avx2;
using render_detail::kGroundTexel;
using render_detail::kMaxGround;
using render_detail::kNear;
using render_detail::kPrefilterFootprints;
using render_detail::lerp_bgra;
using render_detail::Mesh;
using render_detail::mip_level;
using render_detail::Quad;
using render_detail::sat8;
using render_detail::shoelace;

// ---- 1. ground ----
void Renderer::Impl::ground_pass(Frame& fr) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  std::uint8_t* mask = fr.mask;
  float* depth = fr.depth;
  const View& v = fr.v;
  GroundRow g;
  g.texels = map->texels.get();
  g.offsets = map->offsets.data();
  g.levels = map->levels;
  g.inv_h = static_cast<float>(1 / v.h);
  g.w_min = static_cast<float>(1 / kMaxGround);
  g.cxw = static_cast<float>(v.c.x() + map_shift.x());
  g.cyw = static_cast<float>(v.c.y() + map_shift.y());
  g.lod = static_cast<float>(kPrefilterFootprints / (f * kGroundTexel));
  g.ax = static_cast<float>(v.A.x()), g.ay = static_cast<float>(v.A.y()), g.az = static_cast<float>(v.A.z());
  g.width = W;
  const bool avx2 = has_avx2();
  for (int y = 0; y < H; ++y) {
    const Eigen::Vector3d r0 = v.B * y + v.C;
    g.rx0 = static_cast<float>(r0.x()), g.ry0 = static_cast<float>(r0.y()), g.rz0 = static_cast<float>(r0.z());
    std::uint8_t* px = img.ptr<std::uint8_t>(y);
    std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    float* dp = depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    // The AVX2 kernel stores 16 bytes per 4 pixels: it leaves the last
    // pixels of the image to the scalar one (same arithmetic, same bits).
    const int done = avx2 ? ground_row_avx2(g, px, mk, dp, y + 1 < H ? W : W - 8) : 0;
    ground_row_scalar(g, done, W, px, mk, dp);
  }
}

template <class WorldPoint>
bool Renderer::Impl::ground_polygon_in_image(const Frame& fr, WorldPoint&& world_point, std::size_t count) {
  const int W = fr.width, H = fr.height;
  const View& v = fr.v;
  poly3.clear();
  for (std::size_t i = 0; i < count; ++i) poly3.push_back(v.cam(world_point(i)));
  clip_near(poly3, poly3_clip);
  poly2.clear();
  for (const auto& p : poly3_clip) poly2.push_back(project(p));
  if (poly2.size() >= 3) clip_rect(poly2, poly2_tmp, -0.5, -0.5, W - 0.5, H - 0.5);
  return poly2.size() >= 3;
}

// ---- 2. markers and distractors ----
cv::Rect Renderer::Impl::markers_pass(Frame& fr, CameraFrame& out) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  std::uint8_t* mask = fr.mask;
  float* depth = fr.depth;
  const View& v = fr.v;
  out.marker_area_truth_px = 0;
  out.marker_area_visible_px = 0;
  cv::Rect marker_box;
  for (const Quad& q : quads) {
    const auto corner = [&](std::size_t i) { return q.corners[i]; };
    if (!ground_polygon_in_image(fr, corner, 4)) continue;
    if (q.label == Label::Marker) out.marker_area_truth_px = shoelace(poly2);
    double x0 = W, x1 = -1, y0 = H, y1 = -1;
    for (const auto& p : poly2)
      x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
    const int bx0 = std::max(0, static_cast<int>(std::ceil(x0))),
              bx1 = std::min(W - 1, static_cast<int>(std::floor(x1)));
    const int by0 = std::max(0, static_cast<int>(std::ceil(y0))),
              by1 = std::min(H - 1, static_cast<int>(std::floor(y1)));
    if (q.label == Label::Marker)
      marker_box = cv::Rect(bx0, by0, std::max(0, bx1 - bx0 + 1), std::max(0, by1 - by0 + 1));
    const int levels = static_cast<int>(q.mips.size());
    const int m0 = q.mips.front().cols;
    const double texel0 = q.side / m0;
    const float lod = static_cast<float>(kPrefilterFootprints / (f * texel0));
    // World (X, Y) → marker image coordinates at level 0: a = ex·d/texel, b = −ey·d/texel.
    const float inv_t = static_cast<float>(1 / texel0);
    const float ecx = static_cast<float>(q.cos_yaw), esy = static_cast<float>(q.sin_yaw);
    const float half = 0.5f * static_cast<float>(m0);
    const float dx0 = static_cast<float>(v.c.x() - q.centre.x()), dy0 = static_cast<float>(v.c.y() - q.centre.y());
    const float ax = static_cast<float>(v.A.x()), ay = static_cast<float>(v.A.y());
    for (int y = by0; y <= by1; ++y) {
      const Eigen::Vector3d r0 = v.B * y + v.C;
      const float rx0 = static_cast<float>(r0.x()), ry0 = static_cast<float>(r0.y());
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      const float* dp = depth + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      for (int x = bx0; x <= bx1; ++x) {
        if (mk[x] == mask_value(Label::Sky)) continue;
        const float x_f = static_cast<float>(x);
        const float s = dp[x];  // the ground pass's depth: the same ray meets the same plane
        const float dX = dx0 + s * (rx0 + ax * x_f), dY = dy0 + s * (ry0 + ay * x_f);
        const float a = (dX * ecx + dY * esy) * inv_t + half;   // along image columns
        const float b = half - (-dX * esy + dY * ecx) * inv_t;  // along image rows
        if (!(a >= 0 && a < static_cast<float>(m0) && b >= 0 && b < static_cast<float>(m0))) continue;
        const int k = mip_level(s * lod, levels);
        const cv::Mat& mip = q.mips[static_cast<std::size_t>(k)];
        const float scale = q.level_scale[static_cast<std::size_t>(k)];
        const float u = std::clamp(a * scale - 0.5f, 0.0f, static_cast<float>(mip.cols - 1));
        const float vv = std::clamp(b * scale - 0.5f, 0.0f, static_cast<float>(mip.rows - 1));
        const int ui = static_cast<int>(u), vi = static_cast<int>(vv);
        const int u1 = std::min(ui + 1, mip.cols - 1), v1 = std::min(vi + 1, mip.rows - 1);
        const auto tu = static_cast<std::uint32_t>((u - static_cast<float>(ui)) * 256.0f);
        const auto tv = static_cast<std::uint32_t>((vv - static_cast<float>(vi)) * 256.0f);
        const auto* r0p = mip.ptr<std::uint32_t>(vi);
        const auto* r1p = mip.ptr<std::uint32_t>(v1);
        const std::uint32_t c = lerp_bgra(lerp_bgra(r0p[ui], r0p[u1], tu), lerp_bgra(r1p[ui], r1p[u1], tu), tv);
        px[3 * x] = static_cast<std::uint8_t>(c);
        px[3 * x + 1] = static_cast<std::uint8_t>(c >> 8);
        px[3 * x + 2] = static_cast<std::uint8_t>(c >> 16);
        mk[x] = mask_value(q.label);
      }
    }
  }
  return marker_box;
}

// ---- 3. sun shadows of the objects on the ground and markers ----
// (drawn into shadow_mask first: the wet glare needs the sun, too; nullopt
// when there are none)
std::optional<cv::Rect> Renderer::Impl::shadows_pass(Frame& fr, const SceneState& state) {
  const int W = fr.width, H = fr.height;
  if (shadow_keep < 256 && sun.z() > std::sin(deg_to_rad(3))) {
    if (shadow_mask.rows != H || shadow_mask.cols != W) shadow_mask = cv::Mat::zeros(H, W, CV_8U);
    int sx0 = W, sy0 = H, sx1 = -1, sy1 = -1;
    const auto draw_shadow = [&](const std::vector<cv::Point2f>& ground_hull) {
      if (ground_hull.size() < 3) return;
      const auto corner = [&](std::size_t i) { return Eigen::Vector3d(ground_hull[i].x, ground_hull[i].y, 0); };
      if (!ground_polygon_in_image(fr, corner, ground_hull.size())) return;
      ipoly.clear();
      for (const auto& p : poly2) {
        ipoly.emplace_back(static_cast<int>(std::lround(p.x() * 16)), static_cast<int>(std::lround(p.y() * 16)));
        sx0 = std::min(sx0, static_cast<int>(std::floor(p.x()))),
        sx1 = std::max(sx1, static_cast<int>(std::ceil(p.x())));
        sy0 = std::min(sy0, static_cast<int>(std::floor(p.y()))),
        sy1 = std::max(sy1, static_cast<int>(std::ceil(p.y())));
      }
      cv::fillConvexPoly(shadow_mask, ipoly, cv::Scalar(1), cv::LINE_8, 4);
    };
    for (const auto& hull_w : static_shadow) draw_shadow(hull_w);
    for (std::size_t i = 0; i < dynamic_meshes.size(); ++i) {
      const Eigen::Isometry3d& T = state.T_world_dynamic[i];
      for (const Mesh& mesh : dynamic_meshes[i]) {
        shadow_pts.clear();
        for (const auto& p_local : mesh.v) {
          const Eigen::Vector3d p = T * p_local;
          const Eigen::Vector3d g = p - (std::max(0.0, p.z()) / sun.z()) * sun;
          shadow_pts.emplace_back(static_cast<float>(g.x()), static_cast<float>(g.y()));
        }
        cv::convexHull(shadow_pts, hull);
        draw_shadow(hull);
      }
    }
    return cv::Rect(sx0, sy0, sx1 - sx0 + 1, sy1 - sy0 + 1);
  }
  return std::nullopt;
}

/// Darkens the ground, markers and distractors under the shadows in
/// shadow_mask (clearing it for the next frame).
void Renderer::Impl::apply_shadows(Frame& fr, const cv::Rect& shadow_box) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  std::uint8_t* mask = fr.mask;
  int sx0 = shadow_box.x, sy0 = shadow_box.y, sx1 = shadow_box.x + shadow_box.width - 1,
      sy1 = shadow_box.y + shadow_box.height - 1;
  sx0 = std::max(sx0, 0), sy0 = std::max(sy0, 0), sx1 = std::min(sx1, W - 1), sy1 = std::min(sy1, H - 1);
  const auto keep = static_cast<unsigned>(shadow_keep);
  for (int y = sy0; y <= sy1; ++y) {
    std::uint8_t* sm = shadow_mask.ptr<std::uint8_t>(y);
    std::uint8_t* px = img.ptr<std::uint8_t>(y);
    const std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    for (int x = sx0; x <= sx1; ++x) {
      if (!sm[x]) continue;
      sm[x] = 0;
      if (mk[x] > mask_value(Label::Distractor)) continue;  // ground, marker and distractors only
      for (int c = 0; c < 3; ++c) px[3 * x + c] = static_cast<std::uint8_t>((px[3 * x + c] * keep) >> 8);
    }
  }
}

// ---- 4. objects: near-plane clipping and a z-buffer ----
void Renderer::Impl::objects_pass(Frame& fr, const SceneState& state) {
  const int W = fr.width, H = fr.height;
  cv::Mat& img = fr.img;
  std::uint8_t* mask = fr.mask;
  float* depth = fr.depth;
  const View& v = fr.v;
  const auto raster = [&](const Eigen::Vector3d& qa, const Eigen::Vector3d& qb, const Eigen::Vector3d& qc,
                          const Bgr& col, std::uint8_t label) {
    // Screen position and 1/z, which is affine in screen space.
    Eigen::Vector3d a(f * qa.x() / qa.z() + cx, f * qa.y() / qa.z() + cy, 1 / qa.z());
    Eigen::Vector3d b(f * qb.x() / qb.z() + cx, f * qb.y() / qb.z() + cy, 1 / qb.z());
    Eigen::Vector3d c(f * qc.x() / qc.z() + cx, f * qc.y() / qc.z() + cy, 1 / qc.z());
    double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) return;
    if (area < 0) std::swap(b, c), area = -area;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(W - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(H - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    if (x0 > x1 || y0 > y1) return;
    // Edge function of P→Q at (x, y): (Q.x − P.x)(y − P.y) − (Q.y − P.y)(x − P.x).
    const auto edge = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    const double ea_dx = -(c.y() - b.y()), eb_dx = -(a.y() - c.y()), ec_dx = -(b.y() - a.y());
    const double inv_area = 1 / area;
    const double w_dx = (ea_dx * a.z() + eb_dx * b.z() + ec_dx * c.z()) * inv_area;
    for (int y = y0; y <= y1; ++y) {
      // The row's span inside all three edges (a pixel wider each side; the
      // test below decides), so thin triangles do not walk their whole box.
      double lo = x0, hi = x1;
      const auto bound = [&](double e0, double dx) {
        if (dx > 0) {
          lo = std::max(lo, x0 - e0 / dx);
        } else if (dx < 0) {
          hi = std::min(hi, x0 - e0 / dx);
        } else if (e0 < 0) {
          hi = -1;
        }
      };
      bound(edge(b, c, x0, y), ea_dx), bound(edge(c, a, x0, y), eb_dx), bound(edge(a, b, x0, y), ec_dx);
      if (!(lo <= hi + 2)) continue;
      const int xs = std::max(x0, static_cast<int>(std::floor(lo)) - 1);
      const int xe = std::min(x1, static_cast<int>(std::ceil(hi)) + 1);
      double ea = edge(b, c, xs, y), eb = edge(c, a, xs, y), ec = edge(a, b, xs, y);
      double wz = (ea * a.z() + eb * b.z() + ec * c.z()) * inv_area;
      std::uint8_t* px = img.ptr<std::uint8_t>(y);
      const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
      for (int x = xs; x <= xe; ++x, ea += ea_dx, eb += eb_dx, ec += ec_dx, wz += w_dx) {
        if (ea < 0 || eb < 0 || ec < 0 || !(wz > 0)) continue;
        const auto z = static_cast<float>(1 / wz);
        if (!(z < depth[row + static_cast<std::size_t>(x)])) continue;
        depth[row + static_cast<std::size_t>(x)] = z;
        mask[row + static_cast<std::size_t>(x)] = label;
        px[3 * x] = col[0], px[3 * x + 1] = col[1], px[3 * x + 2] = col[2];
      }
    }
  };
  const double tan_x = 0.5 * W / f, tan_y = 0.5 * H / f;
  const double norm_x = std::sqrt(1 + tan_x * tan_x), norm_y = std::sqrt(1 + tan_y * tan_y);
  const auto in_view = [&](const Eigen::Vector3d& centre_world, double r) {
    const Eigen::Vector3d q = v.cam(centre_world);
    if (q.z() < kNear - r) return false;
    if ((std::abs(q.x()) - tan_x * q.z()) / norm_x > r) return false;
    return (std::abs(q.y()) - tan_y * q.z()) / norm_y <= r;
  };
  const auto draw_mesh = [&](const Mesh& mesh, const Eigen::Isometry3d* T, const std::vector<Bgr>* shaded,
                             std::uint8_t label) {
    verts.resize(mesh.v.size());
    for (std::size_t i = 0; i < mesh.v.size(); ++i) verts[i] = T ? (*T) * mesh.v[i] : mesh.v[i];
    for (std::size_t t = 0; t < mesh.tri.size(); ++t) {
      const auto& tri = mesh.tri[t];
      const Eigen::Vector3d& p0 = verts[static_cast<std::size_t>(tri[0])];
      const Eigen::Vector3d& p1 = verts[static_cast<std::size_t>(tri[1])];
      const Eigen::Vector3d& p2 = verts[static_cast<std::size_t>(tri[2])];
      const Eigen::Vector3d n = (p1 - p0).cross(p2 - p0);
      if (n.dot(p0 - v.c) >= 0) continue;  // back face
      Bgr col;
      if (shaded) {
        col = (*shaded)[t];
      } else {
        const double lambert = 0.55 + 0.6 * sun_strength * std::max(0.0, n.normalized().dot(sun));
        const double k = lambert * mesh.tint[t];
        col = Bgr{sat8(mesh.bgr[0] * k), sat8(mesh.bgr[1] * k), sat8(mesh.bgr[2] * k)};
      }
      const Eigen::Vector3d q0 = v.cam(p0), q1 = v.cam(p1), q2 = v.cam(p2);
      const int inside = (q0.z() >= kNear) + (q1.z() >= kNear) + (q2.z() >= kNear);
      if (inside == 0) continue;
      if (inside == 3) {
        raster(q0, q1, q2, col, label);
        continue;
      }
      poly3.assign({q0, q1, q2});
      clip_near(poly3, poly3_clip);
      for (std::size_t k = 1; k + 1 < poly3_clip.size(); ++k)
        raster(poly3_clip[0], poly3_clip[k], poly3_clip[k + 1], col, label);
    }
  };
  for (std::size_t i = 0; i < static_meshes.size(); ++i) {
    if (in_view(static_meshes[i].centre, static_meshes[i].radius)) {
      draw_mesh(static_meshes[i], nullptr, &static_shade[i], mask_value(Label::StaticObject));
    }
  }
  for (std::size_t i = 0; i < dynamic_meshes.size(); ++i) {
    const Eigen::Isometry3d& T = state.T_world_dynamic[i];
    for (const Mesh& mesh : dynamic_meshes[i]) {
      if (in_view(T * mesh.centre, mesh.radius)) draw_mesh(mesh, &T, nullptr, mask_value(Label::DynamicObject));
    }
  }
}

/// The target's visible area: its label survives where nothing covers it.
void Renderer::Impl::count_visible_marker(Frame& fr, const cv::Rect& marker_box, CameraFrame& out) {
  const int W = fr.width;
  std::uint8_t* mask = fr.mask;
  for (int y = marker_box.y; y < marker_box.y + marker_box.height; ++y) {
    const std::uint8_t* mk = mask + static_cast<std::size_t>(y) * static_cast<std::size_t>(W);
    int count = 0;
    for (int x = marker_box.x; x < marker_box.x + marker_box.width; ++x) count += mk[x] == mask_value(Label::Marker);
    out.marker_area_visible_px += count;
  }
}

}  // namespace touchdown::scenario
