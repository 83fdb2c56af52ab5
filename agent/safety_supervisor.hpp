// The deployable controller's safety supervisor: decides, every control step, whether the
// controller's command may reach the thrusters. A state that stops coming, a non-finite state or
// controller output, and a vehicle leaving the mission's limits each take the thrusters from
// the controller; every such event is logged (with the time) and counted.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/task/task.hpp"

namespace auvrl::agent {

/// What the supervisor lets through (values of mission_status_t.supervisor_state).
enum class SupervisorState : std::int8_t {
  kWaiting = 0,    ///< no state yet: zero thrust
  kActive = 1,     ///< the controller's command goes to the thrusters
  kStale = 2,      ///< no state for stale_steps control steps: zero thrust until one arrives
  kNonFinite = 3,  ///< the last state or controller output held NaN or inf: zero thrust
  kAborted = 4,    ///< the vehicle left the mission's limits: zero thrust or surfacing, for good
  kDone = 5,       ///< the mission is complete: the controller holds the last way-point
};

const char* to_string(SupervisorState state);

/// What the thrusters get this control step.
enum class ThrustSource {
  kController,  ///< the controller's command
  kHoldLast,    ///< the last command again (a state missed, fewer than stale_steps in a row)
  kZero,        ///< zero thrust
  kSurface,     ///< the surfacing command (an abort whose mission asks for it)
};

/// Counters of what the supervisor has seen.
struct SupervisorCounters {
  std::int64_t steps = 0;               ///< control steps decided
  std::int64_t missed_states = 0;       ///< control steps without a new state
  std::int64_t stale_events = 0;        ///< entries into kStale
  std::int64_t non_finite_states = 0;   ///< states with NaN or inf
  std::int64_t non_finite_actions = 0;  ///< controller outputs with NaN or inf
  std::int64_t aborts = 0;              ///< 0 or 1
};

/// One logged event: when (s since the supervisor's first step) and what.
struct SupervisorEvent {
  double time_s = 0;
  std::string what;
};

/// The supervisor. Not thread-safe; one call of on_missing_state() or on_state() per control
/// step, then on_action() when on_state() let the controller act.
class SafetySupervisor {
 public:
  /// stale_steps: control steps without a state that make it stale (the 3);
  /// surface_on_abort: an abort commands surfacing instead of zero thrust.
  SafetySupervisor(int stale_steps, bool surface_on_abort);

  /// A control step passed without a new state: hold the last command, or zero thrust once
  /// stale_steps have passed without one.
  ThrustSource on_missing_state(double time_s);
  /// A new state: checks it (finite; within the limits: limit_violation says which limit it
  /// left and by how much, nullopt when within). kController means: let the controller act
  /// and pass its output to on_action(); anything else is what the thrusters get.
  ThrustSource on_state(double time_s, const task::Observation& observation,
                        const std::optional<std::string>& limit_violation);
  /// A state its sender marks as not to be trusted (vehicle_state_t.status != 0): zero thrust
  /// and kNonFinite with `why`, counted with the non-finite states.
  ThrustSource on_unusable_state(double time_s, const std::string& why);
  /// The controller's output for the state on_state() accepted: kController if finite, else
  /// kZero (counted).
  ThrustSource on_action(double time_s, const task::ActionVector& action);
  /// The mission is complete (kDone; the controller keeps holding its last way-point).
  void mission_done(double time_s);
  /// A new mission: not done any more, with its own abort command (an abort stays an abort).
  void new_mission(bool surface_on_abort);

  SupervisorState state() const { return state_; }
  /// Why the state is not kActive ("" while active).
  const std::string& reason() const { return reason_; }
  const SupervisorCounters& counters() const { return counters_; }
  /// Every event so far, in order.
  const std::vector<SupervisorEvent>& events() const { return events_; }

 private:
  void enter(SupervisorState state, double time_s, const std::string& reason);
  ThrustSource abort_source() const;

  int stale_steps_;
  bool surface_on_abort_;
  SupervisorState state_ = SupervisorState::kWaiting;
  std::string reason_ = "no state yet";
  int missed_in_row_ = 0;
  bool done_ = false;  ///< the mission completed (kDone instead of kActive from then on)
  SupervisorCounters counters_;
  std::vector<SupervisorEvent> events_;
};

/// True when every number of the observation is finite.
bool is_finite(const task::Observation& observation);

}  // namespace auvrl::agent
