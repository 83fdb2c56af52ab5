// auv_learner: the central learner (replay buffer, networks, DDPG/TD3 updates, weights
// broadcast, schedule, checkpoints), or `--bench` to print update rates. Parses the command
// line and wires library pieces (learner/learner_process.hpp); nothing else.
#include <iostream>

#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/round_schedule.hpp"
#include "common/task/task_yaml.hpp"
#include "common/transport_options.hpp"
#include "common/unrecoverable.hpp"
#include "common/vehicle_facts.hpp"
#include "learner/learner_config.hpp"
#include "learner/learner_node.hpp"
#include "learner/learner_process.hpp"

int main(int argc, char** argv) {
  using namespace auvrl;
  learner::LearnerNodeConfig config;
  std::string config_path = cli::CommandLine::find_value(argc, argv, "config");
  std::string vehicle_path = default_vehicle_file();
  try {
    if (config_path.empty()) {
      learner::apply_vehicle_file(vehicle_path, config);
    } else {
      learner::read_learner_config_file(config_path, config, &vehicle_path);
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return 2;
  }
  transport::TransportConfig transport_config;
  learner::LearnerProcessOptions options;

  cli::CommandLine cmd("auv_learner",
                       "Central learner: replay buffer and networks, DDPG/TD3 updates from the "
                       "actors' experience, weights broadcast, schedule, checkpoints. Every key "
                       "of the learner: section is a flag (docs/configuration.md).");
  cmd.option("config", &config_path,
             "run configuration (YAML: task, schedule, learner); the options below override it");
  cmd.option("vehicle", &vehicle_path,
             "vehicle file: the networks' sizes follow its thrusters and the task's layout "
             "(default: the run file's vehicle:, else config/vehicles/nessie7.yaml)");
  task::task_table().add_flags(cmd, config.task);
  learner::learner_table().add_flags(cmd, config);
  cmd.option("hidden", &options.hidden, "hidden sizes of both networks, e.g. 400-300");
  cmd.option("checkpoint-dir", &config.checkpoint_dir, "where checkpoints go");
  cmd.option("policy-out", &config.policy_path, "actor network written here at the end");
  cmd.option("average-policy-out", &config.average_policy_path,
             "the mean of the actor's last learner.average_window_updates updates written here at "
             "the end");
  add_reproducible_options(cmd, &config.reproducible, &config.round_weights_every_steps);
  cmd.option("snapshot-dir", &config.snapshot_dir,
             "reproducible mode: the actor network is written here every --snapshot-every-updates");
  cmd.option("snapshot-every-updates", &config.snapshot_every_updates,
             "reproducible mode: updates between snapshots (0: none)");
  cmd.flag("resume", &options.resume,
           "continue from the newest usable checkpoint in --checkpoint-dir");
  cmd.flag("keep-running", &options.keep_running, "keep serving after training is done");
  cmd.option("threads", &options.threads, "threads for the matrix products");
  transport::add_transport_options(cmd, transport_config);
  transport_config.dds.role = "learner";
  cmd.flag("bench", &options.bench,
           "print updates/s for 64-64 batch 100, 256-256 batch 256, 400-300 batch 64 (or the one "
           "case --hidden/--batch-size give) and exit");
  cmd.option("bench-seconds", &options.bench_seconds, "measuring time per benchmark case");
  try {
    if (!cmd.parse(argc, argv)) return 0;
    learner::apply_vehicle_file(vehicle_path, config);  // after the task's flags (layout)
    learner::finish_learner_config(options, config);
  } catch (const std::exception& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return 2;
  }
  options.bench_one_case = learner::names_one_bench_case(argc, argv);
  try {
    if (options.bench) return learner::run_learner_bench(config, options, std::cout);
    learner::run_learner_process(config, options, transport_config, std::cerr);
  } catch (const UnrecoverableFault& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return kExitUnrecoverable;
  } catch (const std::exception& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
