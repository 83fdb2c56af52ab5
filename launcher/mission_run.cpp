#include "launcher/mission_run.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <auvrl_lcm/logger_heartbeat_t.hpp>
#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_reset_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>

#include "agent/controller_process.hpp"
#include "agent/safety_supervisor.hpp"
#include "common/channels.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/vehicle_facts.hpp"
#include "eval/evaluation.hpp"
#include "eval/mission_run.hpp"
#include "launcher/mission_record.hpp"
#include "launcher/mission_report.hpp"
#include "launcher/namespace_exec.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/supervisor.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

constexpr int kVehicleId = 0;              ///< the one vehicle auv_sim serves here
constexpr double kStartTimeoutS = 15.0;    ///< for the logger's heartbeat and the sim's state
constexpr double kStateSilenceS = 5.0;     ///< no state this long (wall-clock): the sim is gone
constexpr double kControllerGraceS = 3.0;  ///< SIGTERM to SIGKILL, s
constexpr double kSimGraceS = 3.0;
constexpr double kLoggerGraceS = 10.0;
/// Mission times are differences of vehicle clocks: 6.0 may come out as 5.9999999.
constexpr double kTimeToleranceS = 1e-6;

/// The mission's name as a file name: letters, digits, '-', '_' and '.' kept, others '_'.
std::string file_name_part(const std::string& name) {
  std::string out = name;
  for (char& c : out) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '-' || c == '_' || c == '.';
    if (!keep) c = '_';
  }
  return out.empty() ? "mission" : out;
}

agent::ControllerProcessOptions controller_options(const MissionRunOptions& o,
                                                   const std::string& mission_path) {
  agent::ControllerProcessOptions c;
  c.mission_path = mission_path;
  c.policy_path = o.policy_path;
  c.controller = o.controller;
  c.vehicle_path = o.vehicle_path;
  c.speed = o.speed;
  c.trust_key = o.trust_key;
  return c;
}

/// Checks the options and what they name: refused here, before anything starts.
void check_mission_run(MissionRunOptions& o) {
  if (o.mission_path.empty()) throw std::invalid_argument("--mission FILE is required");
  if (o.controller == "pid" && !o.policy_path.empty()) {
    throw std::invalid_argument("--policy and --controller pid exclude each other");
  }
  if (o.controller == "policy" && o.policy_path.empty()) {
    throw std::invalid_argument("--policy FILE (or --controller pid) is required");
  }
  if (!(o.speed > 0)) throw std::invalid_argument("--speed must be > 0");
  const agent::Mission mission = agent::read_mission_file(o.mission_path);
  if (o.vehicle_path.empty()) {
    o.vehicle_path = mission.vehicle_path.empty() ? default_vehicle_file() : mission.vehicle_path;
  }
  o.mission_path = absolute_path(o.mission_path);
  o.vehicle_path = absolute_path(o.vehicle_path);
  o.policy_path = absolute_path(o.policy_path);
  o.trust_key = absolute_path(o.trust_key);
  // auv_controller's own checks (the policy fits the vehicle, the PID has gains).
  const agent::ControllerSetup setup =
      agent::load_controller_setup(controller_options(o, o.mission_path));
  for (const agent::MissionEvent& e : mission.events) {
    if (e.kind == agent::MissionEvent::Kind::kThrusterEfficiency &&
        e.thruster >= setup.model.num_thrusters()) {
      throw std::invalid_argument(
          fmt::format("{}: an event names thruster {} but {} has {} thrusters (0..{})",
                      o.mission_path, e.thruster, setup.model.name, setup.model.num_thrusters(),
                      setup.model.num_thrusters() - 1));
    }
  }
  if (o.run_dir.empty()) {
    o.run_dir = (fs::path(o.source_dir) / "runs" /
                 ("mission-" + file_name_part(mission.name) + "-" + run_timestamp()))
                    .string();
  }
  o.run_dir = absolute_path(o.run_dir);
}

/// README.txt: what each file of a mission run directory holds.
void write_mission_readme(const MissionRunOptions& o) {
  std::ofstream out(fs::path(o.run_dir) / "README.txt");
  out << "auvrl run directory (a mission flown by auv_controller on auv_sim --realtime)\n"
      << "  mission.yaml      a copy of " << o.mission_path << "\n"
      << "  vehicle.yaml      a copy of " << o.vehicle_path << "\n"
      << "  trajectory.csv    every state from the mission start, with the command in force and\n"
      << "                    the way-point driven to (auvrl eval --mission's trajectory format)\n"
      << "  waypoints.csv     one row per way-point, index from 0: reached, time to reach, hold\n"
      << "                    error, energy (auvrl eval --mission's mission.csv format)\n"
      << "  vehicle.csv       the vehicle and its thrusters (names for the plots)\n"
      << "  events.csv        the mission's events as applied, with their mission time\n"
      << "  report.md         the table, times, real-time factor, supervisor, events, plots\n"
      << "  plots/            mission_3d.png, mission_thrusters.png\n"
      << "  logs/             LCM event logs of all traffic (auv_log list logs/*.lcmlog)\n"
      << "  processes/        each process's output (logger, sim, controller, plots)\n"
      << "  replay-*/         what `auvrl replay --run-dir` made of logs/, compared with the run\n";
  if (!out) throw std::runtime_error("cannot write " + o.run_dir + "/README.txt");
}

}  // namespace

void prepare_mission_run(MissionRunOptions& o) {
  check_mission_run(o);
  const fs::path dir = o.run_dir;
  if (directory_in_use(o.run_dir)) {
    throw std::runtime_error(o.run_dir +
                             " already exists and is not empty: a run directory is never reused");
  }
  for (const char* sub : {"logs", "processes", "plots"}) fs::create_directories(dir / sub);
  fs::copy_file(o.mission_path, dir / "mission.yaml");
  fs::copy_file(o.vehicle_path, dir / "vehicle.yaml");  // what `auvrl replay` reads the log with
  write_mission_readme(o);
}

std::vector<std::string> mission_namespace_command(const MissionRunOptions& o) {
  std::vector<std::string> args = netns_prefix(o.source_dir, o.run_dir);
  args.insert(args.end(), {o.bin_dir + "/auvrl", "run", "--mission", o.mission_path, "--vehicle",
                           o.vehicle_path, "--speed", fmt::format("{}", o.speed), "--run-dir",
                           o.run_dir, "--bin-dir", o.bin_dir, "--prepared"});
  if (o.controller == "pid") {
    args.insert(args.end(), {"--controller", "pid"});
  } else {
    args.insert(args.end(), {"--policy", o.policy_path});
  }
  if (!o.trust_key.empty()) args.insert(args.end(), {"--trust-key", o.trust_key});
  return args;
}

int start_mission_run(MissionRunOptions options, bool host_network, std::ostream& out) {
  if (!options.prepared) {
    try {
      prepare_mission_run(options);
    } catch (const std::exception& e) {
      throw std::invalid_argument(e.what());  // refused before anything started
    }
  }
  if (host_network || in_private_namespace()) return run_mission(options, out);
  exec_in_namespace(mission_namespace_command(options));
}

namespace {

/// What ended a mission run.
struct MissionEnd {
  int exit_code = kMissionComplete;
  std::string reason;
};

/// Thrown to end the run while it starts (Ctrl-C, a process that does not come up).
struct MissionEndError : std::runtime_error {
  explicit MissionEndError(MissionEnd e) : std::runtime_error(e.reason), end(std::move(e)) {}
  MissionEnd end;
};

/// One mission run: the processes, the traffic it records and what it injects.
class MissionSession {
 public:
  MissionSession(const MissionRunOptions& options, std::ostream& out);
  int run();

 private:
  std::string log_path(const std::string& name) const {
    return (fs::path(options_.run_dir) / "processes" / (name + ".log")).string();
  }
  void subscribe();
  std::unique_ptr<Process> start(const std::string& name, const std::vector<std::string>& argv);
  /// Handles traffic until done(); throws MissionEndError on Ctrl-C, when the process `name`
  /// ends or after kStartTimeoutS.
  void wait_for(const std::function<bool()>& done, const std::string& name, Process& process);
  void start_processes();
  void place_vehicle();
  std::optional<MissionEnd> watch();
  MissionEnd controller_ended();
  void inject_due_events();
  void show_progress();
  std::string status_line() const;
  void stop_processes();
  int finish(const MissionEnd& end);

  const MissionRunOptions& options_;
  std::ostream& out_;
  const bool tty_;
  const agent::Mission mission_;
  const sim::VehicleModel model_;
  SteadyClock clock_;
  const double start_s_;
  ChildProcessStarter starter_;
  std::unique_ptr<Process> logger_, sim_, controller_;
  MissionRecorder recorder_;
  std::int64_t states_seen_ = 0;
  bool logger_heard_ = false;
  std::optional<std::int64_t> sim_faults_total_, sim_currents_total_;
  std::vector<double> efficiency_;  ///< what the faults injected so far left, per thruster
  std::size_t next_event_ = 0;
  MissionEventLog event_log_;
  double next_progress_s_ = 0;
  // Last, so that it goes first: its handlers use the members above.
  std::unique_ptr<transport::Transport> transport_;
};

MissionSession::MissionSession(const MissionRunOptions& options, std::ostream& out)
    : options_(options),
      out_(out),
      tty_(isatty(STDOUT_FILENO) != 0),
      mission_(agent::read_mission_file(options.mission_path)),
      model_(sim::load_vehicle_file(options.vehicle_path)),
      start_s_(clock_.now_s()),
      recorder_(model_.num_thrusters()),
      efficiency_(static_cast<std::size_t>(model_.num_thrusters()), 1.0),
      event_log_(mission_, model_.facts().thruster_names) {}

void MissionSession::subscribe() {
  transport_ = transport::make_transport({});
  transport::subscribe<auvrl_lcm::vehicle_state_t>(
      *transport_, channels::sim_state(kVehicleId),
      [this](const std::string&, const auvrl_lcm::vehicle_state_t& s) {
        ++states_seen_;
        recorder_.add_state(s, clock_.now_s());
      });
  transport::subscribe<auvrl_lcm::thruster_cmd_t>(
      *transport_, channels::sim_command(kVehicleId),
      [this](const std::string&, const auvrl_lcm::thruster_cmd_t& c) { recorder_.add_command(c); });
  transport::subscribe<auvrl_lcm::mission_status_t>(
      *transport_, channels::kMissionStatus,
      [this](const std::string&, const auvrl_lcm::mission_status_t& s) {
        if (s.vehicle_id == kVehicleId) recorder_.add_status(s);
      });
  // The faults as they reach the vehicle's channel (those this command injects, heard back):
  // events.csv is built from them, as `auvrl replay` builds it from the log.
  transport::subscribe<auvrl_lcm::thruster_fault_t>(
      *transport_, channels::sim_fault(kVehicleId),
      [this](const std::string& channel, const auvrl_lcm::thruster_fault_t& f) {
        for (const MissionRunEvent& e :
             event_log_.add_fault(f, recorder_.mission_time_s(), channel)) {
          out_ << (tty_ ? "\n" : "") << "auvrl run: " << e.text << "\n";
        }
      });
  transport::subscribe<auvrl_lcm::water_current_t>(
      *transport_, channels::sim_current(kVehicleId),
      [this](const std::string& channel, const auvrl_lcm::water_current_t& c) {
        const MissionRunEvent e = event_log_.add_current(c, recorder_.mission_time_s(), channel);
        out_ << (tty_ ? "\n" : "") << "auvrl run: " << e.text << "\n";
      });
  transport::subscribe<auvrl_lcm::sim_heartbeat_t>(
      *transport_, channels::kSimHeartbeat,
      [this](const std::string&, const auvrl_lcm::sim_heartbeat_t& h) {
        if (!sim_ || h.pid != sim_->pid()) return;
        sim_faults_total_ = h.faults_total;
        sim_currents_total_ = h.currents_total;
      });
  transport::subscribe<auvrl_lcm::logger_heartbeat_t>(
      *transport_, channels::kLoggerHeartbeat,
      [this](const std::string&, const auvrl_lcm::logger_heartbeat_t& h) {
        if (logger_ && h.pid == logger_->pid()) logger_heard_ = true;
      });
}

std::unique_ptr<Process> MissionSession::start(const std::string& name,
                                               const std::vector<std::string>& argv) {
  std::unique_ptr<Process> p = starter_.start(argv, log_path(name));
  std::ofstream(fs::path(options_.run_dir) / "processes" / (name + ".pid")) << p->pid() << "\n";
  return p;
}

void MissionSession::wait_for(const std::function<bool()>& done, const std::string& name,
                              Process& process) {
  const double until = clock_.now_s() + kStartTimeoutS;
  while (!done()) {
    if (signals::stop_requested()) throw MissionEndError({kMissionStopped, "stopped by the user"});
    if (!process.running()) {
      throw MissionEndError({kMissionError, fmt::format("auv_{} ended while starting (see {})",
                                                        name, log_path(name))});
    }
    if (clock_.now_s() > until) {
      throw MissionEndError(
          {kMissionError, fmt::format("auv_{} did not answer within {:g} s (see {})", name,
                                      kStartTimeoutS, log_path(name))});
    }
    transport_->handle(50);
  }
}

void MissionSession::start_processes() {
  const std::string bin = options_.bin_dir + "/";
  logger_ = start("logger", {bin + "auv_logger", "--dir", options_.run_dir + "/logs"});
  wait_for([this] { return logger_heard_; }, "logger", *logger_);  // it logs from here on
  sim_ = start("sim", {bin + "auv_sim", "--vehicle", options_.vehicle_path, "--realtime",
                       "--realtime-factor", fmt::format("{}", options_.speed)});
  place_vehicle();
  std::vector<std::string> argv = {bin + "auv_controller", "--mission", options_.mission_path};
  if (options_.controller == "pid") {
    argv.insert(argv.end(), {"--controller", "pid"});
  } else {
    argv.insert(argv.end(), {"--policy", options_.policy_path});
  }
  argv.insert(argv.end(), {"--vehicle", options_.vehicle_path, "--speed",
                           fmt::format("{}", options_.speed), "--exit-when-finished"});
  if (!options_.trust_key.empty()) argv.insert(argv.end(), {"--trust-key", options_.trust_key});
  controller_ = start("controller", argv);
  out_ << fmt::format(
      "auvrl run: mission '{}' ({} way-points, time limit {:g} s) with {} on {} at x{:g}, run "
      "{}\n  watch it: scripts/spy.sh {}\n",
      mission_.name, mission_.waypoints.size(), mission_.time_limit_s,
      options_.controller == "pid" ? std::string("the PID") : options_.policy_path, model_.name,
      options_.speed, options_.run_dir, options_.run_dir);
}

/// Puts the vehicle at the mission's start: a reset on SIM_RESET_0 until a state answers.
void MissionSession::place_vehicle() {
  auvrl_lcm::vehicle_reset_t reset{};
  reset.vehicle_id = kVehicleId;
  reset.seq = 0;  // below the controller's first command's (1): none is taken as stale
  reset.seed = 1;
  for (int i = 0; i < 3; ++i) {
    reset.position_ned_m[i] = mission_.start.position_ned_m[i];
    reset.euler_rpy_rad[i] = mission_.start.euler_rpy_rad[i];
    reset.current_constant_ned_mps[i] = event_log_.start_current_ned_mps()[i];
  }
  reset.num_thrusters = 0;  // all healthy
  reset.noise_position_m = mission_.sensor_noise.position_m;
  reset.noise_attitude_rad = mission_.sensor_noise.attitude_rad;
  reset.noise_velocity_mps = mission_.sensor_noise.velocity_mps;
  reset.noise_angular_rate_rad_s = mission_.sensor_noise.angular_rate_rad_s;
  const std::int64_t before = states_seen_;
  double next_reset_s = 0;
  wait_for(
      [&] {
        if (states_seen_ > before) return true;
        if (clock_.now_s() >= next_reset_s) {
          reset.utime = transport::now_utime();
          transport::publish(*transport_, channels::sim_reset(kVehicleId), reset);
          next_reset_s = clock_.now_s() + 0.2;
        }
        return false;
      },
      "sim", *sim_);
}

void MissionSession::inject_due_events() {
  const std::optional<double> t = recorder_.mission_time_s();
  if (!t) return;
  const std::vector<agent::MissionEvent>& events = mission_.events;
  for (; next_event_ < events.size() && events[next_event_].time_s <= *t + kTimeToleranceS;
       ++next_event_) {
    const agent::MissionEvent& e = events[next_event_];
    if (e.kind == agent::MissionEvent::Kind::kCurrent) {
      if (e.time_s == 0.0) continue;  // set with the vehicle's reset
      auvrl_lcm::water_current_t current{};
      current.utime = transport::now_utime();
      current.vehicle_id = kVehicleId;
      for (int i = 0; i < 3; ++i) current.current_constant_ned_mps[i] = e.current_ned_mps[i];
      transport::publish(*transport_, channels::sim_current(kVehicleId), current);
      continue;
    }
    efficiency_[static_cast<std::size_t>(e.thruster)] = e.efficiency;
    auvrl_lcm::thruster_fault_t fault{};
    fault.utime = transport::now_utime();
    fault.vehicle_id = kVehicleId;
    fault.num_thrusters = static_cast<std::int8_t>(efficiency_.size());
    fault.thruster_efficiency = efficiency_;
    transport::publish(*transport_, channels::sim_fault(kVehicleId), fault);
  }
}

std::string MissionSession::status_line() const {
  const auto& s = recorder_.last_status();
  const double wall_s = clock_.now_s() - start_s_;
  if (!s) return fmt::format("waiting for auv_controller  wall {:.1f} s", wall_s);
  const char* state = agent::to_string(static_cast<agent::SupervisorState>(s->supervisor_state));
  const std::string waypoint =
      s->waypoint_index >= s->waypoint_count
          ? fmt::format("way-point {} of {} done", s->waypoint_count, s->waypoint_count)
          : fmt::format("way-point {} of {}", s->waypoint_index + 1, s->waypoint_count);
  return fmt::format("{}  distance {:.2f} m  held {:.1f} s  vehicle {:.1f} s  {}{}  wall {:.1f} s",
                     waypoint, s->distance_m, s->held_s, s->elapsed_s, state,
                     s->reason.empty() ? "" : " (" + s->reason + ")", wall_s);
}

void MissionSession::show_progress() {
  const double now = clock_.now_s();
  if (now < next_progress_s_) return;
  next_progress_s_ = now + (tty_ ? 0.25 : 1.0);
  if (tty_) {
    out_ << "\r" << status_line() << "   " << std::flush;
  } else {
    out_ << status_line() << "\n";
  }
}

MissionEnd MissionSession::controller_ended() {
  transport_->drain();  // its last status
  const int status = controller_->wait_status();
  const std::string log = log_path("controller");
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    const auto& s = recorder_.last_status();
    if (s && s->waypoint_index >= s->waypoint_count) return {kMissionComplete, "mission complete"};
    if (signals::stop_requested()) return {kMissionStopped, "stopped by the user"};
    return {kMissionError,
            "auv_controller stopped before the mission was complete (see " + log + ")"};
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3) {
    const auto& s = recorder_.last_status();
    return {kMissionAborted,
            "aborted by the safety supervisor" + (s && !s->reason.empty() ? ": " + s->reason : "")};
  }
  return {kMissionError, WIFEXITED(status)
                             ? fmt::format("auv_controller exited with status {} (see {})",
                                           WEXITSTATUS(status), log)
                             : fmt::format("auv_controller ended by signal {} (see {})",
                                           WIFSIGNALED(status) ? WTERMSIG(status) : 0, log)};
}

std::optional<MissionEnd> MissionSession::watch() {
  transport_->handle(20);
  inject_due_events();
  show_progress();
  if (signals::stop_requested()) return MissionEnd{kMissionStopped, "stopped by the user"};
  if (!controller_->running()) return controller_ended();
  const std::optional<double> t = recorder_.mission_time_s();
  if (t && *t + kTimeToleranceS >= mission_.time_limit_s) {
    return MissionEnd{kMissionTimeLimit,
                      fmt::format("the mission's time limit of {:g} s (vehicle time) passed",
                                  mission_.time_limit_s)};
  }
  if (!sim_->running()) {
    return MissionEnd{kMissionError, "auv_sim ended (see " + log_path("sim") + ")"};
  }
  if (!logger_->running()) {
    return MissionEnd{kMissionError, "auv_logger ended (see " + log_path("logger") + ")"};
  }
  if (clock_.now_s() - recorder_.last_state_wall_s() > kStateSilenceS) {
    return MissionEnd{kMissionError, fmt::format("no state from auv_sim for {:g} s (see {})",
                                                 kStateSilenceS, log_path("sim"))};
  }
  return std::nullopt;
}

void MissionSession::stop_processes() {
  // The controller first (no more commands), then the simulator; the logger last, after it
  // has taken in the last messages.
  if (controller_) controller_->terminate(kControllerGraceS);
  if (sim_) sim_->terminate(kSimGraceS);
  const double until = clock_.now_s() + 0.3;
  while (clock_.now_s() < until) transport_->handle(50);
  if (logger_) logger_->terminate(kLoggerGraceS);
}

int MissionSession::finish(const MissionEnd& end) {
  MissionRunSummary s;
  s.exit_code = end.exit_code;
  s.ended = end.reason;
  s.wall_s = clock_.now_s() - start_s_;
  s.mission_wall_s = recorder_.mission_wall_s();
  const std::vector<agent::TrajectoryRow> rows = recorder_.trajectory();
  s.vehicle_time_s = rows.empty() ? 0.0 : rows.back().time_s;
  s.last_status = recorder_.last_status();
  s.events = event_log_.events();
  s.sim_faults_total = sim_faults_total_;
  s.sim_currents_total = sim_currents_total_;
  try {
    s.waypoints =
        write_mission_record(options_.run_dir, mission_, model_.facts(), recorder_, event_log_);
    s.plots_note = draw_mission_plots(options_.source_dir, options_.run_dir,
                                      fs::path(options_.run_dir).filename().string());
    write_mission_report(options_, mission_, s);
  } catch (const std::exception& e) {
    out_ << "auvrl run: " << e.what() << "\n";
    s.exit_code = kMissionError;
  }
  print_mission_summary(options_, s, out_);
  return s.exit_code;
}

int MissionSession::run() {
  signals::install_stop_handlers();
  subscribe();
  std::optional<MissionEnd> end;
  try {
    start_processes();
    while (!end) end = watch();
  } catch (const MissionEndError& e) {
    end = e.end;
  } catch (const std::exception& e) {
    end = MissionEnd{kMissionError, e.what()};
  }
  if (tty_) out_ << "\n";
  out_ << "auvrl run: " << end->reason << "; stopping\n";
  stop_processes();
  return finish(*end);
}

}  // namespace

int run_mission(const MissionRunOptions& options, std::ostream& out) {
  out << std::unitbuf;  // progress lines must reach a log file as they happen
  if (!fs::is_directory(fs::path(options.run_dir) / "processes")) {
    throw std::runtime_error(options.run_dir + " is not a prepared run directory (no processes/)");
  }
  MissionSession session(options, out);
  return session.run();
}

}  // namespace auvrl::launcher
