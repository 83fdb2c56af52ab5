// A mission (agent/mission.hpp) run in process: `auvrl eval --mission FILE`. The controller (a
// policy or the PID) drives to the tracker's current way-point, which switches as each one is
// held; the mission's timed events change the vehicle or the water at their times; the run
// stops when the last way-point is held, at the time limit, or when the vehicle leaves the
// mission's safety limits (an abort: the run ends there; what a vehicle then does,
// limits.surface_on_abort, is the deployed controller's business).
//
// Files written to DIR:
//   mission.csv     one row per way-point: index (from 0), x, y, z (NED, m), reached (1 if
//                   held for its hold time), time_to_reach_s (first time within its radius while
//                   it was the current way-point, s since the mission start; EMPTY if never),
//                   time_from_previous_s (the same, from the previous way-point's completion;
//                   EMPTY if never), completed_s (when its hold ended; EMPTY if never),
//                   hold_error_m (mean distance to it from its first arrival until completed
//                   or the run ended; EMPTY if never arrived), energy (sum over the 0.1 s steps
//                   it was the current way-point of the mean squared normalised command).
//   trajectory.csv  the evaluation's trajectory format (write_trajectory_csv; distance_m to
//                   the current way-point) plus a last column `waypoint`: the way-point driven
//                   to during that step (the reset row: 0).
//   vehicle.csv     the vehicle and its thrusters (write_vehicle_csv).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "agent/mission.hpp"
#include "common/task/task.hpp"
#include "eval/evaluation.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::eval {

/// How a mission run ended.
enum class MissionEnd {
  kCompleted,       ///< every way-point held
  kTimeLimit,       ///< the mission's time_limit_s passed first
  kLimitViolation,  ///< the vehicle left the mission's limits (an abort)
  kBlowUp,          ///< the simulation blew up (or reported non-finite values)
  kSimTimeout,      ///< the vehicle did not answer
};

/// "completed", "time_limit", "limit_violation", "blow_up", "sim_timeout".
const char* to_string(MissionEnd end);

/// One way-point's row of mission.csv.
struct MissionWaypointRow {
  int index = 0;  ///< from 0
  agent::MissionWaypoint waypoint;
  agent::WaypointResult result;
  /// Sum over the control steps it was the current way-point of the mean squared normalised
  /// thruster command (the evaluation's thrust_energy, per way-point).
  double thrust_energy = 0.0;
};

/// What a mission run did.
struct MissionOutcome {
  std::string mission;     ///< its name
  std::string controller;  ///< "policy" or "pid"
  MissionEnd end = MissionEnd::kTimeLimit;
  std::string abort_reason;  ///< kLimitViolation: which limit and the value (check_limits)
  double end_time_s = 0.0;   ///< when the run ended, s since the mission start
  int completed = 0;         ///< way-points held
  std::vector<MissionWaypointRow> waypoints;
};

/// A mission's trajectory: the evaluation's rows (the reset state first) and, per row, the
/// way-point driven to.
struct MissionTrajectory {
  std::vector<agent::TrajectoryRow> rows;
  std::vector<int> waypoint_index;
};

/// Runs the mission in process on a fresh vehicle at the mission's start (at rest; events at
/// time 0 are part of the start; sensor noise drawn with `seed`). The mission clock is the
/// control step count times the control step. task: the layout and scales of the controller's
/// observation vector (the vehicle's facts are applied here). Throws std::invalid_argument
/// naming the mission when an event names a thruster the vehicle does not have.
MissionOutcome run_mission(const sim::VehicleModel& model, task::TaskConfig task,
                           agent::Controller& controller, const agent::Mission& mission,
                           std::uint64_t seed, MissionTrajectory* trajectory);

/// Header line of mission.csv (no newline).
std::string mission_csv_header();
/// Writes mission.csv; throws std::runtime_error naming the path on failure.
void write_mission_csv(const std::string& path, const MissionOutcome& outcome);

/// One screen of text: how the run ended, then one line per way-point.
std::string format_mission_table(const MissionOutcome& outcome);

/// The whole `auvrl eval --mission`: reads request.mission_path, picks the vehicle (--vehicle
/// when given, else the mission's vehicle:, else request.vehicle_path, the default) and says
/// which, builds the controller, runs the mission, writes DIR, prints the table to `out`.
/// Throws std::invalid_argument for a bad request and config::ConfigError or
/// std::runtime_error for unreadable or unusable files.
MissionOutcome run_mission_request(const EvalRequest& request, std::ostream& out);

}  // namespace auvrl::eval
