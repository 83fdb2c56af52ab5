#include "eval/mission_run.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>

#include "agent/pid_gains.hpp"
#include "agent/vehicle_link.hpp"
#include "common/csv.hpp"

namespace auvrl::eval {
namespace {

/// Digits of the numbers in mission.csv (as summary.csv).
constexpr int kCsvDigits = 9;
/// Event times and step times are sums of control steps: 10 s may come out as 9.9999999999.
constexpr double kTimeToleranceS = 1e-9;

/// A report the controller can use (as run_episode requires).
bool usable(const agent::VehicleReport& r) {
  const task::Observation& o = r.observation;
  return !r.blown_up && o.position_ned_m.allFinite() && o.euler_rpy_rad.allFinite() &&
         o.velocity_body_mps.allFinite() && o.angular_rate_body_rad_s.allFinite();
}

/// Every event's thruster must be one of the vehicle's.
void check_events(const agent::Mission& mission, int num_thrusters) {
  for (std::size_t i = 0; i < mission.events.size(); ++i) {
    const agent::MissionEvent& e = mission.events[i];
    if (e.kind == agent::MissionEvent::Kind::kThrusterEfficiency &&
        (e.thruster < 0 || e.thruster >= num_thrusters)) {
      throw std::invalid_argument(fmt::format(
          "mission {}: an event at {} s names thruster {}, the vehicle has thrusters 0..{}",
          mission.source_file.empty() ? mission.name : mission.source_file, e.time_s, e.thruster,
          num_thrusters - 1));
    }
  }
}

/// The mission's timed events, applied to a running vehicle as their times come.
class EventPlayer {
 public:
  EventPlayer(const agent::Mission& mission, int num_thrusters)
      : events_(mission.events), efficiency_(static_cast<std::size_t>(num_thrusters), 1.0) {}

  /// The start with every event due at time 0 in it (a fault from the start, as the
  /// evaluation's fault scenario sets it at the reset).
  agent::EpisodeStart start(const agent::Mission& mission, std::uint64_t seed) {
    agent::EpisodeStart start;
    start.position_ned_m = mission.start.position_ned_m;
    start.euler_rpy_rad = mission.start.euler_rpy_rad;
    start.sensor_noise.position_sigma_m = mission.sensor_noise.position_m;
    start.sensor_noise.attitude_sigma_rad = mission.sensor_noise.attitude_rad;
    start.sensor_noise.linear_velocity_sigma_mps = mission.sensor_noise.velocity_mps;
    start.sensor_noise.angular_velocity_sigma_rad_s = mission.sensor_noise.angular_rate_rad_s;
    start.seed = seed;
    bool fault = false;
    for (; next_ < events_.size() && events_[next_].time_s <= kTimeToleranceS; ++next_) {
      fault |= record(events_[next_]);
      if (events_[next_].kind == agent::MissionEvent::Kind::kCurrent) {
        start.current_ned_mps = events_[next_].current_ned_mps;
      }
    }
    if (fault) start.thruster_efficiency = efficiency_;
    return start;
  }

  /// Applies the events due by time_s (s since the start) to the vehicle.
  void apply_due(double time_s, agent::VehicleLink& link) {
    for (; next_ < events_.size() && events_[next_].time_s <= time_s + kTimeToleranceS; ++next_) {
      const agent::MissionEvent& e = events_[next_];
      const bool applied = record(e) ? link.set_thruster_efficiency(efficiency_)
                                     : link.set_current(e.current_ned_mps);
      if (!applied) {
        throw std::runtime_error(fmt::format("this vehicle link cannot apply the {} event at {} s",
                                             agent::to_string(e.kind), e.time_s));
      }
    }
  }

 private:
  /// Notes a thruster event's efficiency; true for a thruster event.
  bool record(const agent::MissionEvent& e) {
    if (e.kind != agent::MissionEvent::Kind::kThrusterEfficiency) return false;
    efficiency_[static_cast<std::size_t>(e.thruster)] = e.efficiency;
    return true;
  }

  const std::vector<agent::MissionEvent>& events_;
  std::vector<double> efficiency_;
  std::size_t next_ = 0;
};

/// The outcome's rows from the tracker.
void fill_rows(const agent::MissionTracker& tracker, const std::vector<double>& energy,
               MissionOutcome& outcome) {
  outcome.waypoints.clear();
  outcome.completed = 0;
  for (int i = 0; i < tracker.count(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    outcome.waypoints.push_back({i, tracker.waypoints()[k], tracker.results()[k], energy[k]});
    if (tracker.results()[k].reached) ++outcome.completed;
  }
}

/// The row of a trajectory for a report.
agent::TrajectoryRow trajectory_row(const agent::VehicleReport& report,
                                    const std::vector<double>& thrust_command_n,
                                    const Eigen::Vector3d& goal_ned_m) {
  return {report.time_s, report.observation, thrust_command_n, report.thrust_realised_n,
          (goal_ned_m - report.observation.position_ned_m).norm()};
}

}  // namespace

const char* to_string(MissionEnd end) {
  switch (end) {
    case MissionEnd::kCompleted:
      return "completed";
    case MissionEnd::kTimeLimit:
      return "time_limit";
    case MissionEnd::kLimitViolation:
      return "limit_violation";
    case MissionEnd::kBlowUp:
      return "blow_up";
    case MissionEnd::kSimTimeout:
      return "sim_timeout";
  }
  return "?";
}

MissionOutcome run_mission(const sim::VehicleModel& model, task::TaskConfig task,
                           agent::Controller& controller, const agent::Mission& mission,
                           std::uint64_t seed, MissionTrajectory* trajectory) {
  task::apply_vehicle(model.facts(), task);
  const int n = model.num_thrusters();
  check_events(mission, n);
  agent::MissionTracker tracker(mission.waypoints);
  std::vector<double> energy(mission.waypoints.size(), 0.0);
  MissionOutcome outcome;
  outcome.mission = mission.name;
  outcome.controller = controller.name();
  if (trajectory) *trajectory = {};

  EventPlayer events(mission, n);
  std::unique_ptr<agent::VehicleLink> link = agent::make_in_process_link(model);
  controller.reset();
  std::optional<agent::VehicleReport> report = link->reset(events.start(mission, seed));
  std::vector<double> thrust_n(static_cast<std::size_t>(n), 0.0);
  const auto finish = [&](MissionEnd end, double time_s) {
    outcome.end = end;
    outcome.end_time_s = time_s;
    fill_rows(tracker, energy, outcome);
    return outcome;
  };
  if (!report) return finish(MissionEnd::kSimTimeout, 0.0);
  if (!usable(*report)) return finish(MissionEnd::kBlowUp, 0.0);
  tracker.update(0.0, report->observation.position_ned_m);
  if (trajectory) {
    trajectory->rows.push_back(
        trajectory_row(*report, thrust_n, mission.waypoints[0].position_ned_m));
    trajectory->waypoint_index.push_back(0);
  }
  if (auto violation = agent::check_limits(mission, report->observation)) {
    outcome.abort_reason = *violation;
    return finish(MissionEnd::kLimitViolation, 0.0);
  }

  const double dt = task.control_step_s;
  const int max_steps = static_cast<int>(std::ceil(mission.time_limit_s / dt - kTimeToleranceS));
  task::ActionVector previous_action = task::ActionVector::Zero(n);
  task::ActionVector action(n);
  task::StateVector state;
  for (int k = 1; k <= max_steps && !tracker.done(); ++k) {
    events.apply_due((k - 1) * dt, *link);
    const int index = tracker.index();
    const Eigen::Vector3d goal = tracker.goal_ned_m();
    task::build_state(task, report->observation, goal, previous_action, state,
                      report->thrust_realised_n);
    controller.act(report->observation, goal, state, action);
    for (int i = 0; i < n; ++i) {
      thrust_n[static_cast<std::size_t>(i)] = static_cast<double>(action[i]) * task.max_thrust_n;
    }
    report = link->step(thrust_n);
    if (!report) return finish(MissionEnd::kSimTimeout, k * dt);
    if (!usable(*report)) return finish(MissionEnd::kBlowUp, k * dt);
    energy[static_cast<std::size_t>(index)] += static_cast<double>(action.squaredNorm()) / n;
    previous_action = action;
    tracker.update(k * dt, report->observation.position_ned_m);
    if (trajectory) {
      trajectory->rows.push_back(trajectory_row(*report, thrust_n, goal));
      trajectory->waypoint_index.push_back(index);
    }
    if (auto violation = agent::check_limits(mission, report->observation)) {
      outcome.abort_reason = *violation;
      return finish(MissionEnd::kLimitViolation, k * dt);
    }
  }
  return finish(tracker.done() ? MissionEnd::kCompleted : MissionEnd::kTimeLimit,
                tracker.elapsed_s());
}

std::string mission_csv_header() {
  return "index,x,y,z,reached,time_to_reach_s,time_from_previous_s,completed_s,hold_error_m,"
         "energy";
}

void write_mission_csv(const std::string& path, const MissionOutcome& outcome) {
  csv::Writer out(path,
                  {"index", "x", "y", "z", "reached", "time_to_reach_s", "time_from_previous_s",
                   "completed_s", "hold_error_m", "energy"},
                  csv::Mode::kTruncate, kCsvDigits);
  const auto time_cell = [&out](double value) {
    if (value < 0) {
      out.empty();
    } else {
      out.cell(value);
    }
  };
  for (const MissionWaypointRow& row : outcome.waypoints) {
    const Eigen::Vector3d& p = row.waypoint.position_ned_m;
    out.cell(row.index).cell(p.x()).cell(p.y()).cell(p.z()).cell(row.result.reached);
    time_cell(row.result.time_to_reach_s);
    time_cell(row.result.time_from_previous_s);
    time_cell(row.result.completed_time_s);
    time_cell(row.result.hold_error_m);
    out.cell(row.thrust_energy);
    out.end_row();
  }
  out.flush();
}

std::string format_mission_table(const MissionOutcome& outcome) {
  std::string text = fmt::format("mission {}, controller {}: {} after {:.1f} s, {}/{} way-points",
                                 outcome.mission, outcome.controller, to_string(outcome.end),
                                 outcome.end_time_s, outcome.completed, outcome.waypoints.size());
  if (!outcome.abort_reason.empty()) text += " (" + outcome.abort_reason + ")";
  text += "\n";
  text +=
      fmt::format("{:>3}{:>7}{:>7}{:>7}{:>9}{:>10}{:>11}{:>12}{:>14}{:>9}\n", "wp", "x", "y", "z",
                  "reached", "time [s]", "from prev", "done at [s]", "hold err [m]", "energy");
  const auto cell = [](double value, int width, int decimals) {
    return value < 0 ? fmt::format("{:>{}}", "-", width)
                     : fmt::format("{:>{}.{}f}", value, width, decimals);
  };
  for (const MissionWaypointRow& row : outcome.waypoints) {
    const Eigen::Vector3d& p = row.waypoint.position_ned_m;
    const agent::WaypointResult& r = row.result;
    text += fmt::format("{:>3}{:>7.1f}{:>7.1f}{:>7.1f}{:>9}", row.index, p.x(), p.y(), p.z(),
                        r.reached ? "yes" : "no");
    text += cell(r.time_to_reach_s, 10, 1) + cell(r.time_from_previous_s, 11, 1) +
            cell(r.completed_time_s, 12, 1) + cell(r.hold_error_m, 14, 2) +
            fmt::format("{:>9.1f}\n", row.thrust_energy);
  }
  text +=
      "time: first arrival within the way-point's radius, s since the mission start; from "
      "prev:\nthe same from the previous way-point's completion; hold error: mean distance "
      "from the\narrival to its completion; energy: sum over 0.1 s steps of the mean squared "
      "normalised\nthruster command while it was the current way-point.\n";
  return text;
}

MissionOutcome run_mission_request(const EvalRequest& request, std::ostream& out) {
  if (request.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
  if (request.scenario != "all") {
    throw std::invalid_argument("--mission and --scenario exclude each other");
  }
  const agent::Mission mission = agent::read_mission_file(request.mission_path);
  std::string vehicle_path = request.vehicle_path;
  std::string vehicle_source = "the default (the mission names no vehicle)";
  if (request.vehicle_given) {
    vehicle_source = mission.vehicle_path.empty()
                         ? "--vehicle"
                         : "--vehicle (in place of the mission's " + mission.vehicle_path + ")";
  } else if (!mission.vehicle_path.empty()) {
    vehicle_path = mission.vehicle_path;
    vehicle_source = "the mission's vehicle:";
  }
  if (vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  const sim::VehicleModel model = sim::load_vehicle_file(vehicle_path);
  EvaluationConfig config;
  std::unique_ptr<agent::Controller> controller = make_eval_controller(request, model, config);
  out << fmt::format("mission {} ({}): {} way-point(s), {} event(s), time limit {} s\n",
                     mission.name, mission.source_file, mission.waypoints.size(),
                     mission.events.size(), mission.time_limit_s);
  out << "vehicle " << describe(model.facts()) << ", from " << vehicle_source << "\n";
  if (request.controller == "pid") {
    const agent::VehiclePidGains gains = agent::pid_gains_for(model);
    out << "PID gains: "
        << (gains.from_file ? gains.file : "the compiled defaults (no " + gains.file + ")") << "\n";
  }
  const std::filesystem::path dir(request.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir.string() + ": cannot create directory: " + ec.message());

  MissionTrajectory trajectory;
  const MissionOutcome outcome =
      run_mission(model, config.task, *controller, mission, request.seed, &trajectory);
  write_mission_csv((dir / "mission.csv").string(), outcome);
  write_trajectory_csv((dir / "trajectory.csv").string(), trajectory.rows, model.num_thrusters(),
                       &trajectory.waypoint_index);
  write_vehicle_csv((dir / "vehicle.csv").string(), model.facts());
  out << format_mission_table(outcome);
  out << "wrote " << (dir / "mission.csv").string() << ", trajectory.csv and vehicle.csv\n";
  return outcome;
}

}  // namespace auvrl::eval
