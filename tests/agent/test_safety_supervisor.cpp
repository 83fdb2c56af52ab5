// The deployable controller's safety supervisor in isolation: stale states, non-finite states
// and outputs, limits, the end of a mission; what the thrusters get each step and what is
// logged and counted.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "agent/safety_supervisor.hpp"

namespace auvrl::agent {
namespace {

task::Observation level() { return task::Observation{}; }

task::ActionVector action(float value) { return task::ActionVector::Constant(6, value); }

TEST(SafetySupervisor, ZeroThrustUntilTheFirstStateThenTheController) {
  SafetySupervisor s(3, false);
  EXPECT_EQ(s.state(), SupervisorState::kWaiting);
  EXPECT_EQ(s.on_missing_state(0.0), ThrustSource::kZero);
  EXPECT_EQ(s.on_state(0.1, level(), std::nullopt), ThrustSource::kController);
  EXPECT_EQ(s.on_action(0.1, action(0.5)), ThrustSource::kController);
  EXPECT_EQ(s.state(), SupervisorState::kActive);
  EXPECT_EQ(s.reason(), "");
}

TEST(SafetySupervisor, ThreeMissedStepsMakeItStaleWithZeroThrustAndAStateResumes) {
  SafetySupervisor s(3, false);
  s.on_state(0.0, level(), std::nullopt);
  s.on_action(0.0, action(0.5));
  // Two late states are jitter: the last command holds.
  EXPECT_EQ(s.on_missing_state(0.1), ThrustSource::kHoldLast);
  EXPECT_EQ(s.on_missing_state(0.2), ThrustSource::kHoldLast);
  EXPECT_EQ(s.state(), SupervisorState::kActive);
  // The third: zero thrust, STALE, counted and logged once however long it lasts.
  EXPECT_EQ(s.on_missing_state(0.3), ThrustSource::kZero);
  EXPECT_EQ(s.state(), SupervisorState::kStale);
  EXPECT_EQ(s.on_missing_state(0.4), ThrustSource::kZero);
  EXPECT_EQ(s.counters().stale_events, 1);
  EXPECT_EQ(s.counters().missed_states, 4);
  EXPECT_EQ(s.reason(), "no state for 3 control steps");
  // A state returns: the controller acts again.
  EXPECT_EQ(s.on_state(0.5, level(), std::nullopt), ThrustSource::kController);
  EXPECT_EQ(s.on_action(0.5, action(0.1)), ThrustSource::kController);
  EXPECT_EQ(s.state(), SupervisorState::kActive);
  ASSERT_EQ(s.events().size(), 3u);  // the first state's ACTIVE, then these
  EXPECT_EQ(s.events()[1].what, "STALE: no state for 3 control steps");
  EXPECT_DOUBLE_EQ(s.events()[1].time_s, 0.3);
  EXPECT_EQ(s.events()[2].what, "ACTIVE");
}

TEST(SafetySupervisor, NonFiniteStatesAndOutputsGetZeroThrust) {
  SafetySupervisor s(3, false);
  task::Observation nan = level();
  nan.velocity_body_mps[1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(s.on_state(0.0, nan, std::nullopt), ThrustSource::kZero);
  EXPECT_EQ(s.state(), SupervisorState::kNonFinite);
  EXPECT_EQ(s.reason(), "non-finite state");
  // While the fault lasts a missed state does not bring the old command back.
  EXPECT_EQ(s.on_missing_state(0.1), ThrustSource::kZero);
  EXPECT_EQ(s.on_state(0.2, level(), std::nullopt), ThrustSource::kController);
  task::ActionVector bad = action(0.2);
  bad[3] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(s.on_action(0.2, bad), ThrustSource::kZero);
  EXPECT_EQ(s.reason(), "non-finite controller output");
  EXPECT_EQ(s.counters().non_finite_states, 1);
  EXPECT_EQ(s.counters().non_finite_actions, 1);
  EXPECT_EQ(s.on_state(0.3, level(), std::nullopt), ThrustSource::kController);
  EXPECT_EQ(s.on_action(0.3, action(0.2)), ThrustSource::kController);
  EXPECT_EQ(s.state(), SupervisorState::kActive);
}

TEST(SafetySupervisor, AStateItsSenderDistrustsGetsZeroThrust) {
  SafetySupervisor s(3, false);
  s.on_state(0.0, level(), std::nullopt);
  s.on_action(0.0, action(0.5));
  EXPECT_EQ(s.on_unusable_state(0.1, "the vehicle reports status 2"), ThrustSource::kZero);
  EXPECT_EQ(s.state(), SupervisorState::kNonFinite);
  EXPECT_EQ(s.reason(), "the vehicle reports status 2");
  EXPECT_EQ(s.counters().non_finite_states, 1);
}

TEST(SafetySupervisor, LeavingTheLimitsAbortsForGoodWithTheReason) {
  for (const bool surface : {false, true}) {
    SafetySupervisor s(3, surface);
    s.on_state(0.0, level(), std::nullopt);
    s.on_action(0.0, action(0.5));
    const ThrustSource abort = surface ? ThrustSource::kSurface : ThrustSource::kZero;
    EXPECT_EQ(s.on_state(0.1, level(), std::string("depth 31.2 m beyond max_depth_m 30")), abort);
    EXPECT_EQ(s.state(), SupervisorState::kAborted);
    EXPECT_EQ(s.reason(), "depth 31.2 m beyond max_depth_m 30");
    // Nothing brings the controller back: not a state within the limits, not a missed one.
    EXPECT_EQ(s.on_state(0.2, level(), std::nullopt), abort);
    EXPECT_EQ(s.on_missing_state(0.3), abort);
    EXPECT_EQ(s.counters().aborts, 1);
  }
}

TEST(SafetySupervisor, ACompletedMissionReportsDoneAndStillFallsBackOnFaults) {
  SafetySupervisor s(3, false);
  s.on_state(0.0, level(), std::nullopt);
  s.on_action(0.0, action(0.5));
  s.mission_done(0.0);
  EXPECT_EQ(s.state(), SupervisorState::kDone);
  for (int i = 1; i <= 3; ++i) s.on_missing_state(0.1 * i);
  EXPECT_EQ(s.state(), SupervisorState::kStale);
  s.on_state(0.4, level(), std::nullopt);
  EXPECT_EQ(s.on_action(0.4, action(0.1)), ThrustSource::kController);
  EXPECT_EQ(s.state(), SupervisorState::kDone);
}

}  // namespace
}  // namespace auvrl::agent
