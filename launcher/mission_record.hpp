// What `auvrl run` records while a mission runs (every SIM_STATE_<id>, SIM_CMD_<id>,
// SIM_FAULT_<id> and MISSION_STATUS) and what it makes of it afterwards: the trajectory from
// the controller's first state on, the events as applied, and one row per way-point computed by
// feeding a MissionTracker (the one auv_controller uses) with the recorded states, in the
// in-process evaluation's form (eval/mission_run.hpp: waypoints.csv is its mission.csv). Only
// messages count, in the order they arrive, so `auvrl replay` (the run's log played back by
// lcm-logplayer) records the same. No processes and no transport here: tests feed messages
// directly.
#pragma once

#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "agent/episode.hpp"
#include "agent/mission.hpp"
#include "eval/mission_run.hpp"

namespace auvrl::launcher {

/// An event of the mission as the run applied it.
struct MissionRunEvent {
  double time_s = 0;  ///< mission time when it was applied, s
  std::string text;   ///< what, with its time ("t=20.0 s (due at 20 s): thruster 0 (T1) at ...")
};

/// The mission's events as the vehicle got them. A current at time 0 is the water's current
/// from the start (set with the vehicle's reset). Every later change is a message heard on the
/// bus (what `auvrl run` injects, heard back, or its replay), at the mission time of the newest
/// state before it, with the due time of the mission's event it applies: a water current on
/// SIM_CURRENT_<id> is one event, a fault on SIM_FAULT_<id> one per thruster whose efficiency
/// it changes.
class MissionEventLog {
 public:
  /// thruster_names: the vehicle's, one per thruster.
  MissionEventLog(const agent::Mission& mission, std::vector<std::string> thruster_names);

  /// A fault message heard on `channel` when the mission time was mission_time_s (nothing
  /// before the mission start: 0). Returns the events it adds (a message that changes nothing,
  /// or names another number of thrusters, adds none).
  std::vector<MissionRunEvent> add_fault(const auvrl_lcm::thruster_fault_t& fault,
                                         std::optional<double> mission_time_s,
                                         const std::string& channel);

  /// A current message heard on `channel` at mission_time_s (as add_fault). Returns its event.
  MissionRunEvent add_current(const auvrl_lcm::water_current_t& current,
                              std::optional<double> mission_time_s, const std::string& channel);

  /// The events applied so far, in order (the current from the start first).
  const std::vector<MissionRunEvent>& events() const { return events_; }
  /// The water current the vehicle starts in (NED, m/s): the mission's current at time 0.
  const Eigen::Vector3d& start_current_ned_mps() const { return start_current_ned_mps_; }

 private:
  /// The mission's events after the start, in order, and whether a message matched each yet.
  std::vector<agent::MissionEvent> live_;
  std::vector<bool> live_seen_;
  /// "due at T s" of the first unmatched event of live_ that `matches`, now matched; or "not
  /// one of the mission's events".
  std::string take_due(const std::function<bool(const agent::MissionEvent&)>& matches);
  std::vector<std::string> thruster_names_;
  std::vector<double> efficiency_;  ///< per thruster, as the last message left it
  std::vector<MissionRunEvent> events_;
  Eigen::Vector3d start_current_ned_mps_ = Eigen::Vector3d::Zero();
};

/// The record of one vehicle's traffic during a mission.
class MissionRecorder {
 public:
  /// num_thrusters: the vehicle's (a command or state with another count is not recorded).
  explicit MissionRecorder(int num_thrusters);

  /// A state, received at wall_s (any monotonic clock, s). A repeat of the newest state's
  /// vehicle time (a re-sent state) is not recorded twice, nor is an older one once the mission
  /// has started; before that, an older one (a reset again) starts the record over.
  void add_state(const auvrl_lcm::vehicle_state_t& state, double wall_s);
  /// A command: the one in force for the states that follow it.
  void add_command(const auvrl_lcm::thruster_cmd_t& command);
  /// A MISSION_STATUS: the newest is kept, and the mission's start on the vehicle clock is
  /// refined from it (see start_time_s).
  void add_status(const auvrl_lcm::mission_status_t& status);

  /// The vehicle time (sim_time_s) of the controller's first state, i.e. of the mission start:
  /// for each status after the first state, the newest state's time minus the status's
  /// elapsed_s, the smallest such value (a status follows its state; a newer state can only
  /// make the difference larger), snapped to a recorded state. Nothing before a status.
  std::optional<double> start_time_s() const;
  /// The newest state's time since the mission start, s (nothing before the start is known).
  std::optional<double> mission_time_s() const;
  /// The newest MISSION_STATUS (nothing before the first).
  const std::optional<auvrl_lcm::mission_status_t>& last_status() const { return status_; }
  /// The newest state's wall time (negative before any state).
  double last_state_wall_s() const;
  std::size_t states_recorded() const { return states_.size(); }

  /// One row per state from the mission start on: time since the start, the observation, the
  /// newest command received before the state (zero before any), the realised thrust.
  /// distance_m is left 0 (analyse_waypoints fills it).
  std::vector<agent::TrajectoryRow> trajectory() const;
  /// Wall-clock from the mission start's state to the newest state, s (0 if none).
  double mission_wall_s() const;

 private:
  struct Sample {
    double sim_time_s;
    double wall_s;
    agent::TrajectoryRow row;
  };
  std::size_t first_mission_sample() const;

  int num_thrusters_;
  std::vector<Sample> states_;
  std::vector<double> command_n_;
  std::optional<auvrl_lcm::mission_status_t> status_;
  std::optional<double> start_estimate_s_;
};

/// The record of a mission as the in-process evaluation (`auvrl eval --mission`) gives it: one
/// row per way-point, and per trajectory row the way-point the vehicle was driving to.
struct MissionAnalysis {
  std::vector<eval::MissionWaypointRow> waypoints;
  std::vector<int> waypoint_index;  ///< per trajectory row, from 0 (write_trajectory_csv)
};

/// Feeds a MissionTracker (the one auv_controller uses) with the rows (times since the mission
/// start), as the evaluation does: each row's command counts for the way-point current before
/// the row (the one it drove to), and its distance_m is set to that way-point. Energy: sum over
/// the rows while a way-point was current of the mean squared normalised command (max_thrust_n
/// is 1); none once the mission is done.
MissionAnalysis analyse_waypoints(const std::vector<agent::MissionWaypoint>& waypoints,
                                  std::vector<agent::TrajectoryRow>& rows, double max_thrust_n);

/// The per-way-point table (Markdown, readable on a terminal too), the way-points numbered from
/// 1 as "way-point i of n" (waypoints.csv's index is from 0).
std::string format_waypoint_table(const std::vector<eval::MissionWaypointRow>& rows);

}  // namespace auvrl::launcher
