// The end of `auvrl run` and `auvrl replay`: the CSV files, the plots (scripts/plot_mission.py)
// and the report, from what the run recorded.
#pragma once

#include <auvrl_lcm/mission_status_t.hpp>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "agent/mission.hpp"
#include "common/vehicle_facts.hpp"
#include "launcher/mission_record.hpp"
#include "launcher/mission_run.hpp"

namespace auvrl::launcher {

/// What a mission run did, for its report.
struct MissionRunSummary {
  int exit_code = 0;  ///< MissionRunExit
  std::string ended;  ///< why it stopped ("mission complete", "time limit of 120 s passed", ...)
  double wall_s = 0;  ///< the whole command, from the first process started to the last stopped
  /// Wall-clock from the mission's first state (the controller's first) to its last, s.
  double mission_wall_s = 0;
  double vehicle_time_s = 0;  ///< the vehicle clock over the same states, s
  std::optional<auvrl_lcm::mission_status_t> last_status;  ///< the last MISSION_STATUS
  std::vector<MissionRunEvent> events;                     ///< the events applied, in order
  /// auv_sim's faults_total and currents_total from its last heartbeat (the live faults and
  /// current changes it applied); none if unheard.
  std::optional<std::int64_t> sim_faults_total, sim_currents_total;
  std::vector<eval::MissionWaypointRow> waypoints;
  std::string plots_note;  ///< empty when the plots were drawn; otherwise why not
};

/// The real-time factor achieved: vehicle time / wall time (0 when no wall time passed).
double achieved_realtime_factor(const MissionRunSummary& summary);

/// Writes what a mission's record gives into dir: trajectory.csv (every state from the mission
/// start, with the way-point driven to), vehicle.csv, waypoints.csv (one row per way-point) and
/// events.csv; returns the per-way-point rows. The same record, live or replayed, gives the
/// same bytes. Throws std::runtime_error naming a file that cannot be written.
std::vector<eval::MissionWaypointRow> write_mission_record(const std::string& dir,
                                                           const agent::Mission& mission,
                                                           const VehicleFacts& facts,
                                                           const MissionRecorder& recorder,
                                                           const MissionEventLog& events);

/// Runs SOURCE/scripts/plot_mission.py on dir (dir/plots/mission_3d.png and
/// mission_thrusters.png, titled with run_name; its output goes to dir/processes/plots.log);
/// returns "" when it drew them, else a note saying why not (Python or matplotlib missing: the
/// note says what to install; a failure: where its output is).
std::string draw_mission_plots(const std::string& source_dir, const std::string& dir,
                               const std::string& run_name);

/// The report's "## Plots" section: the two plots, or plots_note (why there are none).
void write_plots_section(std::ostream& md, const std::string& plots_note);

/// The auv_controller lines of its log (processes/controller.log): its start, every event and
/// way-point with its vehicle time, its end.
std::vector<std::string> controller_event_lines(const std::string& log_path);

/// Writes events.csv: time_s (mission time when applied), event (what). Throws
/// std::runtime_error naming the path on failure.
void write_events_csv(const std::string& path, const std::vector<MissionRunEvent>& events);

/// Writes RUN/report.md: the mission and controller, how it ended, the per-way-point table,
/// wall-clock, vehicle time and the real-time factor achieved, the supervisor's final state and
/// counters, the events injected (and those that could not be), the controller's log lines, the
/// plots. Throws std::runtime_error naming the path on failure.
void write_mission_report(const MissionRunOptions& options, const agent::Mission& mission,
                          const MissionRunSummary& summary);

/// The lines printed at the end: the table, the times and where the files are.
void print_mission_summary(const MissionRunOptions& options, const MissionRunSummary& summary,
                           std::ostream& out);

}  // namespace auvrl::launcher
