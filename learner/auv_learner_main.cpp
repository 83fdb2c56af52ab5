// auv_learner: the central learner (replay buffer, networks, DDPG/TD3 updates, weights
// broadcast, schedule, checkpoints), or `--bench` to print update rates. Parses the command
// line and wires library pieces; nothing else.
#include <iostream>

#include "common/cli.hpp"
#include "common/config/table.hpp"
#include "common/nn/mlp.hpp"
#include "common/signals.hpp"
#include "common/transport_options.hpp"
#include "learner/bench.hpp"
#include "learner/learner_config.hpp"
#include "learner/learner_node.hpp"

namespace {

using namespace auvrl;

int run_bench(const std::string& algo, const std::string& hidden, int batch, int threads,
              bool one_case, double seconds) {
  std::vector<learner::BenchCase> cases;
  if (one_case) {
    learner::BenchCase c;
    c.algo = learner::parse_algo(algo);
    if (!hidden.empty()) c.hidden = learner::parse_hidden(hidden);
    if (batch > 0) c.batch = batch;
    c.threads = threads;
    cases.push_back(c);
  } else {
    cases = learner::standard_bench_cases(learner::parse_algo(algo));
    for (auto& c : cases) c.threads = threads;
  }
  for (auto& c : cases) {
    c.seconds = seconds;
    learner::print_bench_line(std::cout, learner::run_update_benchmark(c));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  learner::LearnerNodeConfig config;
  config.ddpg.state_dim = config.task.state_dim();
  config.ddpg.action_dim = config.task.num_thrusters;
  std::string config_path = cli::CommandLine::find_value(argc, argv, "config");
  if (!config_path.empty()) {
    try {
      learner::read_learner_config_file(config_path, config);
    } catch (const std::exception& e) {
      std::cerr << "auv_learner: " << e.what() << "\n";
      return 2;
    }
  }
  transport::TransportConfig transport_config;
  std::string hidden;
  int threads = 1;
  bool bench = false, resume = false, keep_running = false;
  double bench_seconds = 2.0;

  cli::CommandLine cmd("auv_learner",
                       "Central learner: replay buffer and networks, DDPG/TD3 updates from the "
                       "actors' experience, weights broadcast, schedule, checkpoints. Every key "
                       "of the learner: section is a flag (docs/configuration.md).");
  cmd.option("config", &config_path,
             "run configuration (YAML: task, schedule, learner); the options below override it");
  learner::learner_table().add_flags(cmd, config);
  cmd.option("state-dim", &config.ddpg.state_dim, "observation size (the task's layout)");
  cmd.option("action-dim", &config.ddpg.action_dim, "action size (thrusters)");
  cmd.option("hidden", &hidden, "hidden sizes of both networks, e.g. 400-300");
  cmd.option("checkpoint-dir", &config.checkpoint_dir, "where checkpoints go");
  cmd.option("policy-out", &config.policy_path, "actor network written here at the end");
  cmd.flag("resume", &resume, "continue from the newest usable checkpoint in --checkpoint-dir");
  cmd.flag("keep-running", &keep_running, "keep serving after training is done");
  cmd.option("threads", &threads, "threads for the matrix products");
  transport::add_transport_options(cmd, transport_config);
  cmd.flag("bench", &bench,
           "print updates/s for 64-64 batch 100, 256-256 batch 256, 400-300 batch 64 (or the one "
           "case --hidden/--batch-size give) and exit");
  cmd.option("bench-seconds", &bench_seconds, "measuring time per benchmark case");
  try {
    if (!cmd.parse(argc, argv)) return 0;
    if (!hidden.empty()) {
      config.ddpg.actor_hidden = config.ddpg.critic_hidden = learner::parse_hidden(hidden);
    }
    if (resume && config.checkpoint_dir.empty()) {
      throw cli::UsageError("option --resume needs --checkpoint-dir");
    }
  } catch (const std::exception& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return 2;
  }
  const std::string algo = learner::to_string(config.ddpg.algo);

  try {
    nn::set_num_threads(threads);
    if (bench) {
      bool one_case = false;
      for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        one_case |= a.rfind("--hidden", 0) == 0 || a.rfind("--batch-size", 0) == 0;
      }
      return run_bench(algo, hidden, config.ddpg.batch_size, threads, one_case, bench_seconds);
    }
    auto transport = transport::make_transport(transport_config);
    signals::install_stop_handlers();
    learner::LearnerNode node(config, *transport, std::cerr);
    if (resume) node.resume();
    std::cerr << "auv_learner: " << algo << ", actor " << node.algorithm().actor().spec().describe()
              << ", buffer " << config.ddpg.replay_capacity << ", "
              << transport::describe(transport_config) << "\n";
    bool announced_done = false;
    while (!signals::stop_requested()) {
      node.poll(50);
      if (node.training_done() && !announced_done) {
        announced_done = true;
        std::cerr << "auv_learner: training done after " << node.episodes() << " episodes, "
                  << node.updates() << " updates\n";
        if (!keep_running) break;
      }
    }
    node.finish();
  } catch (const std::exception& e) {
    std::cerr << "auv_learner: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
