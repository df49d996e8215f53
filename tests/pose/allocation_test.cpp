// Steady-state LED tracking must not touch the heap (issue 4; docs/architecture.md, "Conventions"):
// a counting global operator new, armed only around the tracked frames.
#include <gtest/gtest.h>

#include <vector>

#include "counting_new.hpp"
#include "touchdown/pose/epnp.hpp"
#include "touchdown/pose/led_tracker.hpp"
#include "touchdown/pose/sim/synthetic.hpp"

namespace tp = touchdown::pose;

namespace {

struct Frames {
  std::vector<tp::RenderedFrame> frames;
};

Frames render(tp::TrajectoryKind kind, int n, std::uint64_t seed) {
  const tp::CameraModel camera;
  const auto k = tp::default_constellation();
  const tp::SyntheticCamera synth(camera, k);
  const auto trajectory = tp::make_trajectory(kind, n, seed, camera, k);
  Frames f;
  f.frames.resize(trajectory.size());
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    synth.render(trajectory[i].T_camera_body, trajectory[i > 0 ? i - 1 : 0].T_camera_body, seed, i, f.frames[i]);
  }
  return f;
}

}  // namespace

TEST(Allocation, SteadyStateTrackingDoesNotAllocate) {
  for (const auto kind : {tp::TrajectoryKind::Moving, tp::TrajectoryKind::Static}) {
    for (const bool depth : {true, false}) {
      const Frames f = render(kind, 160, 5);
      tp::TrackerOptions o;
      o.use_depth = depth;
      tp::LedTracker tracker(tp::CameraModel{}, tp::default_constellation(), o);
      // Warm-up: the buffers grow to the scene's needs.
      for (std::size_t i = 0; i < 40; ++i) {
        const auto dv = f.frames[i].depth.view();
        tracker.track(f.frames[i].colour.view(), &dv);
      }
      int ok = 0;
      std::size_t message_chars = 0;
      g_allocations = 0;
      g_armed = true;
      for (std::size_t i = 40; i < f.frames.size(); ++i) {
        const auto dv = f.frames[i].depth.view();
        const tp::PoseEstimate& e = tracker.track(f.frames[i].colour.view(), &dv);
        ok += e.ok();
        message_chars += e.message().size();  // the status's fixed text: no allocation either
      }
      g_armed = false;
      EXPECT_GT(message_chars, 0u);
      EXPECT_EQ(g_allocations.load(), 0) << "kind " << int(kind) << " depth " << depth;
      EXPECT_GE(ok, 115);  // it really tracked
    }
  }
}

TEST(Allocation, EpnpAndGaussNewtonDoNotAllocate) {
  const auto k = tp::default_constellation();
  const tp::PinholeCamera cam = tp::CameraModel{}.pinhole();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 0.05, -0.02, 1.5;
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Vector2d> uv;
  for (const auto& l : k.leds) {
    p.push_back(l.p_body);
    uv.push_back(cam.project(T * l.p_body));
  }
  g_allocations = 0;
  g_armed = true;
  const auto r = tp::solve_pnp(cam, p, uv);
  const auto four = tp::solve_epnp(cam, std::span(p).first(4), std::span(uv).first(4));
  const auto too_few = tp::solve_epnp(cam, std::span(p).first(3), std::span(uv).first(3));
  g_armed = false;
  EXPECT_EQ(too_few.status, tp::EpnpStatus::TooFewPoints);
  EXPECT_EQ(too_few.message(), "too_few_points");
  EXPECT_EQ(g_allocations.load(), 0);
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(four.ok());
}

TEST(Allocation, TheCounterWorks) {
  g_allocations = 0;
  g_armed = true;
  auto* v = new std::vector<int>(100);
  g_armed = false;
  delete v;
  EXPECT_GE(g_allocations.load(), 2);
}
