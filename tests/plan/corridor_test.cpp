#include "touchdown/plan/corridor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/core/units.hpp"

namespace touchdown::plan {
namespace {

Box corridor_box(double x0, double y0, double z0, double x1, double y1, double z1) {
  Box b;
  b.min = Eigen::Vector3d(x0, y0, z0);
  b.max = Eigen::Vector3d(x1, y1, z1);
  return b;
}

Eigen::Vector3d corridor_uniform(std::mt19937& rng, const Box& b) {
  std::uniform_real_distribution<double> u(0, 1);
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) p(k) = b.min(k) + u(rng) * (b.max(k) - b.min(k));
  return p;
}

// Strictly inside `o` grown by `r` (with a small slack so that boundary points count as outside).
bool corridor_in_grown(const Box& o, double r, const Eigen::Vector3d& p) {
  const double e = 1e-9;
  return (p.array() > o.min.array() - r + e).all() && (p.array() < o.max.array() + r - e).all();
}

// Offset b of the face whose normal is `n` (NaN when there is none).
double corridor_face_offset(const Polytope& p, const Eigen::Vector3d& n) {
  for (int i = 0; i < p.faces(); ++i) {
    if ((p.A.row(i).transpose() - n).norm() < 1e-12) return p.b(i);
  }
  return std::nan("");
}

Polytope corridor_both(const Polytope& a, const Polytope& b) {
  Polytope p = a;
  p.intersect(b);
  return p;
}

// The landing scenario of the tests: start behind and above the pad, goal at the touchdown height above its centre.
const Eigen::Vector3d kCorridorStart(-3, 0.5, 2.5);
const Eigen::Vector3d kCorridorGoal(0, 0, 0.5);

// A camera near the pad centre, tilted 35 deg backward (toward −x) so that the approach from behind is in view.
CameraFov corridor_camera() {
  CameraFov c;
  c.T_pad_camera = Eigen::Isometry3d::Identity();
  c.T_pad_camera.linear() = Eigen::AngleAxisd(deg_to_rad(-35), Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.T_pad_camera.translation() = Eigen::Vector3d(0.3, 0, 0.1);
  c.horizontal_fov_rad = deg_to_rad(100);
  c.vertical_fov_rad = deg_to_rad(80);
  c.near_m = 0.1;
  c.far_m = 10;
  return c;
}

}  // namespace

// ---------------------------------------------------------------- Box, Polytope

TEST(CorridorBox, ContainsAndVolume) {
  const Box b = corridor_box(0, 0, 0, 2, 3, 4);
  EXPECT_DOUBLE_EQ(b.volume(), 24);
  EXPECT_TRUE(b.contains({1, 1, 1}));
  EXPECT_TRUE(b.contains({2, 3, 4}));
  EXPECT_FALSE(b.contains({2.1, 1, 1}));
  EXPECT_TRUE(b.contains({2.1, 1, 1}, 0.2));
  EXPECT_FALSE(b.contains({1, -0.01, 1}));
  EXPECT_EQ(corridor_box(0, 0, 0, 2, 0, 4).volume(), 0);
  EXPECT_EQ(corridor_box(0, 0, 0, 2, -1, 4).volume(), 0);
}

TEST(CorridorPolytope, AddNormalisesIntersectShrink) {
  Polytope p;
  p.add({0, 0, 2}, 4);
  ASSERT_EQ(p.faces(), 1);
  EXPECT_NEAR((p.A.row(0) - Eigen::RowVector3d(0, 0, 1)).norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(p.b(0), 2);
  EXPECT_TRUE(p.contains({100, -5, 2}));
  EXPECT_FALSE(p.contains({0, 0, 2.001}));
  EXPECT_THROW(p.add({0, 0, 0}, 1), InvalidArgument);

  Polytope q = Polytope::from_box(corridor_box(-1, -1, -1, 1, 1, 1));
  EXPECT_EQ(q.faces(), 6);
  EXPECT_TRUE(q.contains({0.99, -0.99, 0.5}));
  EXPECT_FALSE(q.contains({0, 0, -1.01}));
  q.intersect(p);
  EXPECT_EQ(q.faces(), 7);
  q.shrink(0.5);
  EXPECT_TRUE(q.contains({0.5, 0.5, 0.5}));
  EXPECT_FALSE(q.contains({0.6, 0, 0}));
  EXPECT_DOUBLE_EQ(q.b(6), 1.5);
}

// ---------------------------------------------------------------- Chebyshev ball

TEST(CorridorChebyshev, BoxIsHalfTheSmallestWidthAtTheCentre) {
  const Box b = corridor_box(0, 0, 0, 4, 2, 3);
  const ChebyshevBall ball = chebyshev_ball(Polytope::from_box(b));
  EXPECT_NEAR(ball.radius, 1, 1e-9);
  EXPECT_NEAR((ball.centre - Eigen::Vector3d(2, 1, 1.5)).norm(), 0, 1e-9);

  const ChebyshevBall cube = chebyshev_ball(Polytope::from_box(corridor_box(1, 2, 3, 2, 3, 4)));
  EXPECT_NEAR(cube.radius, 0.5, 1e-9);
  EXPECT_NEAR((cube.centre - Eigen::Vector3d(1.5, 2.5, 3.5)).norm(), 0, 1e-9);
}

TEST(CorridorChebyshev, ShrunkBoxLosesTheShrink) {
  Polytope p = Polytope::from_box(corridor_box(0, 0, 0, 4, 2, 3));
  p.shrink(0.3);
  EXPECT_NEAR(chebyshev_ball(p).radius, 0.7, 1e-9);
}

TEST(CorridorChebyshev, SimplexInradius) {
  Polytope p;
  p.add({-1, 0, 0}, 0);
  p.add({0, -1, 0}, 0);
  p.add({0, 0, -1}, 0);
  p.add({1, 1, 1}, 1);
  const double rho = 1 / (3 + std::sqrt(3.0));
  const ChebyshevBall ball = chebyshev_ball(p);
  EXPECT_NEAR(ball.radius, rho, 1e-9);
  EXPECT_NEAR((ball.centre - Eigen::Vector3d::Constant(rho)).norm(), 0, 1e-9);
}

TEST(CorridorChebyshev, RotatedBox) {
  // A 2 x 1 x 3 box rotated by an arbitrary rotation: radius 0.5 at its centre.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-0.7, Eigen::Vector3d(1, 1, 0).normalized()))
                                .toRotationMatrix();
  const Eigen::Vector3d centre(0.3, -2, 5);
  const Eigen::Vector3d half(1, 0.5, 1.5);
  Polytope p;
  for (int k = 0; k < 3; ++k) {
    p.add(R.col(k), R.col(k).dot(centre) + half(k));
    p.add(-R.col(k), -R.col(k).dot(centre) + half(k));
  }
  const ChebyshevBall ball = chebyshev_ball(p);
  EXPECT_NEAR(ball.radius, 0.5, 1e-9);
  EXPECT_NEAR((ball.centre - centre).norm(), 0, 1e-7);
}

TEST(CorridorChebyshev, EmptyPolytopeHasNegativeRadius) {
  Polytope p = Polytope::from_box(corridor_box(-1, -1, -1, 1, 1, 1));
  p.add({1, 0, 0}, -3);  // x ≤ −3 while x ≥ −1
  EXPECT_LT(chebyshev_ball(p).radius, 0);
  Polytope q = Polytope::from_box(corridor_box(0, 0, 0, 1, 1, 1));
  q.shrink(0.6);  // widths 1 − 1.2 < 0
  EXPECT_LT(chebyshev_ball(q).radius, 0);
}

TEST(CorridorChebyshev, UnboundedPolytopes) {
  Polytope half;
  half.add({0, 0, 1}, 2);  // z ≤ 2: cut by the 1e6 cube
  const ChebyshevBall b1 = chebyshev_ball(half);
  EXPECT_NEAR(b1.radius, (1e6 + 2) / 2, 1e-3);  // the cube's z extent [−1e6, 2] is its narrowest
  EXPECT_LE(b1.centre.z() + b1.radius, 2 + 1e-6);

  Polytope slab;
  slab.add({0, 0, 1}, 1);
  slab.add({0, 0, -1}, 1);
  const ChebyshevBall b2 = chebyshev_ball(slab);
  EXPECT_NEAR(b2.radius, 1, 1e-9);
  EXPECT_NEAR(b2.centre.z(), 0, 1e-9);
}

// ---------------------------------------------------------------- redundant faces

TEST(CorridorRedundant, DropsRedundantPlaneKeepsTheBox) {
  Polytope p = Polytope::from_box(corridor_box(-1, -1, -1, 1, 1, 1));
  p.add({1, 0, 0}, 5);    // far outside: redundant
  p.add({1, 1, 1}, 3);    // through the corner (1,1,1) only: redundant
  p.add({1, 1, 0}, 1.5);  // cuts off the edge x = y = 1: kept, and every box face keeps an area
  const Polytope q = remove_redundant_faces(p);
  ASSERT_EQ(q.faces(), 7);
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(q.A.row(i), p.A.row(i));
    EXPECT_EQ(q.b(i), p.b(i));
  }
  EXPECT_EQ(q.A.row(6), p.A.row(8));
  EXPECT_EQ(q.b(6), p.b(8));
}

TEST(CorridorRedundant, KeepsOneOfDuplicatesAndEmptyAsIs) {
  Polytope p = Polytope::from_box(corridor_box(0, 0, 0, 1, 2, 3));
  p.intersect(Polytope::from_box(corridor_box(0, 0, 0, 1, 2, 3)));
  const Polytope q = remove_redundant_faces(p);
  EXPECT_EQ(q.faces(), 6);
  // Same polytope: every vertex inside, points just outside each face outside.
  for (double x : {0.0, 1.0}) {
    for (double y : {0.0, 2.0}) {
      for (double z : {0.0, 3.0}) EXPECT_TRUE(q.contains({x, y, z}));
    }
  }
  EXPECT_FALSE(q.contains({1.01, 1, 1}));
  EXPECT_FALSE(q.contains({0.5, -0.01, 1}));
  EXPECT_FALSE(q.contains({0.5, 1, 3.01}));

  Polytope empty = Polytope::from_box(corridor_box(0, 0, 0, 1, 1, 1));
  empty.add({-1, 0, 0}, -2);  // x ≥ 2
  EXPECT_EQ(remove_redundant_faces(empty).faces(), 7);
}

// ---------------------------------------------------------------- camera pyramid

namespace {
void corridor_check_pyramid(const CameraFov& c) {
  const Polytope p = c.pyramid();
  ASSERT_EQ(p.faces(), 6);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(p.A.row(i).norm(), 1, 1e-12);
  const double th = std::tan(c.horizontal_fov_rad / 2);
  const double tv = std::tan(c.vertical_fov_rad / 2);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.99, 0.99);
  std::uniform_real_distribution<double> uz(c.near_m + 1e-3, c.far_m - 1e-3);
  for (int n = 0; n < 2000; ++n) {
    const double z = uz(rng);
    const double y = u(rng) * z * tv;  // drawn y first, as recorded
    const Eigen::Vector3d pc(u(rng) * z * th, y, z);
    ASSERT_TRUE(p.contains(c.T_pad_camera * pc)) << pc.transpose();
  }
  const double z = 0.5 * (c.near_m + c.far_m);
  const double e = 1e-3;
  const std::vector<Eigen::Vector3d> outside = {{z * th + e, 0, z},
                                                {-z * th - e, 0, z},
                                                {0, z * tv + e, z},
                                                {0, -z * tv - e, z},
                                                {0.1 * z * th, 0, c.near_m - e},
                                                {0, 0.1 * z * tv, c.far_m + e}};
  const std::vector<Eigen::Vector3d> inside = {{z * th - e, 0, z},  {-z * th + e, 0, z},  {0, z * tv - e, z},
                                               {0, -z * tv + e, z}, {0, 0, c.near_m + e}, {0, 0, c.far_m - e}};
  for (const auto& pc : outside) EXPECT_FALSE(p.contains(c.T_pad_camera * pc)) << pc.transpose();
  for (const auto& pc : inside) EXPECT_TRUE(p.contains(c.T_pad_camera * pc)) << pc.transpose();
}
}  // namespace

TEST(CorridorPyramid, IdentityCameraLooksUp) {
  CameraFov c;
  corridor_check_pyramid(c);
  const Polytope p = c.pyramid();
  EXPECT_TRUE(p.contains({0, 0, 5}));
  EXPECT_FALSE(p.contains({0, 0, -1}));
  EXPECT_FALSE(p.contains({5, 0, 1}));  // 79 deg off axis, beyond the 34 deg half angle
}

TEST(CorridorPyramid, PitchedCameraIsTransformed) {
  CameraFov c;
  c.T_pad_camera = Eigen::Isometry3d::Identity();
  c.T_pad_camera.linear() = Eigen::AngleAxisd(deg_to_rad(30), Eigen::Vector3d::UnitX()).toRotationMatrix();
  c.T_pad_camera.translation() = Eigen::Vector3d(0.2, -0.1, 0.05);
  c.horizontal_fov_rad = deg_to_rad(70);
  c.vertical_fov_rad = deg_to_rad(50);
  c.near_m = 0.2;
  c.far_m = 6;
  corridor_check_pyramid(c);
  // The optical axis is pad (0, −sin 30, cos 30); a point straight above the camera is 30 deg off axis toward
  // the camera's y axis, beyond the 25 deg vertical half angle.
  const Polytope p = c.pyramid();
  const Eigen::Vector3d cam = c.T_pad_camera.translation();
  EXPECT_TRUE(p.contains(cam + 3 * Eigen::Vector3d(0, -std::sin(deg_to_rad(30)), std::cos(deg_to_rad(30)))));
  EXPECT_FALSE(p.contains(cam + Eigen::Vector3d(0, 0, 3)));
}

TEST(CorridorPyramid, InvalidCameraThrows) {
  CameraFov c;
  c.horizontal_fov_rad = 0;
  try {
    (void)c.pyramid();
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("camera.fov_deg"), std::string::npos) << e.what();
  }
  c = CameraFov{};
  c.vertical_fov_rad = std::numbers::pi;
  EXPECT_THROW((void)c.pyramid(), InvalidArgument);
  c = CameraFov{};
  c.far_m = c.near_m;
  try {
    (void)c.pyramid();
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("camera.range"), std::string::npos) << e.what();
  }
  c = CameraFov{};
  c.near_m = -0.1;
  EXPECT_THROW((void)c.pyramid(), InvalidArgument);
}

// ---------------------------------------------------------------- free pieces

TEST(CorridorFreePieces, ObstacleInTheMiddleGivesSixSlabs) {
  const Box f = corridor_box(0, 0, 0, 10, 10, 10);
  const std::vector<Box> obstacles = {corridor_box(4, 4, 4, 6, 6, 6)};
  const std::vector<Box> pieces = free_pieces(f, obstacles);
  ASSERT_EQ(pieces.size(), 6u);
  const std::vector<Box> expected = {corridor_box(0, 0, 0, 4, 10, 10), corridor_box(6, 0, 0, 10, 10, 10),
                                     corridor_box(0, 0, 0, 10, 4, 10), corridor_box(0, 6, 0, 10, 10, 10),
                                     corridor_box(0, 0, 0, 10, 10, 4), corridor_box(0, 0, 6, 10, 10, 10)};
  for (const Box& e : expected) {
    bool found = false;
    for (const Box& p : pieces) found = found || (p.min == e.min && p.max == e.max);
    EXPECT_TRUE(found) << e.min.transpose() << " / " << e.max.transpose();
  }
  // An obstacle outside (or only touching) the box changes nothing.
  const std::vector<Box> away = {corridor_box(10, 0, 0, 12, 5, 5), corridor_box(20, 20, 20, 21, 21, 21)};
  const std::vector<Box> same = free_pieces(f, away);
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].min, f.min);
  EXPECT_EQ(same[0].max, f.max);
}

TEST(CorridorFreePieces, PiecesAreFreeCoverAndMaximal) {
  const Box f = corridor_box(0, 0, 0, 10, 8, 6);
  const std::vector<Box> obstacles = {corridor_box(2, 1, 0, 3, 4, 3), corridor_box(5, 3, 2, 7, 9, 4),
                                      corridor_box(-1, 6, 4, 4, 7, 5), corridor_box(8, -1, 1, 9, 2, 7)};
  const std::vector<Box> pieces = free_pieces(f, obstacles);
  ASSERT_GT(pieces.size(), 6u);
  std::mt19937 rng(11);
  for (const Box& p : pieces) {
    EXPECT_GT(p.volume(), 0);
    EXPECT_TRUE(f.contains(p.min) && f.contains(p.max));
    for (int n = 0; n < 300; ++n) {
      const Eigen::Vector3d x = corridor_uniform(rng, p);
      for (const Box& o : obstacles) ASSERT_FALSE(corridor_in_grown(o, 0, x)) << x.transpose();
    }
  }
  int free_points = 0;
  for (int n = 0; n < 5000; ++n) {
    const Eigen::Vector3d x = corridor_uniform(rng, f);
    bool blocked = false;
    for (const Box& o : obstacles) blocked = blocked || corridor_in_grown(o, 0, x);
    if (blocked) continue;
    ++free_points;
    bool covered = false;
    for (const Box& p : pieces) covered = covered || p.contains(x);
    ASSERT_TRUE(covered) << x.transpose();
  }
  EXPECT_GT(free_points, 3000);
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    for (std::size_t j = 0; j < pieces.size(); ++j) {
      if (i == j) continue;
      const bool inside = (pieces[i].min.array() >= pieces[j].min.array()).all() &&
                          (pieces[i].max.array() <= pieces[j].max.array()).all();
      EXPECT_FALSE(inside) << i << " inside " << j;
    }
  }
}

TEST(CorridorFreePieces, RejectsBadObstaclesAndTooManyBoxes) {
  const Box f = corridor_box(0, 0, 0, 10, 10, 10);
  const std::vector<Box> bad = {corridor_box(1, 1, 1, 2, 2, 2), corridor_box(3, 3, 3, 2, 4, 4)};
  try {
    (void)free_pieces(f, bad);
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("obstacles[1]"), std::string::npos) << e.what();
  }
  const std::vector<Box> one = {corridor_box(4, 4, 4, 6, 6, 6)};
  EXPECT_THROW((void)free_pieces(f, one, 5), InvalidArgument);
  EXPECT_EQ(free_pieces(f, one, 6).size(), 6u);
}

// ---------------------------------------------------------------- corridor

TEST(CorridorBuild, NoObstaclesConnects) {
  const CorridorOptions o;
  const Corridor c = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_EQ(to_string(c.status), "ok");
  EXPECT_TRUE(c.rear.contains(kCorridorStart));
  EXPECT_TRUE(c.touchdown.contains(kCorridorGoal));
  EXPECT_GT(chebyshev_ball(corridor_both(c.rear, c.touchdown)).radius, 1e-3);
  EXPECT_EQ(c.free_box.min, Eigen::Vector3d(-4, -1, 0));
  EXPECT_EQ(c.free_box.max, Eigen::Vector3d(1, 1.5, 3.5));
  EXPECT_EQ(c.rear_piece.min, c.free_box.min);
  EXPECT_EQ(c.touchdown_piece.max, c.free_box.max);
  // The overlap needs k ε_d > r: 0.4 > 0.25 at k = 2.
  EXPECT_EQ(c.dilations, 2);
  // Every point of either part keeps the radius from the free box's sides and the pad.
  std::mt19937 rng(3);
  for (int n = 0; n < 4000; ++n) {
    const Eigen::Vector3d x = corridor_uniform(rng, c.free_box);
    if (c.rear.contains(x) || c.touchdown.contains(x)) {
      ASSERT_TRUE(c.free_box.contains(x, -o.radius + 1e-9)) << x.transpose();
    }
  }
}

TEST(CorridorBuild, RearShrinksByTheRadius) {
  CorridorOptions o;
  o.radius = 0;
  const Corridor c0 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  o.radius = 0.25;
  const Corridor c1 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c0.ok() && c1.ok());
  const double r0 = chebyshev_ball(c0.rear).radius;
  EXPECT_NEAR(r0, 1.25, 1e-9);  // half the 2.5 m y width of the free box
  EXPECT_NEAR(chebyshev_ball(c1.rear).radius, r0 - 0.25, 1e-9);
}

TEST(CorridorBuild, AvoidsAnObstacleBetweenStartAndPad) {
  CorridorOptions o;
  o.max_dilations = 10;
  const std::vector<Box> obstacles = {corridor_box(-1.8, -0.4, 0, -1.2, 0.4, 0.7)};
  const Corridor c = build_corridor(kCorridorStart, kCorridorGoal, obstacles, o);
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_TRUE(c.rear.contains(kCorridorStart));
  EXPECT_TRUE(c.touchdown.contains(kCorridorGoal));
  EXPECT_GT(chebyshev_ball(corridor_both(c.rear, c.touchdown)).radius, 1e-6);
  // Rear: the slab above the obstacle (its bottom at 0.7 + r); touchdown grows up to it: k ε_d > 0.7 at k = 4.
  EXPECT_EQ(c.dilations, 4);
  std::mt19937 rng(5);
  int in_rear = 0;
  int in_touch = 0;
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Vector3d x = corridor_uniform(rng, c.free_box);
    const bool r = c.rear.contains(x);
    const bool t = c.touchdown.contains(x);
    in_rear += r;
    in_touch += t;
    if (r || t) {
      for (const Box& ob : obstacles) ASSERT_FALSE(corridor_in_grown(ob, o.radius, x)) << x.transpose();
    }
  }
  EXPECT_GT(in_rear, 100);
  EXPECT_GT(in_touch, 100);
}

TEST(CorridorBuild, StartBelowTheSplit) {
  const Eigen::Vector3d start(-3, 0.5, 0.4);
  const Corridor c = build_corridor(start, kCorridorGoal, {}, CorridorOptions{});
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_TRUE(c.rear.contains(start));
  // The bottom moves down to start.z − r, then the shrink puts it at start.z.
  EXPECT_NEAR(-corridor_face_offset(c.rear, {0, 0, -1}), start.z(), 1e-12);
}

TEST(CorridorBuild, BlockedStartAndGoal) {
  const CorridorOptions o;
  const std::vector<Box> around_start = {corridor_box(-3.5, 0, 2, -2.5, 1, 3)};
  Corridor c = build_corridor(kCorridorStart, kCorridorGoal, around_start, o);
  EXPECT_EQ(c.status, CorridorStatus::StartBlocked);
  EXPECT_EQ(to_string(c.status), "start_blocked");
  // Close to an obstacle (within the radius) is blocked too.
  const std::vector<Box> near_start = {corridor_box(-2.9, 0, 2, -2.5, 1, 3)};
  EXPECT_EQ(build_corridor(kCorridorStart, kCorridorGoal, near_start, o).status, CorridorStatus::StartBlocked);
  const std::vector<Box> clear_of_start = {corridor_box(-2.7, 0, 2, -2.5, 1, 3)};
  EXPECT_EQ(build_corridor(kCorridorStart, kCorridorGoal, clear_of_start, o).status, CorridorStatus::Ok);
  EXPECT_EQ(build_corridor({-3, 0.5, 0.2}, kCorridorGoal, {}, o).status, CorridorStatus::StartBlocked);

  const std::vector<Box> on_goal = {corridor_box(-0.2, -0.2, 0, 0.2, 0.2, 0.4)};
  c = build_corridor(kCorridorStart, kCorridorGoal, on_goal, o);
  EXPECT_EQ(c.status, CorridorStatus::GoalBlocked);
  EXPECT_EQ(to_string(c.status), "goal_blocked");
  EXPECT_FALSE(c.message.empty());
}

TEST(CorridorBuild, GoalOutsideTheFieldOfView) {
  CorridorOptions o;
  o.camera = corridor_camera();
  const Corridor c = build_corridor(kCorridorStart, {2, 0, 0.5}, {}, o);
  EXPECT_EQ(c.status, CorridorStatus::GoalBlocked);
  EXPECT_NE(c.message.find("field of view"), std::string::npos) << c.message;
  o.camera->T_pad_camera.linear() = Eigen::Matrix3d::Identity();  // looking straight up: the start is out of view
  EXPECT_EQ(build_corridor(kCorridorStart, kCorridorGoal, {}, o).status, CorridorStatus::StartBlocked);
}

TEST(CorridorBuild, CameraCorridorStaysInView) {
  CorridorOptions o;
  o.camera = corridor_camera();
  const Corridor c = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_TRUE(c.rear.contains(kCorridorStart));
  EXPECT_TRUE(c.touchdown.contains(kCorridorGoal));
  EXPECT_GT(chebyshev_ball(corridor_both(c.rear, c.touchdown)).radius, 1e-6);
  Polytope view = o.camera->pyramid();
  view.shrink(o.radius);
  std::mt19937 rng(9);
  int in_parts = 0;
  for (int n = 0; n < 20000; ++n) {
    const Eigen::Vector3d x = corridor_uniform(rng, c.free_box);
    if (c.rear.contains(x) || c.touchdown.contains(x)) {
      ++in_parts;
      ASSERT_TRUE(view.contains(x)) << x.transpose();
    }
  }
  EXPECT_GT(in_parts, 100);
}

TEST(CorridorBuild, WallSeparatesStartFromGoal) {
  const std::vector<Box> wall = {corridor_box(-1.6, -5, 0, -1.4, 5, 10)};
  const Corridor c = build_corridor(kCorridorStart, kCorridorGoal, wall, CorridorOptions{});
  EXPECT_FALSE(c.ok());
  EXPECT_TRUE(c.status == CorridorStatus::NoConnection || c.status == CorridorStatus::NoOverlap) << to_string(c.status);
  EXPECT_FALSE(c.message.empty());
}

TEST(CorridorBuild, DeflationMovesTheTouchdownSides) {
  CorridorOptions o;
  o.deflate = 0;
  const Corridor c0 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  o.deflate = 0.3;
  const Corridor c1 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c0.ok() && c1.ok());
  for (int k = 0; k < 2; ++k) {
    for (double s : {1.0, -1.0}) {
      const Eigen::Vector3d n = s * Eigen::Vector3d::Unit(k);
      const double b0 = corridor_face_offset(c0.touchdown, n);
      const double b1 = corridor_face_offset(c1.touchdown, n);
      ASSERT_FALSE(std::isnan(b0) || std::isnan(b1)) << n.transpose();
      EXPECT_NEAR(b0 - b1, 0.3, 1e-12) << n.transpose();
    }
  }
  EXPECT_NEAR(corridor_face_offset(c1.touchdown, {-1, 0, 0}), 4 - 0.3 - 0.25, 1e-12);
  // The rear part is not deflated.
  EXPECT_NEAR(corridor_face_offset(c1.rear, {-1, 0, 0}), corridor_face_offset(c0.rear, {-1, 0, 0}), 1e-12);
  // Deflation stops at the pad centre: a huge one leaves the drone's footprint only, no room to overlap.
  o.deflate = 10;
  const Corridor c2 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  EXPECT_EQ(c2.status, CorridorStatus::NoOverlap);
  EXPECT_EQ(to_string(c2.status), "no_overlap");
  EXPECT_NE(c2.message.find("dilations"), std::string::npos) << c2.message;
}

TEST(CorridorBuild, DilationSetsTheSplitOverlap) {
  CorridorOptions o;
  o.radius = 0;
  const Corridor c0 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c0.ok());
  EXPECT_EQ(c0.dilations, 1);
  EXPECT_NEAR(-corridor_face_offset(c0.rear, {0, 0, -1}), o.h_touchdown - o.dilate, 1e-12);
  EXPECT_NEAR(corridor_face_offset(c0.touchdown, {0, 0, 1}), o.h_touchdown + o.dilate, 1e-12);
  o.radius = 0.25;
  const Corridor c1 = build_corridor(kCorridorStart, kCorridorGoal, {}, o);
  ASSERT_TRUE(c1.ok());
  EXPECT_EQ(c1.dilations, 2);
  EXPECT_NEAR(-corridor_face_offset(c1.rear, {0, 0, -1}), o.h_touchdown - 2 * o.dilate + o.radius, 1e-12);
  EXPECT_NEAR(corridor_face_offset(c1.touchdown, {0, 0, 1}), o.h_touchdown + 2 * o.dilate - o.radius, 1e-12);
  o.max_dilations = 1;
  EXPECT_EQ(build_corridor(kCorridorStart, kCorridorGoal, {}, o).status, CorridorStatus::NoOverlap);
}

TEST(CorridorBuild, PerSegment) {
  const Corridor c = build_corridor(kCorridorStart, kCorridorGoal, {}, CorridorOptions{});
  ASSERT_TRUE(c.ok());
  const std::vector<Polytope> s = c.per_segment(3);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0].b, c.rear.b);
  EXPECT_EQ(s[1].b, c.rear.b);
  EXPECT_EQ(s[2].b, c.touchdown.b);
  EXPECT_EQ(s[2].A, c.touchdown.A);
  EXPECT_THROW((void)c.per_segment(1), InvalidArgument);
}

TEST(CorridorBuild, StatusNames) {
  EXPECT_EQ(to_string(CorridorStatus::Ok), "ok");
  EXPECT_EQ(to_string(CorridorStatus::StartBlocked), "start_blocked");
  EXPECT_EQ(to_string(CorridorStatus::GoalBlocked), "goal_blocked");
  EXPECT_EQ(to_string(CorridorStatus::NoConnection), "no_connection");
  EXPECT_EQ(to_string(CorridorStatus::NoOverlap), "no_overlap");
}

TEST(CorridorBuild, InvalidInputThrowsNamingTheField) {
  struct Case {
    const char* field;
    void (*set)(CorridorOptions&);
  };
  const Case cases[] = {
      {"corridor.h_touchdown", [](CorridorOptions& o) { o.h_touchdown = 0; }},
      {"corridor.h_touchdown", [](CorridorOptions& o) { o.h_touchdown = std::nan(""); }},
      {"corridor.deflate", [](CorridorOptions& o) { o.deflate = -0.1; }},
      {"corridor.dilate", [](CorridorOptions& o) { o.dilate = 0; }},
      {"corridor.max_dilations", [](CorridorOptions& o) { o.max_dilations = 0; }},
      {"corridor.radius", [](CorridorOptions& o) { o.radius = -1; }},
      {"corridor.radius", [](CorridorOptions& o) { o.radius = INFINITY; }},
      {"corridor.margin", [](CorridorOptions& o) { o.margin = -0.5; }},
      {"corridor.margin",
       [](CorridorOptions& o) {
         o.radius = 0.3;
         o.margin = 0.2;
       }},
      {"corridor.camera.fov_deg",
       [](CorridorOptions& o) {
         o.camera = CameraFov{};
         o.camera->horizontal_fov_rad = 4;
       }},
      {"corridor.camera.fov_deg",
       [](CorridorOptions& o) {
         o.camera = CameraFov{};
         o.camera->vertical_fov_rad = -1;
       }},
      {"corridor.camera.range",
       [](CorridorOptions& o) {
         o.camera = CameraFov{};
         o.camera->far_m = 0.05;
       }},
  };
  for (const Case& k : cases) {
    CorridorOptions o;
    k.set(o);
    std::string why;
    EXPECT_FALSE(o.validate(&why)) << k.field;
    EXPECT_EQ(why.rfind(std::string(k.field) + ":", 0), 0u) << why;
    EXPECT_EQ(why.find('\n'), std::string::npos);
    try {
      (void)build_corridor(kCorridorStart, kCorridorGoal, {}, o);
      ADD_FAILURE() << "no throw for " << k.field;
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find(k.field), std::string::npos) << e.what();
    }
  }
  std::string why;
  EXPECT_TRUE(CorridorOptions{}.validate(&why)) << why;
  EXPECT_NE(CorridorOptions{}.validate(nullptr), false);
  // The radius message carries the bad value.
  CorridorOptions o;
  o.radius = -1;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_NE(why.find("-1"), std::string::npos) << why;

  const CorridorOptions ok;
  EXPECT_THROW((void)build_corridor({std::nan(""), 0, 1}, kCorridorGoal, {}, ok), InvalidArgument);
  EXPECT_THROW((void)build_corridor(kCorridorStart, {0, INFINITY, 0.5}, {}, ok), InvalidArgument);
  const std::vector<Box> bad = {corridor_box(0, 0, 0, -1, 1, 1)};
  EXPECT_THROW((void)build_corridor(kCorridorStart, kCorridorGoal, bad, ok), InvalidArgument);
}

}  // namespace touchdown::plan
