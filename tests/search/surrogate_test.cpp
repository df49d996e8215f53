// The surrogate environment (surrogate.hpp): eq. 5 on hand-made masks, the
// rendered masks' geometry, eq. 4 moves on the grid, eq. 3 states.
#include "touchdown/search/surrogate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <tuple>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/search/evaluation.hpp"

namespace touchdown::search {
namespace {

TEST(MaskReward, IsEq5OnHandMadeMasks) {
  // A 4 × 4 image, the marker on 12 pixels.
  const std::vector<std::uint8_t> truth{0, 1, 1, 1,  //
                                        0, 1, 1, 1,  //
                                        0, 1, 1, 1,  //
                                        0, 1, 1, 1};
  // 4 of them visible, plus two pixels off the marker (not counted).
  const std::vector<std::uint8_t> visible{1, 1, 0, 0,  //
                                          1, 1, 0, 0,  //
                                          0, 1, 0, 0,  //
                                          0, 1, 0, 0};
  const auto [s_gt, s_d] = mask_areas(truth, visible);
  EXPECT_EQ(s_gt, 12.0);
  EXPECT_EQ(s_d, 4.0);
  EXPECT_DOUBLE_EQ(mask_reward(truth, visible), 3.0);                      // S_gt / S_d
  EXPECT_EQ(mask_reward(truth, truth), 0.0);                               // nothing hidden
  EXPECT_EQ(mask_reward(truth, std::vector<std::uint8_t>(16, 0)), 0.0);    // wholly hidden
  EXPECT_EQ(mask_reward(std::vector<std::uint8_t>(16, 0), visible), 0.0);  // marker not in view
  EXPECT_THROW((void)mask_areas(truth, std::vector<std::uint8_t>(15, 0)), InvalidArgument);
}

TEST(RenderMarkerMasks, ProjectsTheMarkerAndHidesWhatTheBoxCovers) {
  SurrogateOptions o;  // 160 × 120, 90°: f = 80 px
  MarkerMasks m;
  // Straight above at 8 m, the object far away: a 10 × 10 px square, all visible.
  render_marker_masks(o, {0, 0, 8}, {5, 5}, m);
  auto [s_gt, s_d] = mask_areas(m.truth, m.visible);
  EXPECT_EQ(s_gt, 100.0);
  EXPECT_EQ(s_d, 100.0);
  // The box on the marker's middle, seen from straight above: its footprint
  // 0.5 × 0.4 m and more (the top is nearer) hidden, the rest visible.
  render_marker_masks(o, {0, 0, 8}, {0, 0}, m);
  std::tie(s_gt, s_d) = mask_areas(m.truth, m.visible);
  EXPECT_EQ(s_gt, 100.0);
  const double top = 0.5 * 0.4 * (80.0 / (8 - 1.75)) * (80.0 / (8 - 1.75));  // top face in px
  EXPECT_NEAR(s_gt - s_d, top, 6.0);
  // Beside the marker, it hides part of it only from a camera on its side
  // (between the camera and the marker), not from the other side.
  render_marker_masks(o, {-3, 0, 8}, {-0.9, 0}, m);
  std::tie(s_gt, s_d) = mask_areas(m.truth, m.visible);
  EXPECT_GT(s_gt, s_d);
  render_marker_masks(o, {3, 0, 8}, {-0.9, 0}, m);
  std::tie(s_gt, s_d) = mask_areas(m.truth, m.visible);
  EXPECT_EQ(s_gt, s_d);
  // Out of view.
  render_marker_masks(o, {20, 0, 8}, {5, 5}, m);
  EXPECT_EQ(mask_areas(m.truth, m.visible).first, 0.0);
}

TEST(SurrogateEnv, MovesOneCellPerActionAndRewardsByEq5) {
  SurrogateOptions o;
  o.position_noise = 0;
  o.start_radius = 0;  // straight down over the marker
  o.steps = 60;
  SurrogateEnv env(o);
  Rng rng(4);
  const DqnState s0 = env.reset(rng);
  EXPECT_EQ(s0[0], env.object().x());
  EXPECT_EQ(s0[1], env.object().y());
  EXPECT_EQ(s0[2], 0.0);
  EXPECT_EQ(s0[3], 0.0);
  EXPECT_EQ(s0[0], std::round(s0[0]));  // on a cell
  const Eigen::Vector2d start = env.object();
  auto st = env.step(0);  // U: +y
  EXPECT_EQ(env.object(), Eigen::Vector2d(start.x(), std::min(6.0, start.y() + 1)));
  EXPECT_EQ(st.state[1], env.object().y());
  EXPECT_EQ(st.reward, frame_reward(st.area_truth_px, st.area_visible_px));
  EXPECT_DOUBLE_EQ(env.drone().z(), 10 - 7.0 / 60);
  for (int k = 0; k < 20; ++k) st = env.step(2);  // L to the grid's edge
  EXPECT_EQ(env.object().x(), -6.0);
  // Walk to the marker and stand on it: partly hidden, a reward > 1.
  while (env.object().x() < 0) st = env.step(3);
  while (env.object().y() > 0) st = env.step(1);
  while (env.object().y() < 0) st = env.step(0);
  st = env.step(4);
  EXPECT_GT(st.area_truth_px, st.area_visible_px);
  EXPECT_GT(st.area_visible_px, 0.0);
  EXPECT_GT(st.reward, 1.0);
  EXPECT_EQ(st.reward, st.area_truth_px / st.area_visible_px);
  while (!st.done) st = env.step(4);
  EXPECT_THROW((void)env.step(4), InvalidArgument);
  EXPECT_THROW((void)env.step(7), InvalidArgument);
}

TEST(SurrogateOptions, Validates) {
  SurrogateOptions o;
  std::string why;
  EXPECT_TRUE(o.validate(&why)) << why;
  o.end_height = 20;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_EQ(why.rfind("start_height:", 0), 0u);
  o = {};
  o.steps = 0;
  EXPECT_FALSE(o.validate(&why));
  EXPECT_THROW(SurrogateEnv{o}, InvalidArgument);
}

}  // namespace
}  // namespace touchdown::search
