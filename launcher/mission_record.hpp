// What `auvrl run` records while a mission runs (every SIM_STATE_<id>, SIM_CMD_<id> and
// MISSION_STATUS) and what it makes of it afterwards: the trajectory from the controller's
// first state on, and one row per way-point computed by feeding a MissionTracker (the one
// auv_controller uses) with the recorded states. No processes and no transport here: tests feed
// messages directly.
#pragma once

#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <optional>
#include <string>
#include <vector>

#include "agent/episode.hpp"
#include "agent/mission.hpp"

namespace auvrl::launcher {

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

/// What became of one way-point of a mission run (waypoints.csv, the report's table).
struct WaypointRow {
  int number = 0;  ///< from 1, as "way-point i of n"
  agent::MissionWaypoint waypoint;
  agent::WaypointResult result;
  /// Sum over the control steps while it was the current way-point of the mean squared
  /// normalised command (six thrusters at full thrust for 10 s give 100).
  double energy = 0.0;
  int steps = 0;  ///< control steps while it was the current way-point
};

/// Feeds a MissionTracker with the rows (times since the mission start) and returns one row per
/// way-point; sets each trajectory row's distance_m to the way-point current at that row.
std::vector<WaypointRow> analyse_waypoints(const std::vector<agent::MissionWaypoint>& waypoints,
                                           std::vector<agent::TrajectoryRow>& rows,
                                           double max_thrust_n);

/// Writes waypoints.csv: index (from 1), x, y, z (NED, m), reached (0/1), time_to_reach_s
/// (first time within the radius as the current way-point, s since the mission start; empty if
/// never), hold_error_m (mean distance from that arrival to its completion, m; empty if never),
/// energy, time_from_previous_s (from the previous way-point's completion; empty if never),
/// completed_s (when its hold ended; empty if never). Throws std::runtime_error naming the path
/// on failure.
void write_waypoints_csv(const std::string& path, const std::vector<WaypointRow>& rows);

/// The per-way-point table (Markdown, readable on a terminal too).
std::string format_waypoint_table(const std::vector<WaypointRow>& rows);

}  // namespace auvrl::launcher
