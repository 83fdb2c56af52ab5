// auv_actor: an exploration actor (episodes against its own vehicle of auv_sim, the newest
// policy plus noise, experience to the learner). Parses the command line and wires library
// pieces; nothing else.
#include <sched.h>

#include <iostream>

#include "agent/actor_config.hpp"
#include "agent/actor_node.hpp"
#include "agent/pid_controller.hpp"
#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/signals.hpp"
#include "common/transport_options.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  agent::ActorNodeConfig config;
  std::string vehicle_path;  // the demonstrator's model
  std::string config_path = cli::CommandLine::find_value(argc, argv, "config");
  if (!config_path.empty()) {
    try {
      agent::read_actor_config_file(config_path, config, &vehicle_path);
    } catch (const std::exception& e) {
      std::cerr << "auv_actor: " << e.what() << "\n";
      return 2;
    }
  }
  transport::TransportConfig transport_config;
  int vehicle_id = -1, pin_cpu = -1, report_every = 50;
  std::int64_t seed = 1;

  cli::CommandLine cmd("auv_actor",
                       "Exploration actor: runs episodes of the goal-driven task on its vehicle "
                       "of auv_sim with the newest policy plus noise; sends experience. Every key "
                       "of the task: and actor: sections is a flag (docs/configuration.md).");
  cmd.option("config", &config_path,
             "run configuration (YAML: task, schedule, actor); the options below override it");
  cmd.option("actor-id", &config.actor_id, "this actor's id (0..)");
  cmd.option("vehicle-id", &vehicle_id, "its vehicle in auv_sim (default: the actor id)");
  task::task_table().add_flags(cmd, config.task);
  agent::actor_table().add_flags(cmd, config);
  cmd.option("initial-beta", &config.initial_beta_m, "goal radius until the learner's first");
  cmd.option("seed", &seed, "seed of way-points and noise (give each actor its own)");
  cmd.option("pin-cpu", &pin_cpu, "pin this process to one CPU (-1: no)");
  cmd.option("report-every", &report_every, "a log line every N episodes");
  cmd.option("vehicle", &vehicle_path, "vehicle file of the PID demonstrator/expert (YAML)");
  transport::add_transport_options(cmd, transport_config);
  transport::LockstepBusOptions lockstep_bus;
  transport::add_lockstep_options(cmd, lockstep_bus);
  try {
    if (!cmd.parse(argc, argv)) return 0;
    config.vehicle_id = vehicle_id >= 0 ? vehicle_id : config.actor_id;
    config.seed = static_cast<std::uint64_t>(seed);
    config.task.validate();
    if (config.demonstration_fraction > 0 || config.expert_labels) {
      if (vehicle_path.empty()) {
        throw std::invalid_argument(
            "demonstrations and expert labels need the vehicle file (vehicle: in the run file, "
            "or --vehicle)");
      }
      const sim::VehicleModel model = sim::load_vehicle_file(vehicle_path);
      // Two instances: the PID keeps integrator state per episode it follows.
      if (config.demonstration_fraction > 0) {
        config.demonstrator = std::make_shared<agent::PidController>(model);
      }
      if (config.expert_labels) config.expert = std::make_shared<agent::PidController>(model);
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_actor: " << e.what() << "\n";
    return 2;
  }
  if (pin_cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(pin_cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) {
      std::cerr << "auv_actor: cannot pin to CPU " << pin_cpu << " (continuing unpinned)\n";
    }
  }

  try {
    auto transport = transport::make_transport(transport_config);
    const auto lockstep_config = transport::lockstep_bus_config(transport_config, lockstep_bus);
    std::unique_ptr<transport::Transport> lockstep;
    if (lockstep_config) lockstep = transport::make_transport(*lockstep_config);
    signals::install_stop_handlers();
    agent::ActorNode node(config, *transport, std::cerr, lockstep.get());
    std::cerr << "auv_actor " << config.actor_id << ": vehicle " << config.vehicle_id << ", "
              << task::to_string(config.task.layout) << " state (" << config.task.state_dim()
              << "), " << task::to_string(config.task.reward) << " reward, seed " << seed << "\n";
    double return_sum = 0.0;
    int successes = 0, window = 0;
    while (!signals::stop_requested() && !node.training_done() &&
           (config.max_episodes == 0 || node.counters().episodes < config.max_episodes)) {
      const agent::EpisodeSummary s = node.run_one_episode();
      if (node.last_was_demonstration()) continue;  // the window is the policy's
      return_sum += s.episode_return;
      successes += s.success ? 1 : 0;
      if (++window == report_every) {
        std::cerr << "auv_actor " << config.actor_id << ": episodes " << node.counters().episodes
                  << ", policy v" << node.policy_version() << ", beta " << node.beta_m()
                  << " m, mean return " << return_sum / window << ", success " << successes << "/"
                  << window << "\n";
        return_sum = 0.0;
        successes = window = 0;
      }
    }
    const auto& c = node.counters();
    std::cerr << "auv_actor " << config.actor_id << ": stopped after " << c.episodes
              << " episodes, " << c.steps << " steps, " << c.transitions_sent
              << " transitions sent, " << c.episodes_discarded << " discarded\n";
  } catch (const std::exception& e) {
    std::cerr << "auv_actor: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
