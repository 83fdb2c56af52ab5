#include "agent/safety_supervisor.hpp"

#include <fmt/format.h>

#include <stdexcept>

namespace auvrl::agent {

const char* to_string(SupervisorState state) {
  switch (state) {
    case SupervisorState::kWaiting:
      return "WAITING";
    case SupervisorState::kActive:
      return "ACTIVE";
    case SupervisorState::kStale:
      return "STALE";
    case SupervisorState::kNonFinite:
      return "NON_FINITE";
    case SupervisorState::kAborted:
      return "ABORTED";
    case SupervisorState::kDone:
      return "DONE";
  }
  return "?";
}

bool is_finite(const task::Observation& o) {
  return o.position_ned_m.allFinite() && o.euler_rpy_rad.allFinite() &&
         o.velocity_body_mps.allFinite() && o.angular_rate_body_rad_s.allFinite();
}

SafetySupervisor::SafetySupervisor(int stale_steps, bool surface_on_abort)
    : stale_steps_(stale_steps), surface_on_abort_(surface_on_abort) {
  if (stale_steps < 1) throw std::invalid_argument("stale_steps must be >= 1");
}

void SafetySupervisor::enter(SupervisorState state, double time_s, const std::string& reason) {
  if (state == state_ && reason == reason_) return;
  state_ = state;
  reason_ = reason;
  events_.push_back(
      {time_s, fmt::format("{}{}{}", to_string(state), reason.empty() ? "" : ": ", reason)});
}

ThrustSource SafetySupervisor::abort_source() const {
  return surface_on_abort_ ? ThrustSource::kSurface : ThrustSource::kZero;
}

ThrustSource SafetySupervisor::on_missing_state(double time_s) {
  ++counters_.steps;
  ++counters_.missed_states;
  if (state_ == SupervisorState::kAborted) return abort_source();
  if (state_ == SupervisorState::kWaiting) return ThrustSource::kZero;
  ++missed_in_row_;
  if (missed_in_row_ < stale_steps_) {
    // A late state or two is jitter: the thrusters keep the last command meanwhile, unless
    // that command was already zero for a fault.
    return state_ == SupervisorState::kNonFinite || state_ == SupervisorState::kStale
               ? ThrustSource::kZero
               : ThrustSource::kHoldLast;
  }
  if (state_ != SupervisorState::kStale) {
    ++counters_.stale_events;
    enter(SupervisorState::kStale, time_s,
          fmt::format("no state for {} control steps", missed_in_row_));
  }
  return ThrustSource::kZero;
}

ThrustSource SafetySupervisor::on_state(double time_s, const task::Observation& observation,
                                        const std::optional<std::string>& limit_violation) {
  ++counters_.steps;
  missed_in_row_ = 0;
  if (state_ == SupervisorState::kAborted) return abort_source();
  if (!is_finite(observation)) {
    ++counters_.non_finite_states;
    enter(SupervisorState::kNonFinite, time_s, "non-finite state");
    return ThrustSource::kZero;
  }
  if (limit_violation) {
    ++counters_.aborts;
    enter(SupervisorState::kAborted, time_s, *limit_violation);
    return abort_source();
  }
  return ThrustSource::kController;
}

ThrustSource SafetySupervisor::on_unusable_state(double time_s, const std::string& why) {
  ++counters_.steps;
  missed_in_row_ = 0;
  if (state_ == SupervisorState::kAborted) return abort_source();
  ++counters_.non_finite_states;
  enter(SupervisorState::kNonFinite, time_s, why);
  return ThrustSource::kZero;
}

ThrustSource SafetySupervisor::on_action(double time_s, const task::ActionVector& action) {
  if (!action.allFinite()) {
    ++counters_.non_finite_actions;
    enter(SupervisorState::kNonFinite, time_s, "non-finite controller output");
    return ThrustSource::kZero;
  }
  enter(done_ ? SupervisorState::kDone : SupervisorState::kActive, time_s,
        done_ ? "mission complete" : "");
  return ThrustSource::kController;
}

void SafetySupervisor::mission_done(double time_s) {
  if (done_ || state_ == SupervisorState::kAborted) return;
  done_ = true;
  if (state_ == SupervisorState::kActive) {
    enter(SupervisorState::kDone, time_s, "mission complete");
  }
}

void SafetySupervisor::new_mission(bool surface_on_abort) {
  surface_on_abort_ = surface_on_abort;
  done_ = false;
}

}  // namespace auvrl::agent
