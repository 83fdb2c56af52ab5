// The fault accommodation runs in a vehicle's control loop (auv_controller): once reset, a
// step must not touch the heap, with every thruster healthy, one dead, or one weak and one dead.
// This binary interposes malloc (glibc) to count calls while stepping.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/task/fault_accommodation.hpp"
#include "malloc_counter.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::task {
namespace {

TEST(NoAllocation, FaultAccommodationStepsNeverAllocate) {
  // Sanity: the interposer sees allocations at all.
  ASSERT_GT(test_support::mallocs_during([] { delete new std::vector<double>(100); }), 0);

  TaskConfig task;
  task.layout = StateLayout::kExtendedThrust;
  apply_vehicle(
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts(),
      task);
  ThrusterFaultAccommodation accommodation(task);
  // Commands of 0.5 on every thruster; each realises what a healthy one would, but T6 nothing
  // when dead and T1 a tenth when weak.
  StateVector state = StateVector::Zero(task.state_dim());
  ActionVector action(6);
  const int first_action = 16, first_thrust = 17 + 6;  // task::build_state's extended_thrust
  for (int i = 0; i < 6; ++i) state[first_action + i] = 0.5f;
  struct Case {
    const char* name;
    bool t1_weak, t6_dead;
  };
  for (const Case& c : {Case{"healthy", false, false}, Case{"T6 dead", false, true},
                        Case{"T1 weak, T6 dead", true, true}}) {
    accommodation.reset();
    for (int i = 0; i < 6; ++i) state[first_thrust + i] = 0.5f;
    if (c.t1_weak) state[first_thrust] = 0.05f;
    if (c.t6_dead) state[first_thrust + 5] = 0.0f;
    const long mallocs = test_support::mallocs_during([&] {
      for (int t = 0; t < 200; ++t) {
        action.setConstant(0.5f);
        accommodation.apply(state, action);
      }
    });
    EXPECT_EQ(accommodation.weak(0), c.t1_weak) << c.name;
    EXPECT_EQ(accommodation.dead(5), c.t6_dead) << c.name;
    EXPECT_EQ(mallocs, 0) << c.name;
  }
}

}  // namespace
}  // namespace auvrl::task
