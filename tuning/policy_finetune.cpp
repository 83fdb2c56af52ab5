#include "tuning/policy_finetune.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "agent/controller.hpp"
#include "agent/episode.hpp"
#include "agent/pid_controller.hpp"
#include "agent/vehicle_link.hpp"
#include "common/nn/adam.hpp"
#include "common/nn/random.hpp"
#include "common/parallel.hpp"
#include "common/random.hpp"
#include "eval/robustness.hpp"

namespace auvrl::tuning {

namespace {
constexpr double kPi = 3.14159265358979323846;
/// A position drawn uniformly in the way-points' region, at least the robustness suite's minimum
/// distance from the goal (a few redraws at most: a region of any use has room beyond 1 m).
Eigen::Vector3d region_start(const task::TaskConfig& task, const Eigen::Vector3d& goal_ned_m,
                             std::mt19937_64& rng) {
  Eigen::Vector3d p = task::sample_goal(task, rng);  // a point of the way-points' region
  for (int attempt = 1;
       attempt < 100 && (goal_ned_m - p).norm() < eval::kRobustnessMinGoalDistanceM; ++attempt) {
    p = task::sample_goal(task, rng);
  }
  return p;
}

/// One of the fine-tuning's random streams: the run seed mixed with the stream's own tag, so that
/// each kind of draw stays apart from the others, from the evaluation suite's (mt19937_64(1))
/// and from the launcher's validation.
std::mt19937_64 finetune_stream(std::uint64_t seed, std::uint32_t tag) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    0xF17E7u, tag};
  return std::mt19937_64(seq);
}

/// The randomisation with every kind but its sensor noise off, and that always on (its levels
/// and scale as they are).
task::EpisodeRandomisation sensor_noise_only(task::EpisodeRandomisation randomisation) {
  randomisation.fault_probability = 0.0;
  randomisation.current_probability = 0.0;
  randomisation.varying_current_probability = 0.0;
  randomisation.model_probability = 0.0;
  randomisation.sensor_noise_probability = 1.0;
  return randomisation;
}

/// A steep dive from the task's start (FinetuneConfig::dive_fraction): depth uniform in the
/// lower half of what the region allows below the start, the horizontal offset uniform in the
/// disc of radius dive_across_m; clamped to the region.
Eigen::Vector3d dive_goal(const task::TaskConfig& task, const FinetuneConfig& config,
                          std::mt19937_64& rng) {
  const Eigen::Vector3d& start_ned_m = task.start_position_ned_m;
  const double deepest_m = task.goal_max_ned_m.z();
  const double from_m = start_ned_m.z() + 0.5 * std::max(0.0, deepest_m - start_ned_m.z());
  const double radius_m = config.dive_across_m * std::sqrt(draw::unit(rng));
  const double bearing_rad = (2.0 * draw::unit(rng) - 1.0) * kPi;
  const double depth_m = from_m + (deepest_m - from_m) * draw::unit(rng);
  const Eigen::Vector3d goal_ned_m(start_ned_m.x() + radius_m * std::cos(bearing_rad),
                                   start_ned_m.y() + radius_m * std::sin(bearing_rad), depth_m);
  return goal_ned_m.cwiseMax(task.goal_min_ned_m).cwiseMin(task.goal_max_ned_m);
}

}  // namespace

void FinetuneConfig::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("finetune: " + what);
  };
  require(iterations >= 0, "iterations must be >= 0");
  require(pairs >= 1, "pairs must be >= 1");
  require(std::isfinite(sigma) && sigma > 0, "sigma must be > 0");
  require(std::isfinite(learning_rate) && learning_rate > 0, "learning_rate must be > 0");
  require(episodes >= 1, "episodes must be >= 1");
  require(random_heading_fraction >= 0 && random_heading_fraction <= 1,
          "random_heading_fraction must be in [0, 1]");
  require(facing_away_fraction >= 0 && facing_away_fraction <= 1,
          "facing_away_fraction must be in [0, 1]");
  require(any_start_fraction >= 0 && any_start_fraction <= 1,
          "any_start_fraction must be in [0, 1]");
  require(std::isfinite(hold_weight) && hold_weight >= 0, "hold_weight must be >= 0");
  require(hold_steps >= 1, "hold_steps must be >= 1");
  require(std::isfinite(hold_turn_weight) && hold_turn_weight >= 0,
          "hold_turn_weight must be >= 0");
  require(std::isfinite(flip_margin_rad) && flip_margin_rad > 0, "flip_margin_rad must be > 0");
  require(std::isfinite(flip_margin_weight) && flip_margin_weight >= 0,
          "flip_margin_weight must be >= 0");
  require(episode_steps >= 1, "episode_steps must be >= 1");
  require(randomised_episode_steps >= 0, "randomised_episode_steps must be >= 0");
  require(std::isfinite(pid_lag_weight) && pid_lag_weight >= 0, "pid_lag_weight must be >= 0");
  require(std::isfinite(pid_lead_s), "pid_lead_s must be finite");
  require(std::isfinite(energy_weight) && energy_weight >= 0, "energy_weight must be >= 0");
  require(std::isfinite(smoothness_weight) && smoothness_weight >= 0,
          "smoothness_weight must be >= 0");
  require(integration_substeps >= 0, "integration_substeps must be >= 0");
  require(threads >= 0, "threads must be >= 0");
  require(candidates >= 1 && candidates <= 64, "candidates must be in [1, 64]");
  require(std::isfinite(candidates_within_s) && candidates_within_s >= 0.0,
          "candidates_within_s must be >= 0 s (0: no limit)");
  require(candidate_min_fraction > 0.0 && candidate_min_fraction <= 1.0,
          "candidate_min_fraction must be in (0, 1]");
  require(std::isfinite(max_search_s) && max_search_s >= 0.0,
          "max_search_s must be >= 0 s (0: no cap)");
  require(selection_seed != eval::EvaluationConfig{}.seed,
          "selection_seed must not be " + std::to_string(eval::EvaluationConfig{}.seed) +
              ", the evaluation's own draw of the robustness suite");
  require(randomised_fraction >= 0 && randomised_fraction <= 1,
          "randomised_fraction must be in [0, 1]");
  require(noisy_fraction >= 0 && noisy_fraction <= 1, "noisy_fraction must be in [0, 1]");
  require(dive_fraction >= 0 && dive_fraction <= 1, "dive_fraction must be in [0, 1]");
  require(std::isfinite(dive_across_m) && dive_across_m > 0, "dive_across_m must be > 0");
  std::string key;
  const std::string what = randomise.check(key);
  require(what.empty(), "randomise." + key + " " + what);
}

std::vector<FinetuneEpisode> finetune_episodes(const task::TaskConfig& task,
                                               const FinetuneConfig& config, std::uint64_t seed) {
  std::mt19937_64 rng = finetune_stream(seed, 0x5EEDu);  // way-points and headings
  std::vector<FinetuneEpisode> episodes;
  const int turned =
      static_cast<int>(std::lround(config.random_heading_fraction * config.episodes));
  const int randomised =
      static_cast<int>(std::lround(config.randomised_fraction * config.episodes));
  // The conditions' and the starts' own streams, drawn for every way-point: turning them on
  // changes no way-point or heading.
  std::mt19937_64 conditions_rng = finetune_stream(seed, 0xC0D1u);
  std::mt19937_64 starts_rng = finetune_stream(seed, 0x57A7u);
  const int any_start = static_cast<int>(std::lround(config.any_start_fraction * config.episodes));
  const int facing_away = static_cast<int>(std::lround(config.facing_away_fraction * turned));
  // Sensor noise alone, on a share of the others.
  std::mt19937_64 noise_rng = finetune_stream(seed, 0x2015Eu);
  const task::EpisodeRandomisation noise_only = sensor_noise_only(config.randomise);
  const int plain = config.episodes - randomised;
  const int noisy = static_cast<int>(std::lround(config.noisy_fraction * plain));
  int plain_so_far = 0;
  std::mt19937_64 dive_rng = finetune_stream(seed, 0xD1BEu);
  const int dives = static_cast<int>(std::lround(config.dive_fraction * plain));
  // Whether item i of n is one of the k spread evenly through them.
  const auto spread = [](int k, int i, int n) { return k > 0 && (i * k) / n != ((i + 1) * k) / n; };
  int faults = 0;
  int turned_so_far = 0;
  for (int i = 0; i < config.episodes; ++i) {
    FinetuneEpisode e;
    e.goal_ned_m = task::sample_goal(task, rng);
    if (!spread(randomised, i, config.episodes)) {
      // Drawn for every plain way-point, so that turning dives on moves no other one.
      const Eigen::Vector3d dive_ned_m = dive_goal(task, config, dive_rng);
      if (spread(dives, plain_so_far, plain)) e.goal_ned_m = dive_ned_m;
    }
    e.start.position_ned_m = task.start_position_ned_m;
    e.start.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, task.start_yaw_rad);
    const Eigen::Vector3d anywhere_ned_m = region_start(task, e.goal_ned_m, starts_rng);
    if (spread(any_start, i, config.episodes)) {
      e.start.position_ned_m = anywhere_ned_m;
      e.safety_radius_m = eval::grown_safety_radius_m(task, anywhere_ned_m, e.goal_ned_m);
    }
    if (spread(turned, i, config.episodes)) {
      // The heading is drawn either way, so that facing away moves no other way-point.
      e.start.euler_rpy_rad[2] = (2.0 * draw::unit(rng) - 1.0) * kPi;
      if (spread(facing_away, turned_so_far++, turned)) {
        e.start.euler_rpy_rad[2] = task::yaw_facing_away_rad(e.start.position_ned_m, e.goal_ned_m);
      }
    }
    // The faults take the thrusters in turn: drawn at random, a dozen of them over six
    // thrusters often leave one without a single fault, and the fine-tuning never learns to do
    // without it (docs/lab-notes/2026-11-25-dead-thrusters.md).
    const task::EpisodeConditions conditions = task::sample_conditions(
        config.randomise, task.num_thrusters, conditions_rng, faults % task.num_thrusters);
    if (spread(randomised, i, config.episodes)) {
      if (conditions.fault_thruster >= 0) ++faults;
      agent::apply_conditions(conditions, e.start);
      e.max_steps = config.randomised_episode_steps;
    } else if (spread(noisy, plain_so_far++, plain)) {
      agent::apply_conditions(task::sample_conditions(noise_only, task.num_thrusters, noise_rng),
                              e.start);
    }
    e.start.seed = seed * 1000 + static_cast<std::uint64_t>(i);
    episodes.push_back(e);
  }
  return episodes;
}

void set_pid_arrivals(const sim::VehicleModel& model, const task::TaskConfig& task,
                      const FinetuneConfig& config, std::vector<FinetuneEpisode>& episodes) {
  // The objective with nothing but the arrival priced: the interpolated arrival time (or, not
  // arriving, the episode's time plus the closest approach).
  FinetuneConfig arrival_only = config;
  arrival_only.hold_weight = 0.0;
  arrival_only.hold_turn_weight = 0.0;
  arrival_only.flip_margin_weight = 0.0;
  arrival_only.energy_weight = 0.0;
  arrival_only.smoothness_weight = 0.0;
  arrival_only.pid_lag_weight = 0.0;
  agent::PidController pid(model, agent::pid_gains_for(model).gains);
  for (FinetuneEpisode& e : episodes) {
    e.pid_arrival_s = arrival_objective(model, task, pid, e, arrival_only);
  }
}

namespace {

/// The search's direction from one iteration's objectives (value[s]: pair s / 2, sign + for
/// even s) and the pairs' perturbations: rank shaping gives the lowest objective +0.5 and the
/// highest -0.5 (robust to the scale and to the outliers of a way-point not reached), and the
/// antithetic pairs' utility differences weight their perturbations. It points to a lower
/// objective.
Eigen::VectorXf rank_weighted_direction(const std::vector<double>& value,
                                        const std::vector<Eigen::VectorXf>& noise, double sigma) {
  const int samples = static_cast<int>(value.size());
  const int pairs = static_cast<int>(noise.size());
  std::vector<int> order(static_cast<std::size_t>(samples));
  for (int s = 0; s < samples; ++s) order[static_cast<std::size_t>(s)] = s;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return value[static_cast<std::size_t>(a)] < value[static_cast<std::size_t>(b)];
  });
  std::vector<double> utility(static_cast<std::size_t>(samples));
  for (int r = 0; r < samples; ++r) {
    utility[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])] =
        0.5 - static_cast<double>(r) / static_cast<double>(samples - 1);
  }
  Eigen::VectorXf direction = Eigen::VectorXf::Zero(noise.front().size());
  for (int k = 0; k < pairs; ++k) {
    direction += static_cast<float>(utility[static_cast<std::size_t>(2 * k)] -
                                    utility[static_cast<std::size_t>(2 * k + 1)]) *
                 noise[static_cast<std::size_t>(k)];
  }
  direction /= static_cast<float>(pairs * sigma);
  return direction;
}

}  // namespace

namespace {

/// One of the objective's episodes made ready to run (evaluation/evaluation.cpp's episode,
/// ended hold_steps after the arrival): its plant, with the search's integration substeps, its
/// task, options, vehicle and trajectory. Not movable: the options point to the trajectory.
struct ObjectiveRun {
  /// `buffer` becomes the trajectory (cleared; its capacity kept from earlier runs).
  ObjectiveRun(const sim::VehicleModel& model, const task::TaskConfig& task,
               const FinetuneEpisode& episode, const FinetuneConfig& config, double reach_radius_m,
               std::vector<agent::TrajectoryRow>& buffer)
      : plant(model), t(task), trajectory(buffer) {
    if (config.integration_substeps > 0) plant.substeps = config.integration_substeps;
    task::apply_vehicle(plant.facts(), t);
    t.max_steps = episode.max_steps > 0 ? episode.max_steps : config.episode_steps;
    if (episode.safety_radius_m > 0.0) t.beta_max_m = episode.safety_radius_m;
    options.goal_ned_m = episode.goal_ned_m;
    options.beta_m = reach_radius_m;
    options.start = episode.start;
    options.reach_radius_m = reach_radius_m;
    options.run_full_time = true;
    options.steps_after_reach = config.hold_steps;
    trajectory.clear();
    trajectory.reserve(static_cast<std::size_t>(t.max_steps));
    options.trajectory = &trajectory;
    link = agent::make_in_process_link(plant);
  }
  ObjectiveRun(const ObjectiveRun&) = delete;
  ObjectiveRun& operator=(const ObjectiveRun&) = delete;

  sim::VehicleModel plant;
  task::TaskConfig t;
  agent::EpisodeOptions options;
  std::vector<agent::TrajectoryRow>& trajectory;
  std::unique_ptr<agent::VehicleLink> link;
};

/// The prices of a run's episode from its trajectory and summary.
ObjectiveTerms objective_terms(const ObjectiveRun& run, const agent::EpisodeSummary& summary,
                               const FinetuneEpisode& episode, const FinetuneConfig& config,
                               double reach_radius_m) {
  const std::vector<agent::TrajectoryRow>& trajectory = run.trajectory;
  const double dt = run.plant.control_step_s;
  ObjectiveTerms terms;
  double tilt_rad = 0.0;
  for (const agent::TrajectoryRow& row : trajectory) {
    tilt_rad = std::max({tilt_rad, std::abs(row.observation.euler_rpy_rad[0]),
                         std::abs(row.observation.euler_rpy_rad[1])});
  }
  const double tilt_beyond_rad = std::max(0.0, tilt_rad - config.flip_margin_rad);
  terms.flip_s = config.flip_margin_weight * tilt_beyond_rad;
  double thrust_s = 0.0;
  if (config.energy_weight != 0.0 || config.smoothness_weight != 0.0) {
    const double smoothness =
        eval::trajectory_smoothness(trajectory, 0, run.plant.thruster_dynamics.max_thrust_n);
    terms.energy_s = config.energy_weight * summary.thrust_energy;
    terms.smoothness_s = config.smoothness_weight * smoothness;
    thrust_s = config.energy_weight * summary.thrust_energy + config.smoothness_weight * smoothness;
  }
  // Summed as the search has always summed them: the same weights give the same bytes.
  const double margin_s = config.flip_margin_weight * tilt_beyond_rad + thrust_s;
  // Time behind the PID's arrival less the lead asked for, if any.
  auto lag_s = [&](double arrival_s) {
    if (!std::isfinite(episode.pid_arrival_s)) return 0.0;
    return config.pid_lag_weight *
           std::max(0.0, arrival_s - (episode.pid_arrival_s - config.pid_lead_s));
  };
  double before = (episode.goal_ned_m - episode.start.position_ned_m).norm();
  double closest_m = before;
  for (std::size_t k = 0; k < trajectory.size(); ++k) {
    const double d = trajectory[k].distance_m;
    closest_m = std::min(closest_m, d);
    if (d > reach_radius_m) {
      before = d;
      continue;
    }
    // Crossed during step k + 1: interpolate the moment the distance passed the radius.
    const double fraction = before > d ? (before - reach_radius_m) / (before - d) : 1.0;
    terms.arrival_s = (static_cast<double>(k) + std::clamp(fraction, 0.0, 1.0)) * dt;
    double sum_m = 0.0;
    double turn_rad = 0.0;  // the heading's net change, unwrapped
    for (std::size_t j = k; j < trajectory.size(); ++j) {
      sum_m += trajectory[j].distance_m;
      if (j == k) continue;
      const double yaw_rad = trajectory[j].observation.euler_rpy_rad[2];
      turn_rad +=
          std::remainder(yaw_rad - trajectory[j - 1].observation.euler_rpy_rad[2], 2.0 * kPi);
    }
    const auto n = static_cast<double>(trajectory.size() - k);
    terms.hold_s = config.hold_weight * sum_m / n;
    // hold_turn_weight x the net turn per second of the hold.
    terms.turn_s = config.hold_turn_weight * std::abs(turn_rad) / (n * dt);
    terms.lag_s = lag_s(terms.arrival_s);
    terms.objective_s = terms.arrival_s + terms.hold_s + terms.turn_s + margin_s + terms.lag_s;
    return terms;
  }
  const double give_up_s = run.t.max_steps * dt;
  terms.arrival_s = give_up_s + closest_m;
  terms.lag_s = lag_s(give_up_s);
  terms.objective_s = terms.arrival_s + margin_s + terms.lag_s;
  return terms;
}

}  // namespace

ObjectiveTerms arrival_objective_terms(const sim::VehicleModel& model, const task::TaskConfig& task,
                                       agent::Controller& controller,
                                       const FinetuneEpisode& episode, const FinetuneConfig& config,
                                       double reach_radius_m) {
  std::vector<agent::TrajectoryRow> trajectory;
  ObjectiveRun run(model, task, episode, config, reach_radius_m, trajectory);
  const agent::EpisodeSummary summary =
      agent::run_episode(run.t, *run.link, controller, run.options);
  return objective_terms(run, summary, episode, config, reach_radius_m);
}

BatchedObjective::BatchedObjective(const sim::VehicleModel& model, const task::TaskConfig& task,
                                   const nn::Mlp& network, const FinetuneConfig& config,
                                   std::size_t max_episodes)
    : model_(model),
      task_(task),
      config_(config),
      network_(network.spec(), static_cast<int>(std::max<std::size_t>(1, max_episodes))),
      trajectories_(max_episodes) {
  network_.copy_params_from(network);
  const task::TaskConfig driving = finetune_driving_task(task);
  for (std::size_t i = 0; i < max_episodes; ++i) aids_.emplace_back(network, driving);
}

std::vector<double> BatchedObjective::operator()(const std::vector<FinetuneEpisode>& episodes) {
  if (episodes.size() > aids_.size()) {
    throw std::invalid_argument("BatchedObjective: " + std::to_string(episodes.size()) +
                                " episodes, more than the " + std::to_string(aids_.size()) +
                                " it was made for");
  }
  std::vector<std::unique_ptr<ObjectiveRun>> runs;
  std::vector<agent::PolicyEpisode> batch;
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    runs.push_back(
        std::make_unique<ObjectiveRun>(model_, task_, episodes[i], config_, 0.5, trajectories_[i]));
    ObjectiveRun& r = *runs.back();
    batch.push_back({&r.t, r.link.get(), &aids_[i], &r.options});
  }
  const std::vector<agent::EpisodeSummary> summaries = agent::run_policy_episodes(network_, batch);
  std::vector<double> objectives;
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    objectives.push_back(
        objective_terms(*runs[i], summaries[i], episodes[i], config_, 0.5).objective_s);
  }
  return objectives;
}

double arrival_objective(const sim::VehicleModel& model, const task::TaskConfig& task,
                         agent::Controller& controller, const FinetuneEpisode& episode,
                         const FinetuneConfig& config, double reach_radius_m) {
  return arrival_objective_terms(model, task, controller, episode, config, reach_radius_m)
      .objective_s;
}

std::vector<FinetuneEpisode> objective_episodes(const sim::VehicleModel& model,
                                                const task::TaskConfig& task,
                                                const FinetuneConfig& config, std::uint64_t seed) {
  std::vector<FinetuneEpisode> episodes = finetune_episodes(task, config, seed);
  if (config.pid_lag_weight > 0) set_pid_arrivals(model, task, config, episodes);
  return episodes;
}

ObjectiveTerms& ObjectiveTerms::operator+=(const ObjectiveTerms& o) {
  arrival_s += o.arrival_s;
  hold_s += o.hold_s;
  turn_s += o.turn_s;
  flip_s += o.flip_s;
  energy_s += o.energy_s;
  smoothness_s += o.smoothness_s;
  lag_s += o.lag_s;
  objective_s += o.objective_s;
  return *this;
}

ObjectiveTerms& ObjectiveTerms::operator/=(double divisor) {
  for (double* term :
       {&arrival_s, &hold_s, &turn_s, &flip_s, &energy_s, &smoothness_s, &lag_s, &objective_s}) {
    *term /= divisor;
  }
  return *this;
}

ObjectiveTerms mean_objective_terms(const sim::VehicleModel& model, const task::TaskConfig& task,
                                    agent::Controller& controller,
                                    const std::vector<FinetuneEpisode>& episodes,
                                    const FinetuneConfig& config) {
  ObjectiveTerms mean;
  for (const FinetuneEpisode& e : episodes) {
    mean += arrival_objective_terms(model, task, controller, e, config);
  }
  mean /= static_cast<double>(std::max<std::size_t>(1, episodes.size()));
  return mean;
}

task::TaskConfig finetune_driving_task(const task::TaskConfig& task) {
  task::TaskConfig t = task;
  t.fault_accommodation.enabled = false;
  return t;
}

int search_threads(const FinetuneConfig& config) {
  return config.threads > 0 ? config.threads
                            : std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
}

FinetuneResult finetune_policy(
    const sim::VehicleModel& model, const task::TaskConfig& task, const nn::Mlp& start,
    const FinetuneConfig& config, std::uint64_t seed,
    const std::function<void(const FinetuneIteration&, const nn::Mlp& weights)>& progress,
    const std::function<bool()>& stop) {
  config.validate();
  // Throws if the network does not fit the task.
  { agent::PolicyController check(start, task); }
  const std::vector<FinetuneEpisode> episodes = objective_episodes(model, task, config, seed);
  const auto t0 = std::chrono::steady_clock::now();

  const int threads = std::min(search_threads(config), 2 * config.pairs);
  // Per worker: the way-points driven all at once (BatchedObjective).
  std::vector<BatchedObjective> batches;
  for (int w = 0; w < threads; ++w)
    batches.emplace_back(model, task, start, config, episodes.size());
  // The mean of per-episode objectives, summed in order.
  const auto mean_of = [](const std::vector<double>& values) {
    double sum = 0.0;
    for (const double v : values) sum += v;
    return sum / static_cast<double>(values.size());
  };
  // Mean objective of weights theta, its episodes split among the workers (each part's values in
  // their own slots: the same sum whatever the threads).
  const auto parts = static_cast<std::size_t>(threads);
  std::vector<std::vector<FinetuneEpisode>> part_episodes(parts);
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    part_episodes[i * parts / episodes.size()].push_back(episodes[i]);
  }
  auto objective = [&](const Eigen::VectorXf& theta) {
    std::vector<std::vector<double>> part_values(parts);
    for_each_index(threads, parts, [&](int w, std::size_t part) {
      BatchedObjective& batch = batches[static_cast<std::size_t>(w)];
      batch.network().params() = theta;
      part_values[part] = batch(part_episodes[part]);
    });
    std::vector<double> values;
    for (const std::vector<double>& v : part_values)
      values.insert(values.end(), v.begin(), v.end());
    return mean_of(values);
  };

  nn::Mlp scratch = start;  // the weights shown to `progress`
  FinetuneResult result{start, 0.0, 0.0, 0, {}, episodes};
  Eigen::VectorXf theta = start.params();
  const Eigen::Index p = theta.size();
  result.start_objective = objective(theta);
  result.best_objective = result.start_objective;
  // Kingma & Ba's defaults (beta 0.9 / 0.999, epsilon 1e-8), no decay, no clipping.
  nn::AdamConfig adam_config;
  adam_config.learning_rate = static_cast<float>(config.learning_rate);
  nn::Adam adam(adam_config, p, 0);
  nn::Rng rng(seed ^ 0xE5E5E5E5ull);
  const int samples = 2 * config.pairs;
  std::vector<Eigen::VectorXf> noise(static_cast<std::size_t>(config.pairs));
  std::vector<double> value(static_cast<std::size_t>(samples));

  for (int it = 1; it <= config.iterations; ++it) {
    if (stop && stop()) break;
    // Portable N(0, 1) draws, vectorised (a draw per parameter and pair every iteration).
    for (Eigen::VectorXf& eps : noise) {
      eps.resize(p);
      nn::fill_standard_normal(rng, eps);
    }
    // Sample s: pair s / 2, sign + for even s; each value in its own slot, whichever worker
    // runs it.
    for_each_index(threads, static_cast<std::size_t>(samples), [&](int w, std::size_t s) {
      const Eigen::VectorXf& eps = noise[s / 2];
      const float sign = s % 2 == 0 ? 1.0f : -1.0f;
      BatchedObjective& batch = batches[static_cast<std::size_t>(w)];
      batch.network().params() = theta + sign * static_cast<float>(config.sigma) * eps;
      value[s] = mean_of(batch(episodes));
    });

    Eigen::VectorXf direction = rank_weighted_direction(value, noise, config.sigma);
    // The direction lowers the objective; Adam descends, so it steps on the negative.
    direction = -direction;
    adam.step(theta, direction);

    FinetuneIteration stats;
    stats.iteration = it;
    stats.objective = objective(theta);
    stats.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (stats.objective < result.best_objective) {
      result.best_objective = stats.objective;
      result.best_iteration = it;
      result.network.params() = theta;
    }
    result.iterations.push_back(stats);
    if (progress) {
      scratch.params() = theta;
      progress(stats, scratch);
    }
  }
  return result;
}

}  // namespace auvrl::tuning
