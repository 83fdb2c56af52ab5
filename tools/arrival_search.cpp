#include "tools/arrival_search.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <ostream>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "agent/vehicle_link.hpp"
#include "common/csv.hpp"
#include "common/random.hpp"

namespace auvrl::tools {

void ArrivalSearchConfig::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("arrival search: " + what);
  };
  require(steps_per_segment >= 1, "steps_per_segment must be >= 1");
  require(population >= 2, "population must be >= 2");
  require(elites >= 1 && elites < population, "elites must be >= 1 and below the population");
  require(iterations >= 0, "iterations must be >= 0");
  require(std::isfinite(initial_sigma) && initial_sigma > 0, "initial_sigma must be > 0");
  require(std::isfinite(min_sigma) && min_sigma > 0, "min_sigma must be > 0");
  require(std::isfinite(smoothing) && smoothing >= 0 && smoothing < 1,
          "smoothing must be in [0, 1)");
  require(extra_steps >= 0, "extra_steps must be >= 0");
  require(std::isfinite(stay_within_m), "stay_within_m must be finite");
  require(stay_steps >= 1, "stay_steps must be >= 1");
}

namespace {

/// The evaluation's config as run_evaluation completes it from the model.
eval::EvaluationConfig completed(eval::EvaluationConfig config, const sim::VehicleModel& model) {
  task::apply_vehicle(model.facts(), config.task);
  config.task.max_steps = config.episode_steps;
  config.task.validate();
  return config;
}

int arrival_step(const eval::SummaryRow& row, double control_step_s) {
  return row.reached ? static_cast<int>(std::lround(row.time_to_reach_s / control_step_s)) : -1;
}

/// One open-loop run of segment commands (rows: segments, columns: thrusters, normalised):
/// the arrival step (-1: none within the horizon), the closest approach (the distance at
/// arrival if it arrived) and, when it ran on after arriving, the farthest distance then.
struct Rollout {
  int arrival_step = -1;
  double closest_m = 0.0;
  double farthest_after_m = -1.0;
};

class RolloutRunner {
 public:
  RolloutRunner(const sim::VehicleModel& model, const eval::EvaluationConfig& config,
                const eval::EvaluationEpisode& episode, int steps_per_segment)
      : link_(agent::make_in_process_link(model)),
        episode_(episode),
        radius_m_(config.reach_radius_m),
        max_thrust_n_(config.task.max_thrust_n),
        steps_per_segment_(steps_per_segment),
        thrust_n_(static_cast<std::size_t>(model.num_thrusters())) {}

  /// Runs to the arrival, then stay_steps more (0: stops on arrival).
  Rollout run(const Eigen::MatrixXd& segments, int horizon_steps, int stay_steps) {
    Rollout r;
    std::optional<agent::VehicleReport> report = link_->reset(episode_.start);
    if (!report) throw std::runtime_error("arrival search: the in-process vehicle did not reset");
    r.closest_m = (episode_.goal_ned_m - report->observation.position_ned_m).norm();
    for (int t = 1; t <= horizon_steps + stay_steps; ++t) {
      if (r.arrival_step < 0 && t > horizon_steps) break;
      if (r.arrival_step > 0 && t > r.arrival_step + stay_steps) break;
      const Eigen::Index seg =
          std::min<Eigen::Index>((t - 1) / steps_per_segment_, segments.rows() - 1);
      for (Eigen::Index i = 0; i < segments.cols(); ++i) {
        thrust_n_[static_cast<std::size_t>(i)] = segments(seg, i) * max_thrust_n_;
      }
      report = link_->step(thrust_n_);
      if (!report || report->blown_up) {  // a blown-up run arrives nowhere
        r.arrival_step = -1;
        return r;
      }
      const double d = (episode_.goal_ned_m - report->observation.position_ned_m).norm();
      if (r.arrival_step > 0) {
        r.farthest_after_m = std::max(r.farthest_after_m, d);
        continue;
      }
      r.closest_m = std::min(r.closest_m, d);
      if (d <= radius_m_) {
        r.arrival_step = t;
        r.closest_m = d;
        if (stay_steps == 0) return r;
        r.farthest_after_m = d;
      }
    }
    return r;
  }

 private:
  std::unique_ptr<agent::VehicleLink> link_;
  eval::EvaluationEpisode episode_;
  double radius_m_;
  double max_thrust_n_;
  int steps_per_segment_;
  std::vector<double> thrust_n_;
};

/// Lower is better: the arrival step, a little more the nearer the radius it arrived (a
/// tie-break towards margin). Not arriving, or (with stay_within_m > 0) not staying, ranks
/// after every arrival that counts, by how far it missed.
double cost(const Rollout& r, int horizon_steps, double radius_m, double stay_within_m) {
  if (r.arrival_step > 0) {
    if (stay_within_m > 0 && r.farthest_after_m > stay_within_m) {
      return horizon_steps + 1.0 + 10.0 * (r.farthest_after_m - stay_within_m);
    }
    return r.arrival_step + 0.01 * (r.closest_m / radius_m);
  }
  return horizon_steps + 1.0 + 10.0 * (r.closest_m - radius_m);
}

/// The search's start: the PID's commands (trajectory row t holds the command of step t),
/// normalised and averaged over each segment of `steps_per_segment` steps, for `steps` steps.
Eigen::MatrixXd segment_means(const std::vector<agent::TrajectoryRow>& pid_trajectory, int steps,
                              int segments, int steps_per_segment, int num_thrusters,
                              double max_thrust_n) {
  Eigen::MatrixXd mean = Eigen::MatrixXd::Zero(segments, num_thrusters);
  Eigen::VectorXi count = Eigen::VectorXi::Zero(segments);
  for (int t = 1; t <= steps && t < static_cast<int>(pid_trajectory.size()); ++t) {
    const int s = (t - 1) / steps_per_segment;
    for (int i = 0; i < num_thrusters; ++i) {
      mean(s, i) += pid_trajectory[static_cast<std::size_t>(t)]
                        .thrust_command_n[static_cast<std::size_t>(i)] /
                    max_thrust_n;
    }
    ++count[s];
  }
  for (int s = 0; s < segments; ++s) {
    if (count[s] > 0) mean.row(s) /= count[s];
  }
  return mean;
}

/// The cross-entropy method's update: the sampling mean and spread move towards those of the
/// `search.elites` best samples (`ranked` in order, best first), smoothed, the spread kept at
/// least search.min_sigma.
void refit_to_elites(const std::vector<Eigen::MatrixXd>& samples,
                     const std::vector<std::pair<double, int>>& ranked,
                     const ArrivalSearchConfig& search, Eigen::MatrixXd& mean,
                     Eigen::MatrixXd& sigma) {
  const auto elite = [&](int e) -> const Eigen::MatrixXd& {
    return samples[static_cast<std::size_t>(ranked[static_cast<std::size_t>(e)].second)];
  };
  Eigen::MatrixXd elite_mean = Eigen::MatrixXd::Zero(mean.rows(), mean.cols());
  for (int e = 0; e < search.elites; ++e) elite_mean += elite(e);
  elite_mean /= search.elites;
  Eigen::MatrixXd elite_var = Eigen::MatrixXd::Zero(mean.rows(), mean.cols());
  for (int e = 0; e < search.elites; ++e) {
    elite_var += (elite(e) - elite_mean).array().square().matrix();
  }
  elite_var /= search.elites;
  mean = (1.0 - search.smoothing) * elite_mean + search.smoothing * mean;
  sigma = ((1.0 - search.smoothing) * elite_var.array().sqrt() + search.smoothing * sigma.array())
              .max(search.min_sigma)
              .matrix();
}

}  // namespace

ArrivalSearchResult search_fastest_arrival(
    const sim::VehicleModel& model, const eval::EvaluationConfig& config_in,
    const eval::EvaluationEpisode& episode, const ArrivalSearchConfig& search,
    const std::function<void(int iteration, int best_step)>& progress) {
  search.validate();
  const eval::EvaluationConfig config = completed(config_in, model);
  const int n = model.num_thrusters();
  const double dt = config.task.control_step_s;

  ArrivalSearchResult result;
  agent::PidController pid(model, agent::pid_gains_for(model).gains);
  std::vector<agent::TrajectoryRow> pid_trajectory;
  const eval::SummaryRow pid_row =
      eval::run_evaluation_episode(model, config, pid, episode, &pid_trajectory);
  result.pid_arrival_step = arrival_step(pid_row, dt);
  if (result.pid_arrival_step < 0) {
    throw std::runtime_error(std::string("arrival search: the PID baseline never reaches the ") +
                             to_string(episode.scenario) +
                             " way-point, so there are no commands to start from");
  }
  const int horizon = result.pid_arrival_step + search.extra_steps;
  const int stay = search.stay_within_m > 0 ? search.stay_steps : 0;
  const int segments = (horizon + stay + search.steps_per_segment - 1) / search.steps_per_segment;

  Eigen::MatrixXd mean = segment_means(pid_trajectory, horizon + stay, segments,
                                       search.steps_per_segment, n, config.task.max_thrust_n);

  RolloutRunner runner(model, config, episode, search.steps_per_segment);
  auto cost_of = [&](const Rollout& r) {
    return cost(r, horizon, config.reach_radius_m, search.stay_within_m);
  };
  // The arrival step of a run if it counts (arrived, and stayed where asked), else -1.
  auto counted_step = [&](const Rollout& r) {
    return cost_of(r) < horizon + 1.0 ? r.arrival_step : -1;
  };
  Rollout best_rollout = runner.run(mean, horizon, stay);
  result.start_arrival_step = counted_step(best_rollout);
  Eigen::MatrixXd best = mean;
  double best_cost = cost_of(best_rollout);

  Eigen::MatrixXd sigma = Eigen::MatrixXd::Constant(segments, n, search.initial_sigma);
  draw::Engine rng(search.seed);
  std::vector<Eigen::MatrixXd> samples(static_cast<std::size_t>(search.population));
  std::vector<std::pair<double, int>> ranked(static_cast<std::size_t>(search.population));
  std::vector<Rollout> rollouts(static_cast<std::size_t>(search.population));
  for (int it = 0; it < search.iterations; ++it) {
    for (int p = 0; p < search.population; ++p) {
      Eigen::MatrixXd& x = samples[static_cast<std::size_t>(p)];
      if (p == 0) {
        x = best;  // the best so far competes again (elitism): the result never gets worse
      } else {
        x.resize(segments, n);
        for (int s = 0; s < segments; ++s) {
          for (int i = 0; i < n; ++i) {
            x(s, i) = std::clamp(mean(s, i) + sigma(s, i) * draw::standard_normal(rng), -1.0, 1.0);
          }
        }
      }
      rollouts[static_cast<std::size_t>(p)] = runner.run(x, horizon, stay);
      ranked[static_cast<std::size_t>(p)] = {cost_of(rollouts[static_cast<std::size_t>(p)]), p};
    }
    std::sort(ranked.begin(), ranked.end());
    const int top = ranked.front().second;
    if (ranked.front().first < best_cost) {
      best_cost = ranked.front().first;
      best = samples[static_cast<std::size_t>(top)];
      best_rollout = rollouts[static_cast<std::size_t>(top)];
    }
    refit_to_elites(samples, ranked, search, mean, sigma);
    result.best_so_far_step.push_back(counted_step(best_rollout));
    result.iteration_best_step.push_back(counted_step(rollouts[static_cast<std::size_t>(top)]));
    if (progress) progress(it, counted_step(best_rollout));
  }

  result.best_arrival_step = counted_step(best_rollout);
  if (result.best_arrival_step > 0) {
    result.best_farthest_after_m = stay > 0 ? best_rollout.farthest_after_m : -1.0;
    for (int t = 1; t <= result.best_arrival_step + stay; ++t) {
      result.commands.push_back(best.row((t - 1) / search.steps_per_segment).transpose());
    }
  }
  return result;
}

OpenLoopController::OpenLoopController(std::vector<Eigen::VectorXd> commands, int num_thrusters,
                                       std::unique_ptr<agent::Controller> after)
    : commands_(std::move(commands)), num_thrusters_(num_thrusters), after_(std::move(after)) {
  if (!after_) throw std::invalid_argument("OpenLoopController: no controller to hand over to");
  for (std::size_t t = 0; t < commands_.size(); ++t) {
    if (commands_[t].size() != num_thrusters_) {
      throw std::invalid_argument("OpenLoopController: command " + std::to_string(t) + " has " +
                                  std::to_string(commands_[t].size()) + " values, expected " +
                                  std::to_string(num_thrusters_));
    }
  }
}

void OpenLoopController::reset() {
  next_ = 0;
  after_->reset();
}

void OpenLoopController::act(const task::Observation& observation,
                             const Eigen::Vector3d& goal_ned_m, const task::StateVector& state,
                             task::ActionVector& action) {
  if (next_ < commands_.size()) {
    action = commands_[next_++].cwiseMax(-1.0).cwiseMin(1.0).cast<float>();
    return;
  }
  after_->act(observation, goal_ned_m, state, action);
}

void write_open_loop_commands_csv(const std::string& path,
                                  const std::vector<Eigen::VectorXd>& commands,
                                  double control_step_s, double max_thrust_n) {
  const Eigen::Index n = commands.empty() ? 0 : commands.front().size();
  std::vector<std::string> header{"t"};
  for (Eigen::Index i = 1; i <= n; ++i) header.push_back(fmt::format("f{}", i));
  // 17 digits: the replay reads back exactly the searched thrusts.
  csv::Writer out(path, header, csv::Mode::kTruncate, 17);
  for (std::size_t t = 0; t < commands.size(); ++t) {
    // Row t takes effect at the control step that starts at t * dt (auv_sim's rule).
    out.cell(static_cast<double>(t) * control_step_s);
    for (Eigen::Index i = 0; i < n; ++i) out.cell(commands[t][i] * max_thrust_n);
    out.end_row();
  }
  // A last row of zeros at the end: auv_sim runs up to the last row's time by default, so
  // every command above is played, and none after.
  out.cell(static_cast<double>(commands.size()) * control_step_s);
  for (Eigen::Index i = 0; i < n; ++i) out.cell(0);
  out.end_row();
  out.flush();
}

namespace {

/// search.csv: the best arrival step so far and the iteration's best, per iteration.
void write_search_csv(const std::string& path, const ArrivalSearchResult& result) {
  csv::Writer out(path, {"iteration", "best_arrival_step", "iteration_best_arrival_step"});
  for (std::size_t i = 0; i < result.best_so_far_step.size(); ++i) {
    out.row(static_cast<std::uint64_t>(i), result.best_so_far_step[i],
            result.iteration_best_step[i]);
  }
  out.flush();
}

/// The closing lines: the PID's figures, the search's start and what the search found.
std::string result_lines(const ArrivalSearchRequest& request, const ArrivalSearchResult& result,
                         const std::vector<eval::SummaryRow>& rows, double dt) {
  std::string lines =
      fmt::format("PID baseline:             {:.1f} s (hold error after {:.2f} m, energy {:.1f})\n",
                  rows[0].time_to_reach_s, rows[0].mean_error_after_reach_m, rows[0].thrust_energy);
  lines += fmt::format("PID's commands, replayed: {:.1f} s (the search's start)\n",
                       result.start_arrival_step * dt);
  if (result.best_arrival_step <= 0) {
    return lines + "soonest found:            none that counts (nor did the PID's replay)\n";
  }
  lines += fmt::format(
      "soonest found:            {:.1f} s; with the PID holding after it: hold error {:.2f} m, "
      "energy {:.1f}\n",
      rows[1].time_to_reach_s, rows[1].mean_error_after_reach_m, rows[1].thrust_energy);
  if (result.best_farthest_after_m >= 0) {
    lines += fmt::format("  farthest in the {:.1f} s after arriving: {:.2f} m\n",
                         request.search.stay_steps * dt, result.best_farthest_after_m);
  }
  namespace fs = std::filesystem;
  lines += fmt::format(
      "wrote {} (replay: auv_sim --vehicle FILE --open-loop commands.csv --out OUT.csv),\n"
      "      summary.csv, search.csv and trajectories/ in {}\n",
      (fs::path(request.out_dir) / "commands.csv").string(), request.out_dir);
  return lines;
}

}  // namespace

ArrivalSearchResult run_arrival_search_request(const ArrivalSearchRequest& request,
                                               std::ostream& out) {
  if (request.out_dir.empty()) throw std::invalid_argument("--out DIR is required");
  if (request.vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  const std::vector<eval::Scenario> scenarios = eval::parse_scenarios(request.scenario);
  if (scenarios.size() != 1 || scenarios.front() == eval::Scenario::kSuite) {
    throw std::invalid_argument("--scenario: expected one of test1, test2, fault, current, got '" +
                                request.scenario + "'");
  }
  request.search.validate();
  const sim::VehicleModel model = sim::load_vehicle_file(request.vehicle_path);
  const eval::EvaluationConfig config = completed(eval::EvaluationConfig{}, model);
  const eval::EvaluationEpisode episode =
      eval::scenario_episodes(config, scenarios.front()).front();
  const double dt = config.task.control_step_s;

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(fs::path(request.out_dir) / "trajectories", ec);
  if (ec) throw std::runtime_error("cannot create " + request.out_dir + ": " + ec.message());

  out << fmt::format("auvrl fastest: {}, {} iterations of {} samples (seed {})", request.scenario,
                     request.search.iterations, request.search.population, request.search.seed);
  if (request.search.stay_within_m > 0) {
    out << fmt::format(", staying within {:g} m for {:g} s after arriving",
                       request.search.stay_within_m, request.search.stay_steps * dt);
  }
  out << "\n";
  const ArrivalSearchResult result =
      search_fastest_arrival(model, config, episode, request.search, [&](int it, int best) {
        if ((it + 1) % 100 == 0) {
          out << fmt::format("  iteration {}: {:g} s\n", it + 1, best * dt) << std::flush;
        }
      });

  // The evaluation's own figures for the PID and for the found commands with the PID after.
  std::vector<eval::SummaryRow> rows;
  std::vector<agent::TrajectoryRow> trajectory;
  agent::PidController pid(model, agent::pid_gains_for(model).gains);
  rows.push_back(eval::run_evaluation_episode(model, config, pid, episode, &trajectory));
  const int n = model.num_thrusters();
  eval::write_trajectory_csv(
      (fs::path(request.out_dir) / "trajectories" / ("pid_" + request.scenario + ".csv")).string(),
      trajectory, n);
  if (result.best_arrival_step > 0) {
    OpenLoopController found(
        result.commands, n,
        std::make_unique<agent::PidController>(model, agent::pid_gains_for(model).gains));
    rows.push_back(eval::run_evaluation_episode(model, config, found, episode, &trajectory));
    eval::write_trajectory_csv(
        (fs::path(request.out_dir) / "trajectories" / ("open_loop_" + request.scenario + ".csv"))
            .string(),
        trajectory, n);
    write_open_loop_commands_csv((fs::path(request.out_dir) / "commands.csv").string(),
                                 result.commands, dt, config.task.max_thrust_n);
  }
  eval::write_summary_csv((fs::path(request.out_dir) / "summary.csv").string(), rows);
  write_search_csv((fs::path(request.out_dir) / "search.csv").string(), result);
  out << result_lines(request, result, rows, dt);
  return result;
}

}  // namespace auvrl::tools
