#include "tuning/pid_tuning.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <ostream>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "common/config/table.hpp"
#include "common/parallel.hpp"
#include "common/random.hpp"

namespace auvrl::tuning {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// The gains of a DOF the vehicle may lack: not perturbed where it does.
const std::map<std::string, sim::Axis>& axis_gains() {
  static const std::map<std::string, sim::Axis> gains = {
      {"sway_position_gain_per_s", sim::kSway}, {"sway_speed_max_mps", sim::kSway},
      {"pitch_max_rad", sim::kPitch},           {"pitch_gain_per_s", sim::kPitch},
      {"pitch_rate_gain_per_s", sim::kPitch},   {"roll_gain_per_s", sim::kRoll},
      {"roll_rate_gain_per_s", sim::kRoll},
  };
  return gains;
}

/// A gain off (0) by default is switched on at its partner's value.
const std::map<std::string, std::string>& switch_on_partner() {
  static const std::map<std::string, std::string> partners = {
      {"roll_gain_per_s", "pitch_gain_per_s"},
      {"roll_rate_gain_per_s", "pitch_rate_gain_per_s"},
  };
  return partners;
}

const config::Field<agent::PidGains>& gain_field(const std::string& key) {
  for (const auto& f : agent::pid_gains_table().fields()) {
    if (f.key == key) return f;
  }
  throw std::invalid_argument("no PID gain named " + key);
}

double get_gain(const agent::PidGains& gains, const std::string& key) {
  agent::PidGains copy = gains;
  return config::shown_number(gain_field(key).show(copy));
}

void set_gain(agent::PidGains& gains, const std::string& key, double value) {
  gain_field(key).parse(fmt::format("{}", value), gains);  // shortest round trip: exact
}

bool failed(task::EndReason reason) {
  return reason == task::EndReason::kFlipped || reason == task::EndReason::kBlowUp ||
         reason == task::EndReason::kLeftRegion || reason == task::EndReason::kSimTimeout;
}

/// The evaluation's configuration for the tuning's episodes.
eval::EvaluationConfig evaluation_config(const sim::VehicleModel& model,
                                         const task::TaskConfig& task,
                                         const PidTuningConfig& config) {
  eval::EvaluationConfig c;
  c.task = task;
  task::apply_vehicle(model.facts(), c.task);
  c.task.max_steps = config.episode_steps;
  c.task.validate();
  c.episode_steps = config.episode_steps;
  c.reach_radius_m = config.reach_radius_m;
  return c;
}

/// The weighted objective of rows (one per episode, in order).
PidObjective score(const std::vector<eval::SummaryRow>& rows, const PidTuningConfig& config,
                   double episode_s) {
  PidObjective o;
  o.episodes = static_cast<int>(rows.size());
  double time_sum = 0.0, hold_sum = 0.0, energy_sum = 0.0;
  int counted = 0;
  for (const eval::SummaryRow& r : rows) {
    energy_sum += r.thrust_energy;
    if (!r.reached || failed(r.end_reason)) {
      ++o.missed;
      continue;
    }
    ++counted;
    time_sum += r.time_to_reach_s;
    hold_sum += r.mean_error_after_reach_m;
  }
  o.mean_time_s = counted > 0 ? time_sum / counted : episode_s;
  o.mean_hold_m = counted > 0 ? hold_sum / counted : 0.0;
  o.mean_energy = o.episodes > 0 ? energy_sum / o.episodes : 0.0;
  const PidObjectiveWeights& w = config.weights;
  const double missed_fraction = o.episodes > 0 ? static_cast<double>(o.missed) / o.episodes : 0.0;
  o.value = w.time * o.mean_time_s + w.hold_s_per_m * o.mean_hold_m + w.missed_s * missed_fraction +
            w.energy_s * o.mean_energy;
  return o;
}

int thread_count(const PidTuningConfig& config, std::size_t episodes) {
  const int cpus = std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  const int wanted = config.threads > 0 ? config.threads : cpus;
  return std::max(1, std::min(wanted, static_cast<int>(episodes)));
}

}  // namespace

void PidTuningConfig::validate() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("tune-pid: " + what);
  };
  require(iterations >= 0, "iterations must be >= 0");
  require(episodes >= 1, "episodes must be >= 1");
  require(fault_fraction >= 0 && current_fraction >= 0 && fault_fraction + current_fraction <= 1,
          "fault_fraction and current_fraction must be >= 0 and add up to at most 1");
  require(fault_efficiency >= 0 && fault_efficiency <= 1, "fault_efficiency must be in [0, 1]");
  require(std::isfinite(current_speed_mps) && current_speed_mps >= 0,
          "current_speed_mps must be >= 0");
  require(gains_per_step >= 1, "gains_per_step must be >= 1");
  require(std::isfinite(sigma) && sigma > 0, "sigma must be > 0");
  require(episode_steps >= 1, "episode_steps must be >= 1");
  require(std::isfinite(reach_radius_m) && reach_radius_m > 0, "reach_radius_m must be > 0");
  require(threads >= 0, "threads must be >= 0");
  const PidObjectiveWeights& w = weights;
  for (double v : {w.time, w.hold_s_per_m, w.missed_s, w.energy_s}) {
    require(std::isfinite(v) && v >= 0, "objective weights must be >= 0");
  }
}

std::string format_objective(const PidObjective& o) {
  return fmt::format("{:.3f} (time {:.2f} s, hold {:.3f} m, missed {}/{}, energy {:.1f})", o.value,
                     o.mean_time_s, o.mean_hold_m, o.missed, o.episodes, o.mean_energy);
}

std::vector<eval::EvaluationEpisode> pid_validation_episodes(const task::TaskConfig& task,
                                                             const PidTuningConfig& config,
                                                             std::uint64_t seed,
                                                             std::uint64_t salt) {
  config.validate();
  // A stream of its own: the evaluation's suite draws from mt19937_64(seed) directly, the
  // fine-tuning and the launcher's validation from theirs; the constants keep them apart.
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    0x91D7u, 0x7E57u, static_cast<std::uint32_t>(salt)};
  draw::Engine rng(seq);
  const int faults = static_cast<int>(std::lround(config.fault_fraction * config.episodes));
  const int currents =
      std::min(config.episodes - faults,
               static_cast<int>(std::lround(config.current_fraction * config.episodes)));
  std::vector<eval::EvaluationEpisode> episodes;
  for (int i = 0; i < config.episodes; ++i) {
    eval::EvaluationEpisode e;
    e.scenario = eval::Scenario::kSuite;
    e.index = i;
    e.goal_ned_m = task::sample_goal(task, rng);
    e.start.position_ned_m = task.start_position_ned_m;
    e.start.euler_rpy_rad = Eigen::Vector3d(0.0, 0.0, task.start_yaw_rad);
    e.start.seed = seed * 1000 + static_cast<std::uint64_t>(i);
    if (i < faults) {
      e.start.thruster_efficiency.assign(static_cast<std::size_t>(task.num_thrusters), 1.0);
      e.start.thruster_efficiency[0] = config.fault_efficiency;
    } else if (i < faults + currents) {
      const double direction = (2.0 * draw::unit(rng) - 1.0) * kPi;
      e.start.current_ned_mps =
          config.current_speed_mps * Eigen::Vector3d(std::cos(direction), std::sin(direction), 0.0);
    }
    episodes.push_back(e);
  }
  return episodes;
}

PidObjective pid_objective(const sim::VehicleModel& model, const task::TaskConfig& task,
                           const agent::PidGains& gains,
                           const std::vector<eval::EvaluationEpisode>& episodes,
                           const PidTuningConfig& config) {
  const eval::EvaluationConfig c = evaluation_config(model, task, config);
  agent::check_pid_gains(gains);
  const int threads = thread_count(config, episodes.size());
  std::vector<eval::SummaryRow> rows(episodes.size());
  // A PID per thread; each row is its episode's, whatever the timing.
  std::vector<agent::PidController> pids;
  for (int w = 0; w < threads; ++w) pids.emplace_back(model, gains);
  for_each_index(threads, episodes.size(), [&](int w, std::size_t i) {
    rows[i] = eval::run_evaluation_episode(model, c, pids[static_cast<std::size_t>(w)], episodes[i],
                                           nullptr);
  });
  return score(rows, config, config.episode_steps * model.control_step_s);
}

std::vector<std::string> tunable_gains(const sim::VehicleModel& model) {
  std::vector<std::string> keys;
  for (const auto& f : agent::pid_gains_table().fields()) {
    const auto axis = axis_gains().find(f.key);
    if (axis != axis_gains().end() &&
        !model.controlled_axes[static_cast<std::size_t>(axis->second)]) {
      continue;
    }
    keys.push_back(f.key);
  }
  return keys;
}

PidTuningResult tune_pid(const sim::VehicleModel& model, const task::TaskConfig& task_in,
                         const agent::PidGains& start, const PidTuningConfig& config,
                         std::uint64_t seed,
                         const std::function<void(const PidTuningStep&)>& progress) {
  config.validate();
  task::TaskConfig task = task_in;
  task::apply_vehicle(model.facts(), task);
  const auto t0 = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const std::vector<eval::EvaluationEpisode> episodes = pid_validation_episodes(task, config, seed);
  const std::vector<std::string> keys = tunable_gains(model);
  const int per_step = std::min(config.gains_per_step, static_cast<int>(keys.size()));

  PidTuningResult result;
  result.start = result.best = start;
  result.start_objective = result.best_objective =
      pid_objective(model, task, start, episodes, config);
  draw::Engine rng(seed ^ 0x9D1A7E5Eull);
  for (int it = 1; it <= config.iterations; ++it) {
    // gains_per_step distinct keys (a partial Fisher-Yates shuffle), each moved by a factor.
    std::vector<std::string> pool = keys;
    PidTuningStep step;
    step.iteration = it;
    agent::PidGains candidate = result.best;
    for (int k = 0; k < per_step; ++k) {
      const auto left = pool.size() - static_cast<std::size_t>(k);
      const auto pick = static_cast<std::size_t>(k) +
                        std::min(left - 1, static_cast<std::size_t>(draw::unit(rng) * left));
      std::swap(pool[static_cast<std::size_t>(k)], pool[pick]);
      const std::string& key = pool[static_cast<std::size_t>(k)];
      const double factor = std::exp(config.sigma * draw::standard_normal(rng));
      double value = get_gain(candidate, key);
      const auto partner = switch_on_partner().find(key);
      if (value == 0.0 && partner != switch_on_partner().end()) {
        value = get_gain(candidate, partner->second);
      }
      set_gain(candidate, key, value * factor);
      step.perturbed.push_back(key);
    }
    step.tried = pid_objective(model, task, candidate, episodes, config);
    step.accepted = step.tried.value < result.best_objective.value;
    if (step.accepted) {
      result.best = candidate;
      result.best_objective = step.tried;
      ++result.accepted;
    }
    step.best = result.best_objective;
    step.elapsed_s = elapsed();
    if (progress) progress(step);
  }
  // Held-out draws of the same seed: whether the gain carries beyond the draws searched on.
  const std::vector<eval::EvaluationEpisode> holdout =
      pid_validation_episodes(task, config, seed, 1);
  result.start_holdout = pid_objective(model, task, result.start, holdout, config);
  result.best_holdout = pid_objective(model, task, result.best, holdout, config);
  result.elapsed_s = elapsed();
  return result;
}

namespace {

/// The gains file's header: how it was produced and what it scored.
std::string gains_header(const sim::VehicleModel& model, const PidTuningRequest& request,
                         const PidTuningResult& r) {
  const PidTuningConfig& c = request.config;
  const int faults = static_cast<int>(std::lround(c.fault_fraction * c.episodes));
  const int currents =
      std::min(c.episodes - faults, static_cast<int>(std::lround(c.current_fraction * c.episodes)));
  const PidObjectiveWeights& w = c.weights;
  std::string h = fmt::format(
      "PID gains for vehicle '{}', read by agent::pid_gains_for (agent/pid_gains.hpp);\n"
      "tuned for the vehicle file {} (CRC-32 {:08x}).\n",
      model.name, request.vehicle_path, model.file_crc32);
  h += fmt::format("Produced by: {}\n", request.command_line);
  h += fmt::format(
      "Procedure (tuning/pid_tuning.hpp): random local search from the compiled defaults, seed "
      "{},\n{} iterations, {} gains at a time multiplied by exp({:g} N(0, 1)), kept if better "
      "({} kept).\n",
      request.seed, c.iterations, c.gains_per_step, c.sigma, r.accepted);
  h += fmt::format(
      "Validation draws: {} way-points from the task's goal box, from rest at its start pose, "
      "{:g} s each;\n{} with T1 at {:g} % efficiency, {} in a {:g} m/s current of random "
      "horizontal direction.\n",
      c.episodes, c.episode_steps * model.control_step_s, faults, 100.0 * c.fault_efficiency,
      currents, c.current_speed_mps);
  h += fmt::format(
      "Objective: {:g} x mean time to reach [s] + {:g} x mean hold error [m] + {:g} x missed "
      "fraction\n+ {:g} x mean thrust energy (reached = within {:g} m).\n",
      w.time, w.hold_s_per_m, w.missed_s, w.energy_s, c.reach_radius_m);
  h += "  defaults: " + format_objective(r.start_objective) + "\n";
  h += "  these:    " + format_objective(r.best_objective) + "\n";
  h += "Held-out draws (same seed, another stream):\n";
  h += "  defaults: " + format_objective(r.start_holdout) + "\n";
  h += "  these:    " + format_objective(r.best_holdout) + "\n";
  return h;
}

}  // namespace

PidTuningResult run_pid_tuning_request(const PidTuningRequest& request, std::ostream& out) {
  if (request.vehicle_path.empty()) throw std::invalid_argument("--vehicle FILE is required");
  request.config.validate();
  const sim::VehicleModel model = sim::load_vehicle_file(request.vehicle_path);
  const std::string path =
      request.out_path.empty() ? agent::pid_gains_path(request.vehicle_path) : request.out_path;
  const task::TaskConfig task;  // the evaluation's: its goal box and start pose
  out << fmt::format(
             "tuning the PID for '{}' (seed {}, {} iterations, {} validation way-points, {} "
             "threads)\n",
             model.name, request.seed, request.config.iterations, request.config.episodes,
             thread_count(request.config, static_cast<std::size_t>(request.config.episodes)))
      << std::flush;
  const agent::PidGains defaults;
  const PidTuningResult r =
      tune_pid(model, task, defaults, request.config, request.seed, [&](const PidTuningStep& s) {
        if (!s.accepted && s.iteration % 50 != 0) return;
        std::string moved;
        for (const std::string& k : s.perturbed) moved += (moved.empty() ? "" : ", ") + k;
        out << fmt::format("  iteration {:4}/{} {:6.1f} s  best {}{}\n", s.iteration,
                           request.config.iterations, s.elapsed_s, format_objective(s.best),
                           s.accepted ? "  <- " + moved : "")
            << std::flush;
      });
  out << fmt::format("done in {:.1f} s; {} of {} perturbations kept\n", r.elapsed_s, r.accepted,
                     request.config.iterations);
  out << "objective on the tuning draws (lower is better):\n"
      << "  defaults: " << format_objective(r.start_objective) << "\n"
      << "  tuned:    " << format_objective(r.best_objective) << "\n"
      << "on held-out draws:\n"
      << "  defaults: " << format_objective(r.start_holdout) << "\n"
      << "  tuned:    " << format_objective(r.best_holdout) << "\n"
      << "gains changed:\n";
  for (const std::string& key : tunable_gains(model)) {
    const double before = get_gain(r.start, key), after = get_gain(r.best, key);
    if (before != after) out << fmt::format("  {:30} {:g} -> {:.4g}\n", key, before, after);
  }
  agent::write_pid_gains_file(path, r.best, gains_header(model, request, r));
  out << "wrote " << path << "\n";
  return r;
}

}  // namespace auvrl::tuning
