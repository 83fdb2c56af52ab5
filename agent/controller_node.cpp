#include "agent/controller_node.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <cmath>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "agent/vehicle_link.hpp"
#include "common/channels.hpp"

namespace auvrl::agent {
namespace {

/// Thrust per thruster (N) that pushes the vehicle up with half the heave force its thrusters
/// have, through the same allocation as the PID (the DOF the thrusters control).
Eigen::VectorXd surfacing_thrust_n(const sim::VehicleModel& model) {
  double heave_capacity_n = 0;
  for (int i = 0; i < model.num_thrusters(); ++i) {
    heave_capacity_n += std::abs(model.allocation(sim::kHeave, i));
  }
  heave_capacity_n *= model.thruster_dynamics.max_thrust_n;
  Eigen::Matrix<double, 6, 1> tau = Eigen::Matrix<double, 6, 1>::Zero();
  tau[sim::kHeave] = -0.5 * heave_capacity_n;  // body z points down
  return PidController(model).allocate(tau);
}

}  // namespace

ControllerNode::ControllerNode(const sim::VehicleModel& model, task::TaskConfig task,
                               std::unique_ptr<Controller> controller, Mission mission,
                               ControllerNodeOptions options, transport::Transport& transport,
                               std::ostream& log)
    : model_(model),
      vehicle_(model.facts()),
      task_(std::move(task)),
      controller_(std::move(controller)),
      mission_(std::move(mission)),
      options_(std::move(options)),
      transport_(transport),
      log_(log),
      supervisor_(options_.stale_steps, mission_.limits.surface_on_abort),
      states_(transport, channels::sim_state(options_.vehicle_id), 8),
      missions_(transport, channels::mission(options_.vehicle_id), 4) {
  task::apply_vehicle(vehicle_, task_);
  task_.validate();
  if (!(options_.speed > 0)) throw std::invalid_argument("--speed must be > 0");
  if (!controller_) throw std::invalid_argument("auv_controller needs a controller");
  tracker_ = std::make_unique<MissionTracker>(mission_.waypoints);
  period_ = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(task_.control_step_s / options_.speed));
  next_due_ = Clock::now() + period_;
  const int n = task_.num_thrusters;
  action_.setZero(n);
  commanded_.setZero(n);
  thrust_realised_n_.assign(static_cast<std::size_t>(n), 0.0);
  surface_thrust_n_ = surfacing_thrust_n(model_);
  controller_->reset();
}

bool ControllerNode::finished() const {
  return supervisor_.state() == SupervisorState::kAborted || tracker_->done();
}

void ControllerNode::set_mission(Mission mission) {
  mission_ = std::move(mission);
  tracker_ = std::make_unique<MissionTracker>(mission_.waypoints);
  supervisor_.new_mission(mission_.limits.surface_on_abort);
  first_state_time_s_.reset();
  controller_->reset();
  log_ << fmt::format("auv_controller: new mission '{}' ({} way-points)\n", mission_.name,
                      mission_.waypoints.size());
}

double ControllerNode::mission_time_s() const {
  return first_state_time_s_ ? last_state_time_s_ - *first_state_time_s_ : 0.0;
}

void ControllerNode::poll(int wait_ms) {
  const auto now = Clock::now();
  const int until_due = static_cast<int>(std::max<std::int64_t>(
      0, std::chrono::duration_cast<std::chrono::milliseconds>(next_due_ - now).count()));
  transport_.handle(std::min(wait_ms, until_due));
  if (auto msg = missions_.take()) on_mission(*msg);
  if (auto msg = states_.take()) {
    on_state(*msg);
    next_due_ = Clock::now() + period_ + period_ / 2;  // a state is due one step after this
  } else if (Clock::now() >= next_due_) {
    on_missed_step();
    next_due_ += period_;
  }
  log_new_events();
}

void ControllerNode::on_mission(const auvrl_lcm::mission_t& msg) {
  const std::string origin = channels::mission(options_.vehicle_id) + " message";
  try {
    if (msg.vehicle_id != options_.vehicle_id) {
      throw std::invalid_argument(fmt::format("it is for vehicle {}", msg.vehicle_id));
    }
    set_mission(read_mission_text(msg.yaml, origin));
  } catch (const std::exception& e) {
    log_ << "auv_controller: mission refused, keeping '" << mission_.name << "': " << e.what()
         << "\n";
  }
}

void ControllerNode::check_vehicle(const auvrl_lcm::vehicle_state_t& msg) const {
  expect_vehicle(vehicle_, msg, "auv_controller",
                 fmt::format("the vehicle on {}", states_.channel()));
}

void ControllerNode::on_state(const auvrl_lcm::vehicle_state_t& msg) {
  check_vehicle(msg);
  const VehicleReport report = vehicle_report(msg);
  observation_ = report.observation;
  thrust_realised_n_ = report.thrust_realised_n;
  last_state_time_s_ = report.time_s;
  if (!first_state_time_s_) first_state_time_s_ = last_state_time_s_;
  const double t = mission_time_s();
  const std::optional<std::string> violation =
      is_finite(observation_) ? check_limits(mission_, observation_) : std::nullopt;
  ThrustSource source = report.blown_up
                            ? supervisor_.on_unusable_state(
                                  t, fmt::format("the vehicle reports status {}", msg.status))
                            : supervisor_.on_state(t, observation_, violation);
  if (source == ThrustSource::kController) {
    const int before = tracker_->index();
    tracker_->update(t, observation_.position_ned_m);
    if (tracker_->index() != before) {
      log_ << fmt::format("auv_controller: t={:.1f} s: way-point {} of {} done\n", t, before + 1,
                          tracker_->count());
    }
    if (tracker_->done()) supervisor_.mission_done(t);
    const Eigen::Vector3d goal = tracker_->goal_ned_m();
    task::build_state(task_, observation_, goal, commanded_, state_vector_, thrust_realised_n_);
    controller_->act(observation_, goal, state_vector_, action_);
    source = supervisor_.on_action(t, action_);
  }
  command(source);
}

void ControllerNode::on_missed_step() {
  // Events are stamped with the vehicle's clock, which stopped with its states.
  command(supervisor_.on_missing_state(mission_time_s()));
}

void ControllerNode::command(ThrustSource source) {
  const int n = task_.num_thrusters;
  switch (source) {
    case ThrustSource::kController:
      commanded_ = action_.cwiseMax(-1.0f).cwiseMin(1.0f);
      break;
    case ThrustSource::kHoldLast:
      break;
    case ThrustSource::kZero:
      commanded_.setZero(n);
      break;
    case ThrustSource::kSurface:
      commanded_ = (surface_thrust_n_ / task_.max_thrust_n).cast<float>();
      break;
  }
  auvrl_lcm::thruster_cmd_t cmd{};
  cmd.utime = transport::now_utime();
  cmd.vehicle_id = options_.vehicle_id;
  cmd.seq = ++seq_;
  cmd.num_thrusters = static_cast<std::int8_t>(n);
  cmd.thrust_n.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    cmd.thrust_n[static_cast<std::size_t>(i)] =
        static_cast<double>(commanded_[i]) * task_.max_thrust_n;
  }
  transport::publish(transport_, channels::sim_command(options_.vehicle_id), cmd);
  publish_status();
}

void ControllerNode::publish_status() {
  auvrl_lcm::mission_status_t s{};
  s.utime = transport::now_utime();
  s.vehicle_id = options_.vehicle_id;
  s.mission_name = mission_.name;
  s.controller = options_.name;
  s.waypoint_index = tracker_->index();
  s.waypoint_count = tracker_->count();
  const Eigen::Vector3d goal = tracker_->goal_ned_m();
  for (int i = 0; i < 3; ++i) s.goal_ned_m[i] = goal[i];
  s.distance_m = (goal - observation_.position_ned_m).norm();
  s.held_s = tracker_->held_s();
  s.elapsed_s = mission_time_s();
  s.supervisor_state = static_cast<std::int8_t>(supervisor_.state());
  s.reason = supervisor_.reason();
  const SupervisorCounters& c = supervisor_.counters();
  s.steps = c.steps;
  s.stale_events = c.stale_events;
  s.non_finite_states = c.non_finite_states;
  s.non_finite_actions = c.non_finite_actions;
  transport::publish(transport_, channels::kMissionStatus, s);
}

void ControllerNode::log_new_events() {
  const auto& events = supervisor_.events();
  for (; events_logged_ < events.size(); ++events_logged_) {
    const SupervisorEvent& e = events[events_logged_];
    log_ << fmt::format("auv_controller: t={:.1f} s: {}\n", e.time_s, e.what);
  }
}

}  // namespace auvrl::agent
