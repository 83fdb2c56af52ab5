#include "launcher/mission_replay.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/wait.h>

#include <auvrl_lcm/mission_status_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <auvrl_lcm/thruster_fault_t.hpp>
#include <auvrl_lcm/vehicle_state_t.hpp>
#include <auvrl_lcm/water_current_t.hpp>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "agent/vehicle_link.hpp"
#include "common/channels.hpp"
#include "common/process.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/unrecoverable.hpp"
#include "launcher/mission_record.hpp"
#include "launcher/mission_report.hpp"
#include "launcher/namespace_exec.hpp"
#include "launcher/run_directory.hpp"
#include "launcher/supervisor.hpp"
#include "logger/event_log.hpp"
#include "logger/log_tools.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::launcher {

namespace fs = std::filesystem;

namespace {

constexpr int kVehicleId = 0;        ///< the vehicle `auvrl run` flies
constexpr double kDrainS = 0.5;      ///< after the player's end, for the last messages in flight
constexpr int kReplayError = 1;      ///< exit code: the replay or a file failed
constexpr int kReplayStopped = 130;  ///< exit code: Ctrl-C or SIGTERM
/// The files of a run that a replay writes again and compares.
const char* const kComparedFiles[] = {"trajectory.csv", "waypoints.csv", "events.csv",
                                      "vehicle.csv"};

std::vector<std::string> read_lines(const std::string& path) {
  std::vector<std::string> lines;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

/// The run's log files, in the order the logger wrote them; throws when there is none.
std::vector<std::string> run_logs(const std::string& run_dir) {
  const fs::path logs = fs::path(run_dir) / "logs";
  if (!fs::is_directory(logs)) {
    throw std::invalid_argument(run_dir + " has no logs/: not an `auvrl run` directory");
  }
  std::vector<std::string> files = logger::expand_log_paths({logs.string()});
  if (files.empty()) throw std::invalid_argument(logs.string() + " holds no *.lcmlog file");
  return files;
}

/// The vehicle file a run named in its vehicle.csv (the second cell of the first row), if any:
/// RUN/vehicle.yaml is a copy of it.
std::optional<std::string> vehicle_file_named_in(const std::string& run_dir) {
  const std::vector<std::string> lines = read_lines((fs::path(run_dir) / "vehicle.csv").string());
  if (lines.size() < 2) return std::nullopt;
  const std::vector<std::string> cells = logger::split_csv_line(lines[1]);
  if (cells.size() < 2) return std::nullopt;
  return cells[1];
}

}  // namespace

std::string compare_files(const std::string& original_path, const std::string& replayed_path) {
  const bool has_original = fs::exists(original_path), has_replayed = fs::exists(replayed_path);
  if (!has_original && !has_replayed) return "in neither";
  if (!has_original) return "missing in the run";
  if (!has_replayed) return "missing in the replay";
  const std::vector<std::string> a = read_lines(original_path), b = read_lines(replayed_path);
  std::size_t i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
  if (i == a.size() && i == b.size()) {
    return fs::file_size(original_path) == fs::file_size(replayed_path)
               ? "identical"
               : "the same lines, not the same bytes (line ends)";
  }
  return fmt::format("differs from line {} (the run has {} lines, the replay {})", i + 1, a.size(),
                     b.size());
}

void prepare_mission_replay(MissionReplayOptions& o) {
  if (o.run_dir.empty()) throw std::invalid_argument("--run-dir RUN is required");
  if (!(o.speed > 0)) throw std::invalid_argument("--speed must be > 0");
  o.run_dir = absolute_path(o.run_dir);
  run_logs(o.run_dir);
  if (!fs::exists(o.player)) {
    throw std::invalid_argument(o.player + " not found (Debian: apt install liblcm-bin)");
  }
  if (o.mission_path.empty()) o.mission_path = (fs::path(o.run_dir) / "mission.yaml").string();
  if (!fs::exists(o.mission_path)) {
    throw std::invalid_argument(o.mission_path + " not found: name the run's mission (--mission)");
  }
  const agent::Mission mission = agent::read_mission_file(o.mission_path);
  if (o.vehicle_path.empty()) {
    const fs::path copy = fs::path(o.run_dir) / "vehicle.yaml";
    o.vehicle_path = fs::exists(copy)               ? copy.string()
                     : mission.vehicle_path.empty() ? default_vehicle_file()
                                                    : mission.vehicle_path;
  }
  sim::load_vehicle_file(o.vehicle_path);  // refused here, naming the file and field
  if (o.out_dir.empty()) {
    o.out_dir = (fs::path(o.run_dir) / ("replay-" + run_timestamp())).string();
  }
  o.out_dir = absolute_path(o.out_dir);
  o.mission_path = absolute_path(o.mission_path);
  o.vehicle_path = absolute_path(o.vehicle_path);
  if (directory_in_use(o.out_dir)) {
    throw std::invalid_argument(o.out_dir +
                                " already exists and is not empty: a replay never overwrites");
  }
  for (const char* sub : {"processes", "plots"}) fs::create_directories(fs::path(o.out_dir) / sub);
}

namespace {

/// The vehicle's facts; when the vehicle is the run's copy (RUN/vehicle.yaml), under the name of
/// the file the run used (its vehicle.csv), so that the replay's vehicle.csv is the run's.
VehicleFacts replay_facts(const MissionReplayOptions& o) {
  VehicleFacts facts = sim::load_vehicle_file(o.vehicle_path).facts();
  if (fs::path(o.vehicle_path) == fs::path(o.run_dir) / "vehicle.yaml") {
    if (const auto original = vehicle_file_named_in(o.run_dir)) facts.source_file = *original;
  }
  return facts;
}

/// One replay: the listener on the bus and the player.
class ReplaySession {
 public:
  ReplaySession(const MissionReplayOptions& options, std::ostream& out)
      : options_(options),
        out_(out),
        mission_(agent::read_mission_file(options.mission_path)),
        facts_(replay_facts(options)),
        recorder_(facts_.num_thrusters()),
        event_log_(mission_, facts_.thruster_names) {}
  int run();

 private:
  void subscribe();
  /// Plays one log file; returns false when stopped by the user. Throws on a player failure.
  bool play(const std::string& file, std::size_t number, std::size_t count);
  void write_report(const std::vector<eval::MissionWaypointRow>& waypoints,
                    const std::string& plots_note,
                    const std::vector<std::pair<std::string, std::string>>& comparison) const;

  const MissionReplayOptions& options_;
  std::ostream& out_;
  const agent::Mission mission_;
  const VehicleFacts facts_;
  MissionRecorder recorder_;
  MissionEventLog event_log_;
  std::int64_t states_ = 0, commands_ = 0, statuses_ = 0, changes_ = 0;
  std::optional<std::string> wrong_vehicle_;  ///< why the log's vehicle is not the file's
  std::vector<std::string> player_commands_;
  SteadyClock clock_;
  std::unique_ptr<transport::Transport> transport_;  // last: its handlers use the members above
};

void ReplaySession::subscribe() {
  transport_ = transport::make_transport({});
  transport::subscribe<auvrl_lcm::vehicle_state_t>(
      *transport_, channels::sim_state(kVehicleId),
      [this](const std::string& channel, const auvrl_lcm::vehicle_state_t& s) {
        if (states_++ == 0) {
          try {
            agent::expect_vehicle(facts_, s, "auvrl replay (" + options_.vehicle_path + ")",
                                  "the log's " + channel);
          } catch (const UnrecoverableFault& e) {
            wrong_vehicle_ = e.what();
          }
        }
        recorder_.add_state(s, clock_.now_s());
      });
  transport::subscribe<auvrl_lcm::thruster_cmd_t>(
      *transport_, channels::sim_command(kVehicleId),
      [this](const std::string&, const auvrl_lcm::thruster_cmd_t& c) {
        ++commands_;
        recorder_.add_command(c);
      });
  transport::subscribe<auvrl_lcm::mission_status_t>(
      *transport_, channels::kMissionStatus,
      [this](const std::string&, const auvrl_lcm::mission_status_t& s) {
        if (s.vehicle_id != kVehicleId) return;
        ++statuses_;
        recorder_.add_status(s);
      });
  transport::subscribe<auvrl_lcm::thruster_fault_t>(
      *transport_, channels::sim_fault(kVehicleId),
      [this](const std::string& channel, const auvrl_lcm::thruster_fault_t& f) {
        ++changes_;
        for (const MissionRunEvent& e :
             event_log_.add_fault(f, recorder_.mission_time_s(), channel)) {
          out_ << "auvrl replay: " << e.text << "\n";
        }
      });
  transport::subscribe<auvrl_lcm::water_current_t>(
      *transport_, channels::sim_current(kVehicleId),
      [this](const std::string& channel, const auvrl_lcm::water_current_t& c) {
        ++changes_;
        out_ << "auvrl replay: "
             << event_log_.add_current(c, recorder_.mission_time_s(), channel).text << "\n";
      });
}

bool ReplaySession::play(const std::string& file, std::size_t number, std::size_t count) {
  const std::vector<std::string> argv = {
      options_.player, fmt::format("--speed={:g}", options_.speed),
      std::string("--lcm-url=") + transport::kDefaultLcmUrl, file};
  player_commands_.push_back(fmt::format("{}", fmt::join(argv, " ")));
  out_ << fmt::format("auvrl replay: playing {} ({} of {}): {}\n", file, number, count,
                      player_commands_.back());
  const std::string log = (fs::path(options_.out_dir) / "processes" / "player.log").string();
  process::ChildProcess player(argv, log, /*append_log=*/number > 1);
  while (player.running()) {
    if (signals::stop_requested()) return false;  // the destructor ends the player
    transport_->handle(20);
  }
  const int status = player.wait_for_exit(std::chrono::milliseconds(0));
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw std::runtime_error(fmt::format("{} failed on {} (wait status {}, see {})",
                                         options_.player, file, status, log));
  }
  return true;
}

int ReplaySession::run() {
  signals::install_stop_handlers();
  subscribe();
  const std::vector<std::string> files = run_logs(options_.run_dir);
  try {
    for (std::size_t i = 0; i < files.size(); ++i) {
      if (!play(files[i], i + 1, files.size())) {
        out_ << "auvrl replay: stopped by the user; nothing written\n";
        return kReplayStopped;
      }
    }
  } catch (const std::exception& e) {
    out_ << "auvrl replay: " << e.what() << "\n";
    return kReplayError;
  }
  const double until = clock_.now_s() + kDrainS;
  while (clock_.now_s() < until) transport_->handle(50);
  out_ << fmt::format(
      "auvrl replay: heard {} states, {} commands, {} MISSION_STATUS, {} fault and current "
      "messages\n",
      states_, commands_, statuses_, changes_);
  if (wrong_vehicle_) {
    out_ << "auvrl replay: " << *wrong_vehicle_ << "\n";
    return kReplayError;
  }
  try {
    const auto waypoints =
        write_mission_record(options_.out_dir, mission_, facts_, recorder_, event_log_);
    const std::string plots_note = draw_mission_plots(
        options_.source_dir, options_.out_dir, fs::path(options_.run_dir).filename().string());
    std::vector<std::pair<std::string, std::string>> comparison;
    for (const char* name : kComparedFiles) {
      comparison.emplace_back(name, compare_files((fs::path(options_.run_dir) / name).string(),
                                                  (fs::path(options_.out_dir) / name).string()));
    }
    write_report(waypoints, plots_note, comparison);
    out_ << "\n"
         << format_waypoint_table(waypoints) << "\ncompared with " << options_.run_dir << ":\n";
    for (const auto& [name, result] : comparison) out_ << "  " << name << ": " << result << "\n";
    if (!plots_note.empty()) out_ << plots_note << "\n";
    out_ << "report: " << (fs::path(options_.out_dir) / "report.md").string() << "\n";
  } catch (const std::exception& e) {
    out_ << "auvrl replay: " << e.what() << "\n";
    return kReplayError;
  }
  return 0;
}

void ReplaySession::write_report(
    const std::vector<eval::MissionWaypointRow>& waypoints, const std::string& plots_note,
    const std::vector<std::pair<std::string, std::string>>& comparison) const {
  const std::string path = (fs::path(options_.out_dir) / "report.md").string();
  std::ofstream md(path);
  md << "# Replay of " << options_.run_dir << "\n\n"
     << "- mission: " << options_.mission_path << " ('" << mission_.name << "')\n"
     << "- vehicle: " << options_.vehicle_path << "\n"
     << "- heard: " << states_ << " states, " << commands_ << " commands, " << statuses_
     << " MISSION_STATUS, " << changes_ << " fault and current messages\n"
     << "- played in a private network namespace:\n\n```\n";
  for (const std::string& command : player_commands_) md << command << "\n";
  md << "```\n\n## Way-points\n\n" << format_waypoint_table(waypoints) << "\n## Events\n\n";
  if (event_log_.events().empty()) md << "None.\n";
  for (const MissionRunEvent& e : event_log_.events()) md << "- " << e.text << "\n";
  md << "\n## Compared with the run\n\n| file | |\n|---|---|\n";
  for (const auto& [name, result] : comparison) md << "| " << name << " | " << result << " |\n";
  md << "\n";
  write_plots_section(md, plots_note);
  md.flush();
  if (!md) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int start_mission_replay(MissionReplayOptions options, bool host_network, std::ostream& out) {
  if (!options.prepared) prepare_mission_replay(options);
  if (!host_network && !in_private_namespace()) {
    std::vector<std::string> args = netns_prefix(options.source_dir, options.out_dir);
    args.insert(args.end(), {options.bin_dir + "/auvrl", "replay", "--run-dir", options.run_dir,
                             "--out", options.out_dir, "--speed", fmt::format("{}", options.speed),
                             "--mission", options.mission_path, "--vehicle", options.vehicle_path,
                             "--player", options.player, "--prepared"});
    exec_in_namespace(args);
  }
  out << std::unitbuf;
  ReplaySession session(options, out);
  return session.run();
}

}  // namespace auvrl::launcher
