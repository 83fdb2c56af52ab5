#include "eval/evaluation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <ostream>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "common/csv.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"

namespace auvrl::eval {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Offsets of the fixed parts of the two layouts (see common/task/task.hpp).

const Scenario kAllScenarios[] = {Scenario::kTest1, Scenario::kTest2, Scenario::kFault,
                                  Scenario::kCurrent, Scenario::kSuite};

/// Digits of the numbers in summary.csv and the trajectories: enough to tell runs apart.
constexpr int kCsvDigits = 9;

/// -0 written as 0 (a zero pitch of a level vehicle comes out of the kinematics as -0).
double tidy(double v) { return v == 0.0 ? 0.0 : v; }

std::vector<std::string> summary_columns() {
  return {"scenario",      "controller",      "episode",
          "goal_x",        "goal_y",          "goal_z",
          "reached",       "time_to_reach_s", "mean_error_after_reach_m",
          "final_error_m", "thrust_energy",   "end_reason",
          "smoothness"};
}

std::vector<std::string> trajectory_columns(int num_thrusters) {
  std::vector<std::string> c{"t", "x", "y", "z", "phi", "theta", "psi",
                             "u", "v", "w", "p", "q",   "r"};
  for (int i = 1; i <= num_thrusters; ++i) c.push_back(fmt::format("cmd_{}", i));
  for (int i = 1; i <= num_thrusters; ++i) c.push_back(fmt::format("thrust_{}", i));
  c.push_back("distance_m");
  return c;
}

std::string joined(const std::vector<std::string>& columns) {
  std::string line;
  for (const std::string& c : columns) line += (line.empty() ? "" : ",") + c;
  return line;
}

}  // namespace

const char* to_string(Scenario scenario) {
  switch (scenario) {
    case Scenario::kTest1:
      return "test1";
    case Scenario::kTest2:
      return "test2";
    case Scenario::kFault:
      return "fault";
    case Scenario::kCurrent:
      return "current";
    case Scenario::kSuite:
      return "suite";
    case Scenario::kRobustness:
      return "robustness";
  }
  return "?";
}

std::vector<Scenario> parse_scenarios(const std::string& name) {
  if (name == "all") return {std::begin(kAllScenarios), std::end(kAllScenarios)};
  for (Scenario s : kAllScenarios) {
    if (name == to_string(s)) return {s};
  }
  throw std::invalid_argument(
      "scenario '" + name +
      "': expected test1, test2, fault, current, suite or all (auvrl eval: or robustness)");
}

const char* end_reason_name(task::EndReason reason) {
  switch (reason) {
    case task::EndReason::kNone:
      return "none";
    case task::EndReason::kReached:
      return "reached";
    case task::EndReason::kTimeLimit:
      return "time_limit";
    case task::EndReason::kLeftRegion:
      return "left_region";
    case task::EndReason::kFlipped:
      return "flipped";
    case task::EndReason::kBlowUp:
      return "blow_up";
    case task::EndReason::kSimTimeout:
      return "sim_timeout";
  }
  return "?";
}

std::vector<EvaluationEpisode> scenario_episodes(const EvaluationConfig& config,
                                                 Scenario scenario) {
  const task::TaskConfig& task = config.task;
  EvaluationEpisode base;
  base.scenario = scenario;
  base.goal_ned_m = config.test_goal_ned_m;
  base.start.position_ned_m = task.start_position_ned_m;
  base.start.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, task.start_yaw_rad);
  base.start.seed = config.seed;
  const Eigen::Vector2d line = (base.goal_ned_m - base.start.position_ned_m).head<2>();
  const double bearing_rad = std::atan2(line[1], line[0]);

  switch (scenario) {
    case Scenario::kTest1:
      return {base};
    case Scenario::kTest2:
      base.start.euler_rpy_rad[2] =
          task::yaw_facing_away_rad(base.start.position_ned_m, base.goal_ned_m);
      return {base};
    case Scenario::kFault:
      if (config.fault_thruster < 0 || config.fault_thruster >= task.num_thrusters) {
        throw std::invalid_argument("evaluation: fault thruster index " +
                                    std::to_string(config.fault_thruster) + " is not one of the " +
                                    std::to_string(task.num_thrusters) + " thrusters");
      }
      base.start.thruster_efficiency.assign(static_cast<std::size_t>(task.num_thrusters), 1.0);
      base.start.thruster_efficiency[static_cast<std::size_t>(config.fault_thruster)] =
          config.fault_efficiency;
      return {base};
    case Scenario::kCurrent: {
      // Perpendicular to the horizontal start->goal line, to its right (bearing + 90 deg).
      const double across = bearing_rad + kPi / 2.0;
      base.start.current_ned_mps =
          config.current_speed_mps * Eigen::Vector3d(std::cos(across), std::sin(across), 0.0);
      return {base};
    }
    case Scenario::kSuite: {
      if (config.suite_episodes < 0) {
        throw std::invalid_argument("evaluation: suite_episodes must be >= 0");
      }
      std::mt19937_64 rng(config.seed);
      std::vector<EvaluationEpisode> episodes;
      for (int i = 0; i < config.suite_episodes; ++i) {
        EvaluationEpisode e = base;
        e.index = i;
        e.goal_ned_m = task::sample_goal(task, rng);
        e.start.seed = config.seed + static_cast<std::uint64_t>(i);
        episodes.push_back(e);
      }
      return episodes;
    }
    case Scenario::kRobustness:
      throw std::invalid_argument(
          "evaluation: the robustness suite's episodes come from robustness_episodes "
          "(eval/robustness.hpp)");
  }
  return {};
}

double command_smoothness(const std::vector<std::vector<double>>& commands_normalised) {
  double sum = 0.0;
  std::size_t count = 0;
  const std::vector<double>* previous = nullptr;
  for (const std::vector<double>& command : commands_normalised) {
    for (std::size_t i = 0; i < command.size(); ++i) {
      const double before =
          previous && i < previous->size() ? (*previous)[i] : 0.0;  // from zero at first
      sum += std::abs(command[i] - before);
    }
    count += command.size();
    previous = &command;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

double trajectory_smoothness(const std::vector<agent::TrajectoryRow>& rows, std::size_t first,
                             double max_thrust_n) {
  // command_smoothness of the normalised commands, without copying them (the fine-tuning scores
  // every episode of its search so): the same sums in the same order.
  double sum = 0.0;
  std::size_t count = 0;
  const std::vector<double>* previous = nullptr;
  for (std::size_t r = first; r < rows.size(); ++r) {
    const std::vector<double>& command = rows[r].thrust_command_n;
    for (std::size_t i = 0; i < command.size(); ++i) {
      const double before = previous && i < previous->size() ? (*previous)[i] / max_thrust_n : 0.0;
      sum += std::abs(command[i] / max_thrust_n - before);
    }
    count += command.size();
    previous = &command;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

SummaryRow run_evaluation_episode(const sim::VehicleModel& model, const EvaluationConfig& config,
                                  agent::Controller& controller, const EvaluationEpisode& episode,
                                  std::vector<agent::TrajectoryRow>* trajectory) {
  std::unique_ptr<agent::VehicleLink> link = agent::make_in_process_link(model);
  // The commands are always recorded: the smoothness is computed from them.
  std::vector<agent::TrajectoryRow> own_trajectory;
  if (!trajectory) trajectory = &own_trajectory;
  // The reset state as the first row (run_episode records from the first step on); the
  // in-process link is deterministic, so run_episode's own reset gives the same state.
  trajectory->clear();
  const std::optional<agent::VehicleReport> first = link->reset(episode.start);
  if (first) {
    const auto n = static_cast<std::size_t>(model.num_thrusters());
    trajectory->push_back({first->time_s, first->observation, std::vector<double>(n, 0.0),
                           first->thrust_realised_n,
                           (episode.goal_ned_m - first->observation.position_ned_m).norm()});
  }
  const std::size_t first_step = trajectory->size();
  agent::EpisodeOptions options;
  options.goal_ned_m = episode.goal_ned_m;
  options.beta_m = config.reach_radius_m;
  options.start = episode.start;
  options.reach_radius_m = config.reach_radius_m;
  options.run_full_time = true;
  options.trajectory = trajectory;
  task::TaskConfig task = config.task;
  task.max_steps = config.episode_steps;
  if (episode.safety_radius_m > 0.0) task.beta_max_m = episode.safety_radius_m;
  const agent::EpisodeSummary s = agent::run_episode(task, *link, controller, options);

  SummaryRow row;
  row.scenario = episode.group.empty() ? to_string(episode.scenario) : episode.group;
  row.controller = controller.name();
  row.episode = episode.index;
  row.goal_ned_m = episode.goal_ned_m;
  row.reached = s.time_to_reach_s >= 0;
  row.time_to_reach_s = s.time_to_reach_s;
  row.mean_error_after_reach_m = row.reached ? s.mean_error_after_reach_m : -1.0;
  row.final_error_m = s.final_distance_m;
  row.thrust_energy = s.thrust_energy;
  row.end_reason = s.end_reason;
  row.smoothness = trajectory_smoothness(*trajectory, first_step, task.max_thrust_n);
  return row;
}

std::vector<SummaryRow> run_evaluation(const sim::VehicleModel& model, EvaluationConfig config,
                                       agent::Controller& controller,
                                       const std::vector<Scenario>& scenarios,
                                       const std::string& out_dir) {
  task::apply_vehicle(model.facts(), config.task);
  config.task.max_steps = config.episode_steps;  // checked here; each episode applies it
  config.task.validate();
  if (!(config.reach_radius_m > 0)) {
    throw std::invalid_argument("evaluation: reach radius must be > 0");
  }
  const std::filesystem::path dir(out_dir);
  if (!out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(dir / "trajectories", ec);
    if (ec) {
      throw std::runtime_error((dir / "trajectories").string() +
                               ": cannot create directory: " + ec.message());
    }
  }
  std::vector<SummaryRow> rows;
  std::vector<agent::TrajectoryRow> trajectory;
  for (Scenario scenario : scenarios) {
    for (const EvaluationEpisode& episode : scenario_episodes(config, scenario)) {
      const bool write_trajectory =
          !out_dir.empty() && (scenario != Scenario::kSuite || config.suite_trajectories < 0 ||
                               episode.index < config.suite_trajectories);
      rows.push_back(run_evaluation_episode(model, config, controller, episode,
                                            write_trajectory ? &trajectory : nullptr));
      if (write_trajectory) {
        const std::string name =
            std::string(to_string(scenario)) + "_" + std::to_string(episode.index) + ".csv";
        write_trajectory_csv((dir / "trajectories" / name).string(), trajectory,
                             model.num_thrusters());
      }
    }
  }
  if (!out_dir.empty()) {
    write_summary_csv((dir / "summary.csv").string(), rows);
    write_vehicle_csv((dir / "vehicle.csv").string(), model.facts());
  }
  return rows;
}

ValidationScore score_against_reference(const std::vector<SummaryRow>& rows,
                                        const std::vector<SummaryRow>& reference) {
  if (rows.size() != reference.size()) {
    throw std::invalid_argument("validation score: " + std::to_string(rows.size()) +
                                " episodes against " + std::to_string(reference.size()) +
                                " of the reference; expected the same episodes");
  }
  ValidationScore score;
  double time_sum = 0, hold_sum = 0, worst_ratio = 0, energy_sum = 0, smoothness_sum = 0;
  bool any_ratio = false;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const SummaryRow& r = rows[i];
    const SummaryRow& ref = reference[i];
    if (r.scenario != ref.scenario || r.episode != ref.episode ||
        !r.goal_ned_m.isApprox(ref.goal_ned_m)) {
      throw std::invalid_argument("validation score: episode " + std::to_string(i) + " (" +
                                  r.scenario + " " + std::to_string(r.episode) +
                                  ") is not the reference's (" + ref.scenario + " " +
                                  std::to_string(ref.episode) + ")");
    }
    ++score.episodes;
    energy_sum += r.thrust_energy;
    smoothness_sum += r.smoothness;
    if (!r.reached) continue;
    ++score.reached;
    time_sum += r.time_to_reach_s;
    hold_sum += r.mean_error_after_reach_m;
    if (ref.reached && ref.time_to_reach_s > 0.0) {
      worst_ratio = std::max(worst_ratio, r.time_to_reach_s / ref.time_to_reach_s);
      any_ratio = true;
    }
  }
  if (score.reached > 0) {
    score.mean_time_s = time_sum / score.reached;
    score.mean_hold_m = hold_sum / score.reached;
  }
  if (any_ratio) score.max_time_ratio = worst_ratio;
  if (score.episodes > 0) {
    score.mean_energy = energy_sum / score.episodes;
    score.mean_smoothness = smoothness_sum / score.episodes;
  }
  return score;
}

std::string summary_csv_header() { return joined(summary_columns()); }

void write_summary_csv(const std::string& path, const std::vector<SummaryRow>& rows) {
  csv::Writer out(path, summary_columns(), csv::Mode::kTruncate, kCsvDigits);
  for (const SummaryRow& r : rows) {
    out.cell(r.scenario).cell(r.controller).cell(r.episode);
    out.cell(r.goal_ned_m[0]).cell(r.goal_ned_m[1]).cell(r.goal_ned_m[2]).cell(r.reached);
    if (r.reached) {
      out.cell(r.time_to_reach_s).cell(r.mean_error_after_reach_m);
    } else {
      out.empty().empty();  // never reached: both cells empty
    }
    out.cell(r.final_error_m).cell(r.thrust_energy).cell(end_reason_name(r.end_reason));
    out.cell(r.smoothness);
    out.end_row();
  }
  out.flush();
}

void write_vehicle_csv(const std::string& path, const VehicleFacts& vehicle) {
  csv::Writer out(path, {"vehicle", "file", "thruster", "name", "max_thrust_n"},
                  csv::Mode::kTruncate, kCsvDigits);
  for (int i = 0; i < vehicle.num_thrusters(); ++i) {
    out.cell(vehicle.name).cell(vehicle.source_file).cell(i + 1);
    out.cell(vehicle.thruster_names[static_cast<std::size_t>(i)]).cell(vehicle.max_thrust_n());
    out.end_row();
  }
  out.flush();
}

std::string trajectory_csv_header(int num_thrusters) {
  return joined(trajectory_columns(num_thrusters));
}

void write_trajectory_csv(const std::string& path, const std::vector<agent::TrajectoryRow>& rows,
                          int num_thrusters, const std::vector<int>* waypoint_index) {
  std::vector<std::string> columns = trajectory_columns(num_thrusters);
  if (waypoint_index) {
    if (waypoint_index->size() != rows.size()) {
      throw std::invalid_argument(path + ": " + std::to_string(waypoint_index->size()) +
                                  " way-point indices for " + std::to_string(rows.size()) +
                                  " trajectory rows");
    }
    columns.push_back("waypoint");
  }
  csv::Writer out(path, columns, csv::Mode::kTruncate, kCsvDigits);
  const auto n = static_cast<std::size_t>(num_thrusters);
  std::size_t row_index = 0;
  for (const agent::TrajectoryRow& r : rows) {
    if (r.thrust_command_n.size() != n || r.thrust_realised_n.size() != n) {
      throw std::invalid_argument(path + ": a trajectory row does not have " +
                                  std::to_string(num_thrusters) + " thrusters");
    }
    const task::Observation& o = r.observation;
    out.cell(tidy(r.time_s));
    for (const Eigen::Vector3d* v :
         {&o.position_ned_m, &o.euler_rpy_rad, &o.velocity_body_mps, &o.angular_rate_body_rad_s}) {
      out.cell(tidy((*v)[0])).cell(tidy((*v)[1])).cell(tidy((*v)[2]));
    }
    for (double f : r.thrust_command_n) out.cell(tidy(f));
    for (double f : r.thrust_realised_n) out.cell(tidy(f));
    out.cell(r.distance_m);
    if (waypoint_index) out.cell((*waypoint_index)[row_index]);
    ++row_index;
    out.end_row();
  }
  out.flush();
}

std::string format_summary_table(const std::vector<SummaryRow>& rows) {
  struct Totals {
    int episodes = 0, reached = 0;
    double time = 0, hold = 0, final_error = 0, energy = 0, smoothness = 0;
    std::string controller;
  };
  std::vector<std::string> order;
  std::map<std::string, Totals> by_scenario;
  for (const SummaryRow& r : rows) {
    if (!by_scenario.count(r.scenario)) order.push_back(r.scenario);
    Totals& t = by_scenario[r.scenario];
    t.controller = r.controller;
    ++t.episodes;
    if (r.reached) {
      ++t.reached;
      t.time += r.time_to_reach_s;
      t.hold += r.mean_error_after_reach_m;
    }
    t.final_error += r.final_error_m;
    t.energy += r.thrust_energy;
    t.smoothness += r.smoothness;
  }
  std::string out =
      fmt::format("{:<9}{:<12}{:>10}{:>13}{:>14}{:>15}{:>10}{:>8}\n", "scenario", "controller",
                  "reached", "time [s]", "hold err [m]", "final err [m]", "energy", "smooth");
  for (const std::string& name : order) {
    const Totals& t = by_scenario[name];
    out += fmt::format("{:<9}{:<12}{:>10}", name, t.controller,
                       fmt::format("{}/{}", t.reached, t.episodes));
    if (t.reached > 0) {
      out += fmt::format("{:>13.1f}{:>14.2f}", t.time / t.reached, t.hold / t.reached);
    } else {
      out += fmt::format("{:>13}{:>14}", "-", "-");
    }
    out += fmt::format("{:>15.2f}{:>10.1f}{:>8.3f}\n", t.final_error / t.episodes,
                       t.energy / t.episodes, t.smoothness / t.episodes);
  }
  out +=
      "time and hold error: means over the reached episodes (reached = within 0.5 m);\n"
      "final error, energy and smoothness: means over all episodes; energy = sum over 0.1 s\n"
      "steps of the mean squared normalised thruster command; smooth = mean |change of the\n"
      "normalised command| per step and thruster.\n";
  return out;
}

std::unique_ptr<agent::Controller> make_eval_controller(const EvalRequest& request,
                                                        const sim::VehicleModel& model,
                                                        EvaluationConfig& config) {
  const int n = model.num_thrusters();
  // The vehicle's facts before the policy copies the task for its integral action (its
  // control step).
  task::apply_vehicle(model.facts(), config.task);
  if (!request.layout.empty()) config.task.layout = task::parse_layout(request.layout);
  if (request.controller == "pid") {
    if (!request.policy_path.empty()) {
      throw std::invalid_argument("--policy and --controller pid exclude each other");
    }
    return std::make_unique<agent::PidController>(model, agent::pid_gains_for(model).gains);
  }
  if (request.controller != "policy") {
    throw std::invalid_argument("--controller '" + request.controller +
                                "': expected policy (with --policy FILE) or pid");
  }
  if (request.policy_path.empty()) {
    throw std::invalid_argument("--policy FILE is required (or --controller pid)");
  }
  std::optional<task::StateLayout> layout;
  if (!request.layout.empty()) layout = config.task.layout;
  request.driving.apply(config.task);
  return agent::load_policy(request.policy_path, model.name, n, layout, config.task);
}

std::vector<SummaryRow> run_eval_request(const EvalRequest& request, std::ostream& out) {
  if (request.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
  if (request.vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  if (request.suite_episodes < 0) throw std::invalid_argument("--suite-episodes must be >= 0");
  const std::vector<Scenario> scenarios = parse_scenarios(request.scenario);
  const sim::VehicleModel model = sim::load_vehicle_file(request.vehicle_path);
  EvaluationConfig config;
  config.seed = request.seed;
  config.suite_episodes = request.suite_episodes;
  config.suite_trajectories = request.suite_trajectories;
  std::unique_ptr<agent::Controller> controller = make_eval_controller(request, model, config);
  out << "vehicle " << describe(model.facts()) << "\n";
  if (request.controller == "pid") {
    const agent::VehiclePidGains gains = agent::pid_gains_for(model);
    out << "PID gains: "
        << (gains.from_file ? gains.file : "the compiled defaults (no " + gains.file + ")") << "\n";
  }
  const std::vector<SummaryRow> rows =
      run_evaluation(model, config, *controller, scenarios, request.out_dir);
  out << format_summary_table(rows);
  out << "wrote " << (std::filesystem::path(request.out_dir) / "summary.csv").string()
      << " and trajectories/\n";
  return rows;
}

}  // namespace auvrl::eval
