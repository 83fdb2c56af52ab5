#include "launcher/mission_report.hpp"

#include <fmt/format.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "agent/safety_supervisor.hpp"
#include "common/csv.hpp"
#include "common/process.hpp"
#include "eval/evaluation.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

/// plot_mission.py's exit status when matplotlib or numpy cannot be imported.
constexpr int kPlotModulesMissing = 3;
constexpr const char* kInstallPlots = "apt install python3-matplotlib python3-numpy";

std::string controller_text(const MissionRunOptions& o) {
  return o.controller == "pid" ? std::string("PID baseline (the vehicle's gains file)")
                               : "policy " + o.policy_path;
}

void write_times(std::ostream& md, const MissionRunOptions& o, const MissionRunSummary& s) {
  md << "## Time\n\n"
     << "| | |\n|---|---|\n"
     << fmt::format("| wall-clock, first process started to last stopped | {:.1f} s |\n", s.wall_s)
     << fmt::format("| wall-clock, the mission (its first state to its last) | {:.1f} s |\n",
                    s.mission_wall_s)
     << fmt::format("| vehicle time, the mission | {:.1f} s |\n", s.vehicle_time_s)
     << fmt::format(
            "| real-time factor achieved (vehicle time / mission wall-clock) | {:.2f} "
            "(asked: {:g}) |\n\n",
            achieved_realtime_factor(s), o.speed);
}

void write_supervisor(std::ostream& md, const MissionRunSummary& s) {
  md << "## Safety supervisor (the last MISSION_STATUS)\n\n";
  if (!s.last_status) {
    md << "No MISSION_STATUS was received.\n\n";
    return;
  }
  const auvrl_lcm::mission_status_t& st = *s.last_status;
  md << "| | |\n|---|---|\n"
     << "| state | " << agent::to_string(static_cast<agent::SupervisorState>(st.supervisor_state))
     << " |\n"
     << "| reason | " << (st.reason.empty() ? "-" : st.reason) << " |\n"
     << fmt::format("| way-point | {} of {} |\n",
                    std::min(st.waypoint_index + 1, st.waypoint_count), st.waypoint_count)
     << fmt::format("| mission time | {:.1f} s |\n", st.elapsed_s) << "| control steps commanded | "
     << st.steps << " |\n"
     << "| stale events | " << st.stale_events << " |\n"
     << "| non-finite states | " << st.non_finite_states << " |\n"
     << "| non-finite controller outputs | " << st.non_finite_actions << " |\n\n";
}

void write_events(std::ostream& md, const MissionRunSummary& s) {
  md << "## Events\n\n";
  if (s.events.empty()) md << "The mission has no events.\n";
  for (const MissionRunEvent& e : s.events) md << "- " << e.text << "\n";
  if (s.sim_faults_total && s.sim_currents_total) {
    md << "\nauv_sim applied " << *s.sim_faults_total << " live thruster fault(s) and "
       << *s.sim_currents_total
       << " live current change(s) (faults_total and currents_total of its last heartbeat).\n";
  }
  md << "\n";
}

}  // namespace

void write_plots_section(std::ostream& md, const std::string& plots_note) {
  md << "## Plots\n\n";
  if (!plots_note.empty()) {
    md << plots_note << "\n\n";
    return;
  }
  md << "![3-D path through the way-points](plots/mission_3d.png)\n\n"
     << "![thruster outputs](plots/mission_thrusters.png)\n\n";
}

double achieved_realtime_factor(const MissionRunSummary& s) {
  return s.mission_wall_s > 0 ? s.vehicle_time_s / s.mission_wall_s : 0.0;
}

std::vector<eval::MissionWaypointRow> write_mission_record(const std::string& dir,
                                                           const agent::Mission& mission,
                                                           const VehicleFacts& facts,
                                                           const MissionRecorder& recorder,
                                                           const MissionEventLog& events) {
  std::vector<agent::TrajectoryRow> rows = recorder.trajectory();
  const MissionAnalysis analysis = analyse_waypoints(mission.waypoints, rows, facts.max_thrust_n());
  const fs::path d = dir;
  eval::write_trajectory_csv((d / "trajectory.csv").string(), rows, facts.num_thrusters(),
                             &analysis.waypoint_index);
  eval::write_vehicle_csv((d / "vehicle.csv").string(), facts);
  eval::MissionOutcome outcome;  // write_mission_csv writes its way-points only
  outcome.waypoints = analysis.waypoints;
  eval::write_mission_csv((d / "waypoints.csv").string(), outcome);
  write_events_csv((d / "events.csv").string(), events.events());
  return analysis.waypoints;
}

std::string draw_mission_plots(const std::string& source_dir, const std::string& dir,
                               const std::string& run_name) {
  const std::string python = "/usr/bin/python3";
  const std::string script = source_dir + "/scripts/plot_mission.py";
  if (!fs::exists(python)) {
    return fmt::format(
        "No plots: {} is not installed (apt install python3 python3-matplotlib "
        "python3-numpy).",
        python);
  }
  if (!fs::exists(script)) return "No plots: " + script + " not found.";
  fs::create_directories(fs::path(dir) / "processes");
  const std::string log = (fs::path(dir) / "processes" / "plots.log").string();
  process::ChildProcess plotter({python, script, dir, run_name}, log);
  const int status = plotter.wait_for_exit(std::chrono::minutes(2));
  if (status == -1) {
    plotter.terminate();
    return "No plots: plot_mission.py took more than 2 minutes (see " + log + ").";
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (WIFEXITED(status) && WEXITSTATUS(status) == kPlotModulesMissing) {
    return fmt::format("No plots: python3-matplotlib or python3-numpy is not installed ({}).",
                       kInstallPlots);
  }
  return "No plots: plot_mission.py failed (see " + log + ").";
}

void write_events_csv(const std::string& path, const std::vector<MissionRunEvent>& events) {
  csv::Writer out(path, {"time_s", "event"}, csv::Mode::kTruncate, 9);
  for (const MissionRunEvent& e : events) out.row(e.time_s, e.text);
  out.flush();
}

std::vector<std::string> controller_event_lines(const std::string& log_path) {
  std::vector<std::string> lines;
  std::ifstream in(log_path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("auv_controller: ", 0) == 0) lines.push_back(line);
  }
  return lines;
}

void write_mission_report(const MissionRunOptions& o, const agent::Mission& mission,
                          const MissionRunSummary& s) {
  const std::string path = (fs::path(o.run_dir) / "report.md").string();
  std::ofstream md(path);
  md << "# Mission run: " << mission.name << "\n\n"
     << "- mission: " << o.mission_path
     << fmt::format(" ({} way-points, time limit {:g} s)\n", mission.waypoints.size(),
                    mission.time_limit_s)
     << "- controller: " << controller_text(o) << "\n"
     << "- vehicle: " << o.vehicle_path << "\n"
     << fmt::format("- speed: x{:g} real time (auv_sim --realtime-factor)\n", o.speed)
     << "- ended: " << s.ended << " (exit code " << s.exit_code << ")\n\n"
     << "## Way-points\n\n"
     << format_waypoint_table(s.waypoints) << "\n"
     << "From the recorded states fed to the mission tracker auv_controller uses: times are "
        "vehicle seconds since the mission start (the controller's first state); time to reach: "
        "first within the reach radius as the current way-point; from previous: the same from "
        "the previous way-point's completion; hold error: mean distance from that arrival to "
        "the end of its hold; energy: sum over the control steps while it was the current "
        "way-point of the mean squared normalised command.\n\n";
  write_times(md, o, s);
  write_supervisor(md, s);
  write_events(md, s);
  md << "## auv_controller's log\n\n```\n";
  for (const std::string& line :
       controller_event_lines((fs::path(o.run_dir) / "processes" / "controller.log").string())) {
    md << line << "\n";
  }
  md << "```\n\n";
  write_plots_section(md, s.plots_note);
  md << "## Files\n\n"
     << "trajectory.csv (every state from the mission start, eval's trajectory format), "
        "waypoints.csv, vehicle.csv, logs/ (LCM event logs), processes/ (each process's "
        "output).\n";
  md.flush();
  if (!md) throw std::runtime_error("cannot write " + path);
}

void print_mission_summary(const MissionRunOptions& o, const MissionRunSummary& s,
                           std::ostream& out) {
  out << "\n" << format_waypoint_table(s.waypoints) << "\n";
  out << fmt::format(
      "wall-clock {:.1f} s (mission {:.1f} s), vehicle time {:.1f} s, real-time factor {:.2f} "
      "(asked {:g})\n",
      s.wall_s, s.mission_wall_s, s.vehicle_time_s, achieved_realtime_factor(s), o.speed);
  if (s.last_status) {
    const auvrl_lcm::mission_status_t& st = *s.last_status;
    out << "supervisor: "
        << agent::to_string(static_cast<agent::SupervisorState>(st.supervisor_state))
        << (st.reason.empty() ? "" : " (" + st.reason + ")") << ", " << st.stale_events
        << " stale, " << st.non_finite_states << " non-finite states, " << st.non_finite_actions
        << " non-finite outputs\n";
  }
  if (!s.plots_note.empty()) out << s.plots_note << "\n";
  out << "ended: " << s.ended << "\nreport: " << (fs::path(o.run_dir) / "report.md").string()
      << "\n";
}

}  // namespace auvrl::launcher
