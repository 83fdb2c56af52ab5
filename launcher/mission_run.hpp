// `auvrl run`: a mission flown by the deployable controller on the real-time simulator, from one
// command, the way it would fly on a vehicle. In a run directory it starts auv_logger, auv_sim
// --realtime, places the vehicle at the mission's start (vehicle_reset_t), then starts
// auv_controller; it shows the mission's progress (MISSION_STATUS), records every state and
// command, injects the mission's timed thruster faults and current changes live
// (thruster_fault_t on SIM_FAULT_0, water_current_t on SIM_CURRENT_0), and stops when the
// controller exits, the mission's time limit passes or on Ctrl-C. Then it writes trajectory.csv,
// vehicle.csv, waypoints.csv, events.csv, the plots and report.md (docs/deployment.md, "auvrl
// run").
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace auvrl::launcher {

/// What `auvrl run` was asked.
struct MissionRunOptions {
  std::string mission_path;           ///< the mission file (required)
  std::string policy_path;            ///< the policy's network file (controller "policy")
  std::string controller = "policy";  ///< "policy" or "pid"
  /// auv_controller --trust-key: the mission and policy must be signed by its private key.
  std::string trust_key;
  std::string vehicle_path;  ///< "": the mission's vehicle:, else Nessie VII
  double speed = 1.0;        ///< the vehicle runs this many times faster than real time
  std::string run_dir;       ///< "": SOURCE/runs/mission-<name>-<time>
  /// run_dir was prepared by this command before it entered the network namespace.
  bool prepared = false;
  std::string bin_dir;     ///< where auvrl, auv_sim, auv_controller and auv_logger are
  std::string source_dir;  ///< the source tree (scripts/netns.sh, scripts/plot_mission.py)
};

/// Exit codes of `auvrl run`.
enum MissionRunExit : int {
  kMissionComplete = 0,   ///< every way-point reached
  kMissionError = 1,      ///< a process failed or an output could not be written
  kMissionAborted = 3,    ///< the safety supervisor aborted the mission
  kMissionTimeLimit = 4,  ///< the mission's time limit passed before it was complete
  kMissionStopped = 130,  ///< Ctrl-C (SIGINT) or SIGTERM
};

/// Checks the mission, the vehicle and the controller before anything starts (a file that does
/// not fit is refused here, naming it: std::runtime_error, std::invalid_argument or
/// config::ConfigError), then creates the run directory (logs/, processes/, plots/, a copy of
/// the mission, README.txt); refuses one that exists and is not empty. Fills in run_dir and
/// vehicle_path and makes every path absolute.
void prepare_mission_run(MissionRunOptions& options);

/// The command line that runs this mission again inside a new private network namespace
/// (scripts/netns.sh --pidfile RUN/netns.pid), its run directory prepared.
std::vector<std::string> mission_namespace_command(const MissionRunOptions& options);

/// `auvrl run` once its options are parsed: prepares the run directory (unless
/// options.prepared), then runs the mission here when host_network is set or this process
/// already runs inside a private network namespace (AUVRL_IN_NETNS=1); otherwise runs itself
/// again inside a new one and does not return. Returns the exit code (MissionRunExit); throws
/// std::invalid_argument (auvrl's exit status 2) for anything refused before the run starts.
int start_mission_run(MissionRunOptions options, bool host_network, std::ostream& out);

/// Runs the prepared mission here (inside the namespace, or with --network host): processes,
/// progress, live faults, then the files, the plots, the report and the per-way-point table on
/// `out`. Returns the exit code (MissionRunExit).
int run_mission(const MissionRunOptions& options, std::ostream& out);

}  // namespace auvrl::launcher
