// The height-field contact (issue 57, item 3): detection of a grid mesh,
// its candidate query against the bucket grid's, and the landings it gives
// against the trimesh contact and the analytic answers.
#include "touchdown/twin/height_field.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "touchdown/core/units.hpp"
#include "touchdown/terrain/height_map.hpp"
#include "touchdown/twin/landing.hpp"
#include "touchdown/twin/threshold.hpp"
#include "twin/contacts.hpp"
#include "twin_test_util.hpp"

namespace tw = touchdown::twin;
namespace tt = touchdown::terrain;
using touchdown::kRadPerDeg;
using touchdown::TriangleMesh;
using touchdown::test::analytic_terrain;

namespace {

// A noisy grid with an empty corner and an empty hole (walls inside and
// along a ragged edge), as a depth camera's footprint leaves it.
tt::HeightMap ragged_map(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.003);
  tt::HeightMap m(-0.5, -0.4, 0.02, 50, 40);
  for (int j = 0; j < m.ny(); ++j) {
    for (int i = 0; i < m.nx(); ++i) {
      const bool corner = i + j < 8;
      const bool hole = std::abs(i - 30) < 3 && std::abs(j - 20) < 2;
      if (corner || hole) continue;
      const double z = 0.1 * m.centre_x(i) + (m.centre_y(j) > 0.1 ? 0.05 : 0.0) + noise(rng);
      m.set(i, j, static_cast<float>(z), tt::CellState::Measured);
    }
  }
  return m;
}

std::vector<Eigen::Vector3d> normals_of(const tw::TerrainModel& t) {
  std::vector<Eigen::Vector3d> n;
  for (std::uint32_t k = 0; k < t.mesh().triangles.size(); ++k) n.push_back(t.normal(k));
  return n;
}

tw::RunResult land(const std::shared_ptr<const tw::TerrainModel>& terrain, double heading, double ground_z,
                   tw::TerrainContact contact, const tw::Airframe& af = tw::Airframe::f450()) {
  tw::SimulationOptions opt;
  opt.tip_nutation = tw::compute_safety_threshold(af).tip_rad;
  opt.contact = contact;
  const tw::LandingSimulator sim(af, terrain, opt);
  tw::LandingConditions c;
  c.heading = heading;
  c.ground_z = ground_z;
  c.friction = 1.0;
  return sim.land(c);
}

constexpr auto kGrid = tw::TerrainContact::HeightField;
constexpr auto kMesh = tw::TerrainContact::Trimesh;

}  // namespace

TEST(HeightField, TheMesherSolidIsOneAndItsQueryIsTheBucketsWithoutTheBottom) {
  const tw::TerrainModel terrain(tt::triangulate_solid(ragged_map(3), 0.1));
  const tw::HeightField* hf = terrain.height_field();
  ASSERT_NE(hf, nullptr);
  EXPECT_NEAR(hf->cell(), 0.02, 1e-6);
  EXPECT_EQ(hf->quads_x(), 49);
  EXPECT_EQ(hf->quads_y(), 39);
  EXPECT_GT(hf->wall_count(), 0U);
  // Oracle: the bucket query of the same box, less the downward faces
  // (the solid's bottom), as a set; the grid lists each triangle once.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> x(-0.6, 0.6), y(-0.5, 0.5), z(-0.15, 0.15), size(0.0, 0.25);
  std::size_t nonempty = 0, walls_seen = 0;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d lo(x(rng), y(rng), z(rng));
    const Eigen::AlignedBox3d box(lo, lo + Eigen::Vector3d(size(rng), size(rng), size(rng)));
    std::vector<std::uint32_t> buckets, grid;
    terrain.triangles_overlapping(box, buckets);
    hf->triangles_overlapping(box, grid);
    std::set<std::uint32_t> want;
    for (std::uint32_t t : buckets) {
      if (terrain.normal(t).z() >= -1e-9) want.insert(t);
    }
    const std::set<std::uint32_t> got(grid.begin(), grid.end());
    ASSERT_EQ(got.size(), grid.size()) << "a triangle listed twice, box " << k;
    ASSERT_EQ(got, want) << "box " << k;
    nonempty += !got.empty();
    for (std::uint32_t t : got) walls_seen += std::abs(terrain.normal(t).z()) < 1e-9;
  }
  EXPECT_GT(nonempty, 500U);
  EXPECT_GT(walls_seen, 10U) << "the test must reach the walls";
}

TEST(HeightField, AMeshThatIsNotAGridIsNotOne) {
  const TriangleMesh solid = tt::triangulate_solid(ragged_map(4), 0.1);
  {  // a top vertex moved off its grid line
    TriangleMesh m = solid;
    m.vertices[m.triangles[0][1]].x() += 0.004f;
    const tw::TerrainModel t(m);
    EXPECT_EQ(t.height_field(), nullptr);
  }
  {  // a quad left with one triangle
    TriangleMesh m = solid;
    m.triangles.erase(m.triangles.begin());
    EXPECT_EQ(tw::HeightField::detect(m, normals_of(tw::TerrainModel(solid))), nullptr);
  }
  {  // an overhang: a downward face above the top surface
    TriangleMesh m = solid;
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.emplace_back(0.0f, 0.0f, 1.0f);
    m.vertices.emplace_back(0.0f, 0.1f, 1.0f);
    m.vertices.emplace_back(0.1f, 0.0f, 1.0f);
    m.triangles.push_back({base, base + 1, base + 2});  // normal -z
    const tw::TerrainModel t(m);
    EXPECT_EQ(t.height_field(), nullptr);
  }
}

TEST(HeightField, ASphereOnFlatGroundHasOneContactOfItsDepth) {
  const auto flat = touchdown::test::flat_terrain(0.0);
  ASSERT_NE(flat->height_field(), nullptr);
  for (const Eigen::Vector3d& c :
       {Eigen::Vector3d(0.0, 0.0, 0.007), Eigen::Vector3d(0.025, 0.025, 0.004), Eigen::Vector3d(0.0125, -0.3, 0.009)}) {
    for (bool grid : {false, true}) {
      tw::detail::Scratch scratch;
      scratch.height_field = grid ? flat->height_field() : nullptr;
      std::vector<tw::detail::Contact> out;
      tw::detail::collide_sphere(*flat, c, 0.01, scratch, out);
      if (grid) tw::detail::merge_patch_contacts(out, 0, flat->height_field()->cell(), 0.9);
      ASSERT_FALSE(out.empty());
      for (const auto& k : out) {
        EXPECT_NEAR(k.depth, 0.01 - c.z(), 1e-9);
        EXPECT_NEAR(k.normal.z(), 1.0, 1e-9);
      }
      if (grid) {
        EXPECT_EQ(out.size(), 1U) << "one patch, one contact";
      }
    }
  }
}

TEST(HeightField, AFootOnAStepEdgeIsPushedAsTheTrimeshPushesIt) {
  // A 10 cm step along x = 0 on a 1 cm grid: the foot (r = 1 cm) over the
  // edge touches the top and the steep band between the two rows of
  // cells. Both queries find the same deepest contact; every trimesh
  // contact has a merged one within a cell and 25° that is at least as
  // deep (the patch it belongs to), and the merged set pushes the way all
  // of the trimesh's contacts push (depth-weighted normals) within 25°.
  const auto step = analytic_terrain([](double x, double) { return x > 0 ? 0.1 : 0.0; }, 0.5, 0.01);
  ASSERT_NE(step->height_field(), nullptr);
  int compared = 0;
  for (double cx = -0.012; cx <= 0.012; cx += 0.003) {
    const Eigen::Vector3d c(cx, 0.0031, 0.106);
    std::vector<tw::detail::Contact> mesh, grid;
    tw::detail::Scratch s1, s2;
    s2.height_field = step->height_field();
    tw::detail::collide_sphere(*step, c, 0.01, s1, mesh);
    tw::detail::collide_sphere(*step, c, 0.01, s2, grid);
    tw::detail::merge_patch_contacts(grid, 0, step->height_field()->cell(), std::cos(25 * kRadPerDeg));
    ASSERT_EQ(mesh.empty(), grid.empty()) << cx;
    if (mesh.empty()) continue;
    auto deepest = [](const std::vector<tw::detail::Contact>& v) {
      return std::max_element(v.begin(), v.end(), [](auto& a, auto& b) { return a.depth < b.depth; })->depth;
    };
    EXPECT_NEAR(deepest(mesh), deepest(grid), 1e-12) << cx;
    auto push = [](const std::vector<tw::detail::Contact>& v) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (const auto& k : v) p += k.depth * k.normal;
      return p.normalized();
    };
    EXPECT_GT(push(mesh).dot(push(grid)), std::cos(25 * kRadPerDeg)) << cx;
    for (const auto& k : mesh) {
      const bool kept = std::any_of(grid.begin(), grid.end(), [&](const tw::detail::Contact& q) {
        return (q.position - k.position).norm() <= 0.01 + 1e-12 &&
               q.normal.dot(k.normal) >= std::cos(25 * kRadPerDeg) && q.depth >= k.depth - 1e-12;
      });
      EXPECT_TRUE(kept) << cx;
    }
    EXPECT_LE(grid.size(), mesh.size());
    ++compared;
  }
  EXPECT_GE(compared, 5);
}

TEST(HeightField, LandingsAgreeWithTheTrimeshAndTheAnalyticAnswers) {
  const auto af = tw::Airframe::f450();
  // Flat: level, the CoM at its analytic height.
  const auto flat = touchdown::test::flat_terrain(0.0);
  for (double h : {0.0, 77.0}) {
    const auto g = land(flat, h * kRadPerDeg, 0.0, kGrid), m = land(flat, h * kRadPerDeg, 0.0, kMesh);
    ASSERT_EQ(g.status, tw::RunStatus::Settled);
    EXPECT_LT(g.nutation, 0.02);
    EXPECT_TRUE(g.all_feet_in_contact);
    EXPECT_FALSE(g.strike());
    EXPECT_NEAR(g.final_position.z(), af.centre_of_mass().z() - af.ground_z(), 0.003);
    EXPECT_NEAR(g.final_position.z(), m.final_position.z(), 0.001);
  }
  // Inclines: the slope's angle, and the trimesh's within 5 mrad.
  for (double alpha : {5.0, 15.0}) {
    const auto slope = touchdown::test::incline_terrain(alpha * kRadPerDeg);
    const auto g = land(slope, 0.5, std::tan(alpha * kRadPerDeg) * 0.35, kGrid);
    const auto m = land(slope, 0.5, std::tan(alpha * kRadPerDeg) * 0.35, kMesh);
    ASSERT_EQ(g.status, tw::RunStatus::Settled) << alpha;
    EXPECT_NEAR(g.nutation, alpha * kRadPerDeg, 0.02) << alpha;
    EXPECT_NEAR(g.nutation, m.nutation, 0.005) << alpha;
  }
  // Front feet on a 6 cm ledge: atan(h / 0.30), as the trimesh.
  const auto ledge = analytic_terrain([](double x, double) { return x > 0 ? 0.06 : 0.0; }, 1.0, 0.01);
  const auto g = land(ledge, 0.0, 0.06, kGrid), m = land(ledge, 0.0, 0.06, kMesh);
  ASSERT_EQ(g.status, tw::RunStatus::Settled);
  EXPECT_NEAR(g.nutation, std::atan(0.06 / 0.30), 0.03);
  EXPECT_NEAR(g.nutation, m.nutation, 0.005);
  EXPECT_FALSE(g.strike());
  // A post under a propeller is a strike; turned 45°, clear.
  const auto post = analytic_terrain(
      [](double x, double y) { return std::hypot(x - 0.223, y - 0.223) < 0.02 ? 0.25 : 0.0; }, 1.0, 0.01);
  EXPECT_TRUE(land(post, 0.0, 0.0, kGrid).prop_strike);
  EXPECT_FALSE(land(post, 45 * kRadPerDeg, 0.0, kGrid).strike());
}

TEST(HeightField, ABoxOnFlatGroundRestsLevelAsOnTheTrimesh) {
  // The gearless quad lands on its body box: level, the box's bottom on the
  // ground, the same as with the trimesh's contacts.
  const tw::Airframe af =
      tw::load_airframe(std::filesystem::path(TOUCHDOWN_SOURCE_DIR) / "data/airframes/gearless_quad.yaml");
  ASSERT_FALSE(af.has_landing_gear());
  const auto flat = touchdown::test::flat_terrain(0.0);
  for (double h : {0.0, 30.0}) {
    const auto g = land(flat, h * kRadPerDeg, 0.0, kGrid, af), m = land(flat, h * kRadPerDeg, 0.0, kMesh, af);
    ASSERT_EQ(g.status, tw::RunStatus::Settled) << h;
    EXPECT_LT(g.nutation, 0.01) << h;
    EXPECT_TRUE(g.all_feet_in_contact) << "the box's four bottom corners";
    EXPECT_NEAR(g.final_position.z(), af.centre_of_mass().z() - af.ground_z(), 0.003) << h;
    EXPECT_NEAR(g.final_position.z(), m.final_position.z(), 0.001) << h;
    EXPECT_NEAR(g.nutation, m.nutation, 0.005) << h;
  }
}
