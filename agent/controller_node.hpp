// auv_controller's logic, the deployable controller: takes the vehicle's state from its state
// channel, builds the observation with the task's own function, lets the policy (or the PID)
// act every control step under the safety supervisor, publishes the thruster command, advances
// through the mission and publishes MISSION_STATUS. It knows nothing of the learner, the replay
// buffer or the training actors: a vehicle's driver that speaks SIM_STATE_<id> and
// SIM_CMD_<id> (docs/deployment.md) is all it needs.
#pragma once

#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/mission_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <chrono>
#include <memory>
#include <optional>
#include <ostream>

#include "agent/controller.hpp"
#include "agent/mission.hpp"
#include "agent/safety_supervisor.hpp"
#include "common/task/task.hpp"
#include "common/transport.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {

/// auv_controller's settings besides the vehicle, the controller and the mission.
struct ControllerNodeOptions {
  int vehicle_id = 0;   ///< its vehicle's SIM_STATE_<id> / SIM_CMD_<id>
  int stale_steps = 3;  ///< control steps without a state that stop the thrusters
  double speed = 1.0;   ///< the vehicle runs this many times faster than real time
  std::string name;     ///< "policy" or "pid" (MISSION_STATUS.controller)
};

/// The deployable controller as a transport participant. Single-threaded.
class ControllerNode {
 public:
  /// task: the layout the controller needs (the vehicle's facts are applied here). Throws
  /// std::invalid_argument for an unusable mission or option.
  ControllerNode(const sim::VehicleModel& model, task::TaskConfig task,
                 std::unique_ptr<Controller> controller, Mission mission,
                 ControllerNodeOptions options, transport::Transport& transport, std::ostream& log);

  /// Handles messages for up to wait_ms; takes a new mission sent over MISSION_<id>; acts on the
  /// newest state, or decides a missed control step when one is due. Throws UnrecoverableFault when
  /// the state names another vehicle.
  void poll(int wait_ms);
  /// Replaces the mission (a new one sent to the running controller): the tracker starts over
  /// from its first way-point; an abort stays an abort.
  void set_mission(Mission mission);

  const SafetySupervisor& supervisor() const { return supervisor_; }
  const MissionTracker& tracker() const { return *tracker_; }
  const Mission& mission() const { return mission_; }
  /// The mission is complete or aborted: nothing more will happen but holding or zero thrust.
  bool finished() const;

 private:
  using Clock = std::chrono::steady_clock;

  void on_state(const auvrl_lcm::vehicle_state_t& msg);
  /// A mission sent over MISSION_<id>: started, or refused (logged) keeping the current one.
  void on_mission(const auvrl_lcm::mission_t& msg);
  void on_missed_step();
  void check_vehicle(const auvrl_lcm::vehicle_state_t& msg) const;
  void command(ThrustSource source);
  void publish_status();
  void log_new_events();
  double mission_time_s() const;

  const sim::VehicleModel& model_;
  const VehicleFacts vehicle_;  ///< model_.facts(), once: every state is checked against it
  task::TaskConfig task_;
  std::unique_ptr<Controller> controller_;
  Mission mission_;
  ControllerNodeOptions options_;
  transport::Transport& transport_;
  std::ostream& log_;
  std::unique_ptr<MissionTracker> tracker_;
  SafetySupervisor supervisor_;
  transport::Latest<auvrl_lcm::vehicle_state_t> states_;
  transport::Latest<auvrl_lcm::mission_t> missions_;

  Clock::duration period_;
  Clock::time_point next_due_;  ///< when a control step without a state is decided
  std::optional<double> first_state_time_s_;
  double last_state_time_s_ = 0;  ///< the vehicle's clock (sim_time_s) of the newest state
  task::Observation observation_;
  std::vector<double> thrust_realised_n_;
  task::StateVector state_vector_;
  task::ActionVector action_;     ///< the controller's last output
  task::ActionVector commanded_;  ///< the last command sent, normalised
  Eigen::VectorXd surface_thrust_n_;
  std::int64_t seq_ = 0;
  std::size_t events_logged_ = 0;
};

}  // namespace auvrl::agent
