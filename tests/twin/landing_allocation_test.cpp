// A landing's step loop does not touch the heap (issue 35): the twin's
// contact generation, controller and mixer, and ODE's step arena, reuse
// their memory. Counted around whole landings that differ only in how many
// steps they take: operator new (counting_new.hpp) and, outside the
// sanitizer build (whose runtime owns malloc), malloc itself, through which
// Eigen and ODE allocate.
#include <gtest/gtest.h>

#include "counting_new.hpp"

#if !TOUCHDOWN_TEST_ASAN
extern "C" void* __libc_malloc(std::size_t);  // NOLINT(readability-identifier-naming): glibc's own malloc
namespace {
std::atomic<long> g_mallocs{0};
}
extern "C" void* malloc(std::size_t n) {
  if (g_armed.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
#endif
#include "touchdown/twin/landing.hpp"
#include "twin_test_util.hpp"

namespace tw = touchdown::twin;

namespace {

long allocations_of_landing(const std::shared_ptr<const tw::TerrainModel>& terrain, double hover_offset,
                            double still_time, long* steps) {
  tw::SimulationOptions o;
  o.still_time = still_time;
  o.rest_time = still_time + 1;  // end on still_time alone
  const tw::LandingSimulator sim(tw::Airframe::f450(), terrain, o);
  tw::LandingConditions c;
  c.hover_offset = hover_offset;
  c.heading = 0.4;
  g_allocations = 0;
#if !TOUCHDOWN_TEST_ASAN
  g_mallocs = 0;
#endif
  g_armed = true;
  const tw::RunResult r = sim.land(c);
  g_armed = false;
#if !TOUCHDOWN_TEST_ASAN
  std::cout << "landing of " << r.steps << " steps: " << g_allocations << " operator new, " << g_mallocs << " malloc\n";
  g_allocations += g_mallocs;
#endif
  EXPECT_EQ(r.status, tw::RunStatus::Settled);
  *steps = r.steps;
  return g_allocations;
}

}  // namespace

TEST(LandingAllocation, MoreStepsNoMoreAllocations) {
  // An incline: feet on several triangles, contacts every step once down.
  const auto slope = touchdown::test::incline_terrain(0.1);
  long steps_short = 0, steps_long = 0, steps_rest = 0;
  allocations_of_landing(slope, 0.6, 0.3, &steps_short);  // one-time set-up of the process
  const long a = allocations_of_landing(slope, 0.6, 0.3, &steps_short);
  const long b = allocations_of_landing(slope, 1.2, 0.3, &steps_long);  // longer flight and descent
  const long c = allocations_of_landing(slope, 0.6, 1.5, &steps_rest);  // 1.2 s more on the ground
  ASSERT_GT(steps_long, steps_short + 300);
  ASSERT_GT(steps_rest, steps_short + 500);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a, c);
}
