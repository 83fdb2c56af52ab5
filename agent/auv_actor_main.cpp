// auv_actor: an exploration actor (episodes against its own vehicle of auv_sim, the newest
// policy plus noise, experience to the learner). Parses the command line and wires library
// pieces (agent/actor_process.hpp); nothing else.
#include <iostream>

#include "agent/actor_config.hpp"
#include "agent/actor_node.hpp"
#include "agent/actor_process.hpp"
#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/round_schedule.hpp"
#include "common/transport_options.hpp"
#include "common/unrecoverable.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  agent::ActorNodeConfig config;
  agent::ActorProcessOptions options;
  std::string config_path = cli::CommandLine::find_value(argc, argv, "config");
  try {
    if (!config_path.empty()) {
      agent::read_actor_config_file(config_path, config, &options.vehicle_path);
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_actor: " << e.what() << "\n";
    return 2;
  }
  transport::TransportConfig transport_config;
  transport::LockstepBusOptions lockstep_bus;

  cli::CommandLine cmd("auv_actor",
                       "Exploration actor: runs episodes of the goal-driven task on its vehicle "
                       "of auv_sim with the newest policy plus noise; sends experience. Every key "
                       "of the task: and actor: sections is a flag (docs/configuration.md).");
  cmd.option("config", &config_path,
             "run configuration (YAML: task, schedule, actor); the options below override it");
  cmd.option("actor-id", &config.actor_id, "this actor's id (0..)");
  cmd.option("vehicle-id", &options.vehicle_id, "its vehicle in auv_sim (default: the actor id)");
  task::task_table().add_flags(cmd, config.task);
  agent::actor_table().add_flags(cmd, config);
  cmd.option("initial-beta", &config.initial_beta_m, "goal radius until the learner's first");
  cmd.option("seed", &options.seed, "seed of way-points and noise (give each actor its own)");
  cmd.option("pin-cpu", &options.pin_cpu, "pin this process to one CPU (-1: no)");
  cmd.option("report-every", &options.report_every, "a log line every N episodes");
  add_reproducible_options(cmd, &config.reproducible, &config.round_weights_every_steps);
  cmd.custom_option(
      "wait-for-readers",
      [&options](const std::string& v) {
        options.wait_for_readers = transport::parse_comma_list(v, "role");
      },
      "",
      "before the first episode, wait for readers of these roles (learner,logger; DDS "
      "discovery), so that no first message is lost",
      "list");
  cmd.option("wait-for-readers-s", &options.wait_for_readers_s,
             "wait at most this long for them, then start anyway");
  cmd.option("vehicle", &options.vehicle_path,
             "vehicle file (default: the run file's vehicle:, else config/vehicles/nessie7.yaml)");
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "actor";
  transport::add_lockstep_options(cmd, lockstep_bus);
  try {
    if (!cmd.parse(argc, argv)) return 0;
    agent::finish_actor_config(options, config);
  } catch (const std::exception& e) {
    std::cerr << "auv_actor: " << e.what() << "\n";
    return 2;
  }
  if (options.pin_cpu >= 0) agent::pin_to_cpu(options.pin_cpu, std::cerr);
  try {
    agent::run_actor_process(config, options, transport_config, lockstep_bus, std::cerr);
  } catch (const UnrecoverableFault& e) {
    std::cerr << "auv_actor " << config.actor_id << ": " << e.what() << "\n";
    return kExitUnrecoverable;
  } catch (const std::exception& e) {
    std::cerr << "auv_actor: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
