#include "agent/actor_process.hpp"

#include <sched.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>

#include "agent/pid_controller.hpp"
#include "common/channels.hpp"
#include "common/signals.hpp"
#include "sim/vehicle_model.hpp"

namespace auvrl::agent {

void finish_actor_config(const ActorProcessOptions& options, ActorNodeConfig& config) {
  config.vehicle_id = options.vehicle_id >= 0 ? options.vehicle_id : config.actor_id;
  config.seed = static_cast<std::uint64_t>(options.seed);
  const sim::VehicleModel model = sim::load_vehicle_file(
      options.vehicle_path.empty() ? default_vehicle_file() : options.vehicle_path);
  config.vehicle = model.facts();
  task::apply_vehicle(config.vehicle, config.task);
  config.task.validate();
  if (config.demonstration_fraction <= 0 && !config.expert_labels) return;
  // Two instances: the PID keeps integrator state per episode it follows.
  const PidGains gains = pid_gains_for(model).gains;  // X.pid.yaml beside the vehicle, or defaults
  if (config.demonstration_fraction > 0) {
    config.demonstrator = std::make_shared<PidController>(model, gains);
  }
  if (config.expert_labels) config.expert = std::make_shared<PidController>(model, gains);
}

bool pin_to_cpu(int cpu, std::ostream& log) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof set, &set) == 0) return true;
  log << "auv_actor: cannot pin to CPU " << cpu << " (continuing unpinned)\n";
  return false;
}

void run_actor_episodes(ActorNode& node, const ActorNodeConfig& config, int report_every,
                        std::ostream& log) {
  double return_sum = 0.0;
  int successes = 0, window = 0;
  int randomised = 0, randomised_successes = 0;  // episodes with task.randomise conditions
  while (!signals::stop_requested() && !node.training_done() &&
         (config.max_episodes == 0 || node.counters().episodes < config.max_episodes)) {
    const EpisodeSummary s = node.run_one_episode();
    if (s.length_steps == 0 && node.training_done()) break;  // ended while it waited
    if (node.last_was_demonstration()) continue;             // the window is the policy's
    return_sum += s.episode_return;
    successes += s.success ? 1 : 0;
    if (node.last_conditions().kinds != 0) {
      ++randomised;
      randomised_successes += s.success ? 1 : 0;
    }
    if (++window == report_every) {
      log << "auv_actor " << config.actor_id << ": episodes " << node.counters().episodes
          << ", policy v" << node.policy_version() << ", beta " << node.beta_m()
          << " m, mean return " << return_sum / window << ", success " << successes << "/"
          << window;
      if (config.task.randomise.any()) {
        log << " (randomised episodes " << randomised_successes << "/" << randomised << ")";
      }
      log << "\n";
      return_sum = 0.0;
      successes = window = randomised = randomised_successes = 0;
    }
  }
  const auto& c = node.counters();
  log << "auv_actor " << config.actor_id << ": stopped after " << c.episodes << " episodes, "
      << c.steps << " steps, " << c.transitions_sent << " transitions sent, "
      << c.episodes_discarded << " discarded";
  if (config.reproducible) {
    log << ", " << c.rounds_sent << " rounds sent, " << c.rounds_resent << " sent again, "
        << c.rounds_abandoned << " abandoned, waited " << c.round_start_wait_s
        << " s for rounds to start and " << c.round_step_wait_s << " s for weights within them";
  }
  log << "\n";
}

namespace {

/// Waits for the readers options.wait_for_readers names (see ActorProcessOptions).
void wait_for_system(transport::Transport& transport, const ActorProcessOptions& options,
                     int actor_id, std::ostream& log) {
  if (options.wait_for_readers.empty()) return;
  const auto timeout =
      std::chrono::milliseconds(static_cast<int>(options.wait_for_readers_s * 1e3));
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::string> missing =
      transport.wait_for_readers(channels::kExperience, options.wait_for_readers, timeout);
  const bool wants_learner =
      std::find(options.wait_for_readers.begin(), options.wait_for_readers.end(), "learner") !=
      options.wait_for_readers.end();
  if (missing.empty() && wants_learner) {
    const auto left = timeout - (std::chrono::steady_clock::now() - start);
    missing = transport.wait_for_readers(
        channels::kWeightsRequest, {"learner"},
        std::max(std::chrono::milliseconds(0),
                 std::chrono::duration_cast<std::chrono::milliseconds>(left)));
  }
  if (!missing.empty()) {
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    log << "auv_actor " << actor_id << ": no reader of role " << names << " found in "
        << options.wait_for_readers_s << " s; starting anyway\n";
  }
}

}  // namespace

void run_actor_process(const ActorNodeConfig& config, const ActorProcessOptions& options,
                       const transport::TransportConfig& transport_config,
                       const transport::LockstepBusOptions& lockstep_bus, std::ostream& log) {
  auto transport = transport::make_transport(transport_config);
  const auto lockstep_config = transport::lockstep_bus_config(transport_config, lockstep_bus);
  std::unique_ptr<transport::Transport> lockstep;
  if (lockstep_config) lockstep = transport::make_transport(*lockstep_config);
  signals::install_stop_handlers();
  wait_for_system(*transport, options, config.actor_id, log);
  ActorNode node(config, *transport, log, lockstep.get());
  log << "auv_actor " << config.actor_id << ": vehicle " << config.vehicle_id << " "
      << describe(config.vehicle) << ", " << task::to_string(config.task.layout) << " state ("
      << config.task.state_dim() << "), " << task::to_string(config.task.reward) << " reward, seed "
      << options.seed << ", randomised episodes: " << task::describe(config.task.randomise) << "\n";
  run_actor_episodes(node, config, options.report_every, log);
}

}  // namespace auvrl::agent
