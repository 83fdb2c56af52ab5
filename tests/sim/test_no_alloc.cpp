// step() must never touch the heap (training steps it millions of times, and real-time mode
// must not stall). This binary interposes malloc (glibc) to count calls while stepping.
#include <gtest/gtest.h>

#include "malloc_counter.hpp"
#include "sim_test_util.hpp"  // before any Eigen header: see the note on Eigen warnings there

namespace auvrl::sim::test {
namespace {

TEST(NoAllocation, StepAndMeasureNeverAllocate) {
  // Sanity: the interposer sees allocations at all.
  ASSERT_GT(test_support::mallocs_during([] { delete new std::vector<double>(100); }), 0);

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
    const long mallocs = test_support::mallocs_during([&] {
      for (int k = 0; k < 1000; ++k) {
        command(0) = (k % 20 < 10) ? 20.0 : -20.0;
        step(*m, s, command);
        step_ideal_thrusters(*m, s, command);
        step(euler, s, command);
        const Measurement z = measure(*m, s);
        (void)z;
      }
    });
    EXPECT_EQ(s.status, StateStatus::kOk) << m->name;
    EXPECT_EQ(mallocs, 0) << m->name;
  }
}

}  // namespace
}  // namespace auvrl::sim::test
