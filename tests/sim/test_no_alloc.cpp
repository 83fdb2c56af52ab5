// step() must never touch the heap (training steps it millions of times, and real-time mode
// must not stall). This binary interposes malloc (glibc) to count calls while stepping.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>

#include "sim_test_util.hpp"  // first: see the note on Eigen warnings there

extern "C" void* __libc_malloc(std::size_t size);  // glibc's own allocator

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_mallocs{0};
}  // namespace

extern "C" void* malloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1);
  return __libc_malloc(size);
}

namespace auvrl::sim::test {
namespace {

TEST(NoAllocation, StepAndMeasureNeverAllocate) {
  // Sanity: the interposer sees allocations at all.
  g_counting = true;
  auto* probe = new std::vector<double>(100);
  g_counting = false;
  delete probe;
  ASSERT_GT(g_mallocs.load(), 0);

  for (const VehicleModel* m : {&nessie(), &nessie_munk(), &bluerov()}) {
    ResetSettings reset = reset_at_depth(5);
    reset.current.gauss_markov_speed_mean_mps = 0.1;
    reset.current.gauss_markov_speed_sigma_mps = 0.05;
    reset.current.gauss_markov_direction_sigma_rad = 0.1;
    reset.sensor_noise.position_sigma_m = 0.1;
    VehicleState s = make_state(*m, reset);
    ThrusterVector command = ThrusterVector::Constant(m->num_thrusters(), 10.0);
    VehicleModel euler = *m;
    euler.integrator = Integrator::kSemiImplicitEuler;
    g_mallocs = 0;
    g_counting = true;
    for (int k = 0; k < 1000; ++k) {
      command(0) = (k % 20 < 10) ? 20.0 : -20.0;
      step(*m, s, command);
      step_ideal_thrusters(*m, s, command);
      step(euler, s, command);
      const Measurement z = measure(*m, s);
      (void)z;
    }
    g_counting = false;
    EXPECT_EQ(s.status, StateStatus::kOk) << m->name;
    EXPECT_EQ(g_mallocs.load(), 0) << m->name;
  }
}

}  // namespace
}  // namespace auvrl::sim::test
