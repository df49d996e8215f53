// Unobserved terrain is an answer, not an error (issue 11, item 8): regions
// the camera never saw are kept as `unknown` cells, and a landing whose feet,
// arms, propellers or body would be over them is unsafe for that reason.
// Tested on hand-made height maps (exact answers) and on PCL's real stereo
// scan of a table with a mug, which has both kinds of unobserved region: the
// mug's inside and the occlusion shadow behind it.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "../test_util.hpp"
#include "sweep_golden.hpp"
#include "touchdown/core/cloud_io.hpp"
#include "touchdown/terrain/filters.hpp"
#include "touchdown/terrain/height_map.hpp"
#include "touchdown/terrain/terrain_mesher.hpp"
#include "touchdown/twin/sweep.hpp"
#include "touchdown/twin/sweep_plot.hpp"

namespace td = touchdown;
namespace tt = touchdown::terrain;
namespace tw = touchdown::twin;

namespace {

tw::SweepOptions quick(int headings, int runs) {
  tw::SweepOptions o;
  o.headings = headings;
  o.runs = runs;
  o.threads = 2;
  return o;
}

// A 3 x 3 m flat map at z = 0 (2 cm cells) with a square of `hole` cells of
// side 2·half_hole m at (hx, hy) left empty, then holes filled/marked as the
// terrain stage does.
tt::HeightMap flat_with_hole(double hx, double hy, double half_hole, tt::UnknownFill fill) {
  const double cell = 0.02;
  tt::HeightMap m(-1.5, -1.5, cell, 150, 150);
  for (int j = 0; j < m.ny(); ++j) {
    for (int i = 0; i < m.nx(); ++i) {
      const bool in_hole = std::abs(m.centre_x(i) - hx) < half_hole && std::abs(m.centre_y(j) - hy) < half_hole;
      // A 10 cm rim around the hole, as the top of an object.
      const bool rim =
          !in_hole && std::abs(m.centre_x(i) - hx) < half_hole + 0.1 && std::abs(m.centre_y(j) - hy) < half_hole + 0.1;
      if (!in_hole) m.set(i, j, rim ? 0.3f : 0.0f, tt::CellState::Measured);
    }
  }
  // Gaps up to one cell are interpolated: none here, so the hole stays whole.
  tt::fill_holes(m, 0.02, 1.0);
  tt::fill_unknown(m, fill, 1.0);
  return m;
}

std::shared_ptr<const tw::TerrainModel> model_of(const tt::HeightMap& m) {
  return std::make_shared<const tw::TerrainModel>(tt::triangulate_solid(m, 0.1), tw::UnknownCells::of(m));
}

}  // namespace

TEST(UnknownCells, EnclosedEmptyRegionsAreMarkedAndFilledPessimistically) {
  for (const auto fill : {tt::UnknownFill::Block, tt::UnknownFill::Pit}) {
    const auto m = flat_with_hole(0.5, 0.5, 0.2, fill);
    // The 40 x 40 cm hole is wider than max_hole: all of its 20 x 20 cells
    // are unknown, at the rim's top (0.3 m) or 1 m below its lowest cell
    // (also 0.3 m: the rim is the object's top).
    EXPECT_EQ(m.count(tt::CellState::Unknown), 400u);
    EXPECT_EQ(m.count(tt::CellState::Empty), 0u);
    const int i = static_cast<int>((0.5 + 1.5) / 0.02), j = i;
    ASSERT_EQ(m.state(i, j), tt::CellState::Unknown);
    EXPECT_FLOAT_EQ(m.height(i, j), fill == tt::UnknownFill::Block ? 0.3f : -0.7f);
  }
  // A region that reaches the grid border is outside the scan, not unknown.
  tt::HeightMap m(0, 0, 0.02, 50, 50);
  for (int j = 0; j < 50; ++j)
    for (int i = 0; i < 30; ++i) m.set(i, j, 0.0f, tt::CellState::Measured);
  const auto rep = tt::fill_unknown(m, tt::UnknownFill::Block, 1.0);
  EXPECT_EQ(rep.regions, 0u);
  EXPECT_EQ(m.count(tt::CellState::Unknown), 0u);
}

TEST(UnknownCells, FootprintQueriesMatchHandComputedGeometry) {
  // Unknown square [0.3, 0.7]^2 (plus the conservative half-diagonal of a 2 cm cell).
  const auto terrain = model_of(flat_with_hole(0.5, 0.5, 0.2, tt::UnknownFill::Block));
  const double slack = 0.01 * std::sqrt(2.0);
  // A disk at the origin of radius r reaches the square's corner at
  // distance 0.3·√2 = 0.424 m (cell centres are 1 cm inside it).
  const double corner = std::hypot(0.31, 0.31);
  EXPECT_FALSE(terrain->unknown_near({0, 0}, {0, 0}, corner - slack - 0.005));
  EXPECT_TRUE(terrain->unknown_near({0, 0}, {0, 0}, corner - slack + 0.005));
  // A capsule along y = 0.2 passes 0.11 m below the lowest cell centres.
  EXPECT_FALSE(terrain->unknown_near({-1, 0.2}, {1, 0.2}, 0.11 - slack - 0.005));
  EXPECT_TRUE(terrain->unknown_near({-1, 0.2}, {1, 0.2}, 0.11 - slack + 0.005));
  // A 0.2 x 0.2 box centred at (0, 0.5): its edge x = 0.1 is 0.21 m from the
  // nearest centre; turned by 45° it reaches 0.1·√2 = 0.141 m.
  EXPECT_FALSE(terrain->unknown_in_box({0, 0.5}, {0.1, 0.1}, 0.0, 0.21 - slack - 0.005));
  EXPECT_TRUE(terrain->unknown_in_box({0, 0.5}, {0.1, 0.1}, 0.0, 0.21 - slack + 0.005));
  const double diag = 0.1 * std::sqrt(2.0);
  EXPECT_FALSE(terrain->unknown_in_box({0, 0.5}, {0.1, 0.1}, M_PI / 4, 0.31 - diag - slack - 0.005));
  EXPECT_TRUE(terrain->unknown_in_box({0, 0.5}, {0.1, 0.1}, M_PI / 4, 0.31 - diag - slack + 0.005));
}

TEST(UnknownTerrain, HeadingsOverUnobservedTerrainAreUnsafeWithThatReason) {
  // F450: props reach 0.225 + 0.127 = 0.352 m from the centre along the
  // diagonals (45°, 135°, ...). The unknown square starts 0.45 m east of the
  // landing point: at heading 0 a prop centre sits at (0.159, 0.159), its
  // disk reaches x = 0.286, short of 0.45; so every heading is clear.
  auto o = quick(4, 1);
  const auto clear =
      tw::run_sweep(tw::Airframe::f450(), model_of(flat_with_hole(0.75, 0, 0.3, tt::UnknownFill::Block)), o);
  ASSERT_TRUE(clear.ok()) << clear.message;
  td::test::check_golden("unknown_test_hole_clear", clear);
  EXPECT_TRUE(clear.safe);
  for (const auto& h : clear.headings) EXPECT_FALSE(h.unobserved);
  // Now the unknown square starts 0.25 m east: a prop disk overlaps it at
  // every heading (the twin spans 0.352 m in its diagonal directions and
  // ≥ 0.25 m in every direction between them).
  const auto over =
      tw::run_sweep(tw::Airframe::f450(), model_of(flat_with_hole(0.55, 0, 0.3, tt::UnknownFill::Block)), o);
  ASSERT_TRUE(over.ok()) << over.message;
  td::test::check_golden("unknown_test_hole_over", over);
  EXPECT_FALSE(over.safe);
  for (const auto& h : over.headings) {
    EXPECT_TRUE(h.unobserved) << h.yaw;
    EXPECT_EQ(h.reason, tw::UnsafeReason::UnobservedTerrain);
    EXPECT_FALSE(h.safe);
  }
  EXPECT_NE(tw::unsafe_summary(over).find("4 headings: unobserved terrain"), std::string::npos)
      << tw::unsafe_summary(over);
}

TEST(UnknownTerrain, OffTheScanIsStillAnErrorSayingByHowMuch) {
  // The 3 x 3 m map spans [-1.5, 1.5] (cell centres to ±1.49): a landing
  // point at x = 1.3 puts the 0.352 m footprint 0.162 m past the last centre.
  auto o = quick(2, 1);
  o.landing_point = {1.3, 0.0};
  const auto r = tw::run_sweep(tw::Airframe::f450(), model_of(flat_with_hole(-0.5, 0, 0.2, tt::UnknownFill::Block)), o);
  ASSERT_EQ(r.status, tw::SweepStatus::FootprintNotCovered);
  const auto at = r.message.find("sticks out of the scanned area by ");
  ASSERT_NE(at, std::string::npos) << r.message;
  EXPECT_NEAR(std::stod(r.message.substr(at + 34)), 1.3 + 0.352 - 1.49, 0.01) << r.message;
  EXPECT_NE(r.message.find("x in [-1.490, 1.490]"), std::string::npos) << r.message;
}

// The overhang is how far the footprint reaches beyond the scan, whether the
// landing point is on it or not (issue 31, item 5: it printed the footprint
// radius for every point off the scan). Oracle: the 3 x 3 m map's top
// surface is the rectangle [-1.49, 1.49]^2 (cell centres); a disk of radius r
// at c reaches dist(c, rectangle) + r beyond it when c is outside, and
// c.x + r - 1.49 when c is inside near the east edge.
TEST(UnknownTerrain, OffTheScanMessageSaysTheRealOverhangAndDistance) {
  const auto terrain = model_of(flat_with_hole(-0.5, 0, 0.2, tt::UnknownFill::Block));
  const double r = tw::Airframe::f450().footprint_radius();
  const double edge = 1.49;
  auto rectangle_distance = [&](const Eigen::Vector2d& c) {
    return Eigen::Vector2d(std::max(0.0, std::abs(c.x()) - edge), std::max(0.0, std::abs(c.y()) - edge)).norm();
  };
  auto number_after = [](const std::string& m, const std::string& key) {
    const auto at = m.find(key);
    EXPECT_NE(at, std::string::npos) << key << " in " << m;
    return at == std::string::npos ? -1.0 : std::stod(m.substr(at + key.size()));
  };
  std::vector<double> seen;
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(1.3, 0), Eigen::Vector2d(1.6, 0), Eigen::Vector2d(2, 0),
                                   Eigen::Vector2d(5, 0), Eigen::Vector2d(5, 5), Eigen::Vector2d(-3, 0.5)}) {
    auto o = quick(1, 1);
    o.landing_point = c;
    const auto res = tw::run_sweep(tw::Airframe::f450(), terrain, o);
    ASSERT_EQ(res.status, tw::SweepStatus::FootprintNotCovered) << c.transpose();
    const double off = rectangle_distance(c);
    const double expected = off > 0 ? off + r : c.x() + r - edge;
    const double overhang = number_after(res.message, "sticks out of the scanned area by ");
    EXPECT_NEAR(overhang, expected, 0.01) << res.message;
    seen.push_back(overhang);
    if (off > 0) {
      EXPECT_NEAR(number_after(res.message, "the landing point itself is "), off, 0.002) << res.message;
    } else {
      EXPECT_EQ(res.message.find("the landing point itself"), std::string::npos) << res.message;
    }
  }
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()) << "the overhangs must differ";
}

// ---- PCL's real stereo scan of a table with a mug --------------------------

namespace {

struct TableScan {
  std::shared_ptr<const tw::TerrainModel> terrain;
  tt::HeightMap map;
  Eigen::Vector2d mug = Eigen::Vector2d::Zero();     // centre of the mug's rim
  Eigen::Vector2d shadow = Eigen::Vector2d::Zero();  // centroid of the occlusion shadow
  Eigen::Vector2d bare = Eigen::Vector2d::Zero();    // a point on the bare table
};

// The table plane by RANSAC (fixed seed, 5 mm inlier band) refined by least
// squares on its inliers: n·p + d = 0 with the camera (origin) above it.
Eigen::Vector4d table_plane(const td::PointCloud& cloud) {
  std::vector<Eigen::Vector3d> pts;
  for (const auto& p : cloud.points) {
    if (p.allFinite()) pts.push_back(p.cast<double>());
  }
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
  Eigen::Vector4d best = Eigen::Vector4d::Zero();
  std::size_t best_count = 0;
  for (int it = 0; it < 300; ++it) {
    const Eigen::Vector3d a = pts[pick(rng)], b = pts[pick(rng)], c = pts[pick(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    n.normalize();
    std::size_t count = 0;
    for (std::size_t k = 0; k < pts.size(); k += 7) count += std::abs(n.dot(pts[k] - a)) < 0.005;
    if (count > best_count) {
      best_count = count;
      best << n, -n.dot(a);
    }
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> in;
  for (const auto& p : pts) {
    if (std::abs(best.head<3>().dot(p) + best[3]) < 0.005) in.push_back(p);
  }
  for (const auto& p : in) mean += p;
  mean /= static_cast<double>(in.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : in) cov += (p - mean) * (p - mean).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  double d = -n.dot(mean);
  if (d < 0) {  // the camera at the origin is on the positive side
    n = -n;
    d = -d;
  }
  return {n.x(), n.y(), n.z(), d};
}

// Levelled (table plane → z = 0, its normal → +z) and scaled ×4, so the
// table is about 2 × 1.7 m and the mug about 0.5 m tall, as a landing site.
const TableScan& table_scan() {
  static const TableScan kScan = [] {
    td::PointCloud cloud = td::read_cloud(td::test::data_path("pcl/table_scene_mug_stereo_textured.pcd"));
    const Eigen::Vector4d plane = table_plane(cloud);
    const double scale = 4.0;
    for (auto& p : cloud.points) p *= static_cast<float>(scale);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond::FromTwoVectors(plane.head<3>(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0, 0, scale * plane[3]);
    tt::TerrainOptions opt;
    opt.T_world_camera = T;
    auto result = tt::mesh_terrain(std::move(cloud), opt);
    EXPECT_TRUE(result.ok()) << result.message;
    TableScan s;
    s.map = result.height_map;
    s.terrain = std::make_shared<const tw::TerrainModel>(std::move(result.mesh), tw::UnknownCells::of(s.map));
    const auto& m = s.map;
    // The mug: measured cells 0.3–0.7 m above the table (its rim and sides).
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int count = 0;
    for (int j = 0; j < m.ny(); ++j)
      for (int i = 0; i < m.nx(); ++i)
        if (m.state(i, j) == tt::CellState::Measured && m.height(i, j) > 0.3 && m.height(i, j) < 0.7) {
          sum += Eigen::Vector2d(m.centre_x(i), m.centre_y(j));
          ++count;
        }
    EXPECT_GT(count, 50);
    s.mug = sum / std::max(count, 1);
    // The shadow: unknown cells more than 0.25 m from the mug's centre
    // (outside its inside) and within 1 m of it.
    sum.setZero();
    count = 0;
    for (int j = 0; j < m.ny(); ++j)
      for (int i = 0; i < m.nx(); ++i) {
        const Eigen::Vector2d c(m.centre_x(i), m.centre_y(j));
        const double d = (c - s.mug).norm();
        if (m.state(i, j) == tt::CellState::Unknown && d > 0.25 && d < 1.0) {
          sum += c;
          ++count;
        }
      }
    EXPECT_GT(count, 30);
    s.shadow = sum / std::max(count, 1);
    // Bare table: the point with the widest clearance from anything that
    // is not flat table (unknown, off the scan, or more than 4 cm from the
    // table plane: stereo noise ×4), on a 4 cm grid.
    double best = 0;
    for (double y = 1.9; y <= 3.9; y += 0.04) {
      for (double x = -1.0; x <= 1.4; x += 0.04) {
        double clear = 0.6;
        const int r = static_cast<int>(std::ceil(clear / m.cell()));
        const int ci = static_cast<int>(std::floor((x - m.x0()) / m.cell()));
        const int cj = static_cast<int>(std::floor((y - m.y0()) / m.cell()));
        for (int j = cj - r; j <= cj + r; ++j)
          for (int i = ci - r; i <= ci + r; ++i) {
            const bool flat = i >= 0 && j >= 0 && i < m.nx() && j < m.ny() &&
                              (m.state(i, j) == tt::CellState::Measured || m.state(i, j) == tt::CellState::Filled) &&
                              std::abs(m.height(i, j)) < 0.04;
            if (!flat) clear = std::min(clear, std::hypot(m.centre_x(i) - x, m.centre_y(j) - y));
          }
        if (clear > best) {
          best = clear;
          s.bare = {x, y};
        }
      }
    }
    // The F450 spans 0.352 m from its centre (along its diagonals).
    EXPECT_GT(best, 0.352) << "no bare table found";
    std::printf("table scan: mug (%.2f, %.2f), shadow (%.2f, %.2f), bare table (%.2f, %.2f)\n", s.mug.x(), s.mug.y(),
                s.shadow.x(), s.shadow.y(), s.bare.x(), s.bare.y());
    return s;
  }();
  return kScan;
}

}  // namespace

TEST(UnknownTerrainRealScan, TheMugsInsideAndShadowAreUnknownTheTableIsNot) {
  const auto& s = table_scan();
  // Both unobserved regions exist and the mug stands about 0.5 m tall.
  EXPECT_GT(s.map.count(tt::CellState::Unknown), 100u);
  const int i = static_cast<int>(std::floor((s.mug.x() - s.map.x0()) / s.map.cell()));
  const int j = static_cast<int>(std::floor((s.mug.y() - s.map.y0()) / s.map.cell()));
  EXPECT_EQ(s.map.state(i, j), tt::CellState::Unknown) << "the mug's inside";
  EXPECT_NEAR(s.map.height(i, j), 0.5, 0.15) << "filled as a block up to the rim";
  EXPECT_GT((s.shadow - s.mug).norm(), 0.25);
}

TEST(UnknownTerrainRealScan, BareTableSafeMugAndShadowUnsafeOffScanError) {
  const auto& s = table_scan();
  const auto af = tw::Airframe::f450();
  auto o = quick(8, 2);
  o.landing_point = s.bare;
  const auto bare = tw::run_sweep(af, s.terrain, o);
  ASSERT_TRUE(bare.ok()) << bare.message;
  td::test::check_golden("unknown_test_table_bare", bare);
  EXPECT_TRUE(bare.safe) << tw::unsafe_summary(bare);
  for (const auto& h : bare.headings) {
    EXPECT_TRUE(h.safe) << h.yaw << " " << tw::to_string(h.reason);
    EXPECT_LE(h.score, 0.05) << h.yaw;
  }
  for (const Eigen::Vector2d& p : {s.mug, s.shadow}) {
    o.landing_point = p;
    const auto r = tw::run_sweep(af, s.terrain, o);
    ASSERT_TRUE(r.ok()) << r.message;  // an answer, not an error
    td::test::check_golden(p == s.mug ? "unknown_test_table_mug" : "unknown_test_table_shadow", r);
    EXPECT_FALSE(r.safe);
    for (const auto& h : r.headings) EXPECT_EQ(h.reason, tw::UnsafeReason::UnobservedTerrain) << h.yaw;
    EXPECT_NE(tw::unsafe_summary(r).find("8 headings: unobserved terrain"), std::string::npos);
  }
  // Off the scan: 0.2 m past the mesh's east edge.
  o.landing_point = {s.terrain->bounds().max.x() + 0.2, s.bare.y()};
  const auto off = tw::run_sweep(af, s.terrain, o);
  EXPECT_EQ(off.status, tw::SweepStatus::FootprintNotCovered);
  EXPECT_NE(off.message.find("sticks out of the scanned area by"), std::string::npos) << off.message;
}

TEST(UnknownTerrainRealScan, SearchFindsTheNearestPointClearOfUnknownTerrain) {
  const auto& s = table_scan();
  auto o = quick(4, 1);
  // Ask for a point 0.2 m from the bare table towards the shadow: its
  // footprint overlaps the shadow.
  o.landing_point = s.bare - Eigen::Vector2d(0.2, 0.0);
  const auto r = tw::search_landing_point(tw::Airframe::f450(), s.terrain, o, 0.3, 0.1, tw::SearchPreference::Nearest);
  ASSERT_TRUE(r.ok()) << r.message;
  td::test::check_golden("unknown_test_table_search_nearest", r);
  ASSERT_FALSE(r.candidates.empty());
  EXPECT_FALSE(r.candidates[0].safe);  // the requested point itself
  EXPECT_TRUE(r.candidates[0].unobserved);
  ASSERT_GE(r.best, 0);
  const auto& best = r.candidates[static_cast<std::size_t>(r.best)];
  EXPECT_TRUE(best.safe);
  EXPECT_FALSE(best.unobserved);
  const double d = (best.xy - o.landing_point).norm();
  for (const auto& c : r.candidates) {
    const double dc = (c.xy - o.landing_point).norm();
    if (dc < d - 1e-9) {
      EXPECT_FALSE(c.safe) << "a nearer safe point: " << c.xy.transpose();
    }
    if (dc > d + 1e-9) {
      EXPECT_FALSE(c.evaluated) << "flown beyond the nearest safe ring";
    }
  }
  const auto& h = r.sweep.headings[static_cast<std::size_t>(r.sweep.best)];
  EXPECT_FALSE(h.unobserved);
  EXPECT_TRUE(h.safe);
  // The search's top view shows the unobserved cells and the chosen footprint.
  const std::string svg =
      tw::search_plot_svg(r, o.landing_point, 0.3, tw::Airframe::f450(), *s.terrain, {"table", "F450"});
  EXPECT_NE(svg.find("fill='url(#unk)'/>"), std::string::npos);
  EXPECT_NE(svg.find("Landing-point search"), std::string::npos);
  EXPECT_EQ(svg.find("nan"), std::string::npos);
  // Preferring the lowest S flies every candidate and may go farther, but
  // never to a point over unobserved terrain.
  const auto low = tw::search_landing_point(tw::Airframe::f450(), s.terrain, o, 0.3, 0.1);
  td::test::check_golden("unknown_test_table_search_lowest", low);
  ASSERT_GE(low.best, 0);
  const auto& lb = low.candidates[static_cast<std::size_t>(low.best)];
  EXPECT_TRUE(lb.safe);
  EXPECT_FALSE(lb.unobserved);
  EXPECT_LE(lb.score, best.score);
  for (const auto& c : low.candidates) {
    EXPECT_TRUE(c.evaluated);
    if (c.safe) {
      EXPECT_GE(c.score, lb.score);
    }
  }
}
