// The fault accommodation runs in a vehicle's control loop (auv_controller): once reset, a
// step must not touch the heap, with every thruster healthy or one dead. This binary
// interposes malloc (glibc) to count calls while stepping.
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <string>
#include <vector>

#include "common/task/fault_accommodation.hpp"
#include "sim/vehicle_model.hpp"

extern "C" void* __libc_malloc(std::size_t size);  // glibc's own allocator

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_mallocs{0};
}  // namespace

extern "C" void* malloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_mallocs.fetch_add(1);
  return __libc_malloc(size);
}

namespace auvrl::task {
namespace {

TEST(NoAllocation, FaultAccommodationStepsNeverAllocate) {
  g_counting = true;  // sanity: the interposer sees allocations at all
  auto* probe = new std::vector<double>(100);
  g_counting = false;
  delete probe;
  ASSERT_GT(g_mallocs.load(), 0);

  TaskConfig task;
  task.layout = StateLayout::kExtendedThrust;
  apply_vehicle(
      sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml").facts(),
      task);
  ThrusterFaultAccommodation accommodation(task);
  // Commands of 0.5 on every thruster; each realises what a healthy one would, but T6 nothing.
  StateVector state = StateVector::Zero(task.state_dim());
  ActionVector action(6);
  const int first_action = 16, first_thrust = 17 + 6;  // task::build_state's extended_thrust
  for (int i = 0; i < 6; ++i) state[first_action + i] = 0.5f;
  for (bool t6_dead : {false, true}) {
    accommodation.reset();
    for (int i = 0; i < 6; ++i) state[first_thrust + i] = i == 5 && t6_dead ? 0.0f : 0.5f;
    g_mallocs = 0;
    g_counting = true;
    for (int t = 0; t < 200; ++t) {
      action.setConstant(0.5f);
      accommodation.apply(state, action);
    }
    g_counting = false;
    EXPECT_EQ(accommodation.dead(5), t6_dead);
    EXPECT_EQ(g_mallocs.load(), 0) << (t6_dead ? "T6 dead" : "healthy");
  }
}

}  // namespace
}  // namespace auvrl::task
