#include "learner/learner_process.hpp"

#include <vector>

#include "common/cli.hpp"
#include "common/listening_lines.hpp"
#include "common/nn/mlp.hpp"
#include "common/signals.hpp"
#include "common/transport_options.hpp"
#include "learner/bench.hpp"

namespace auvrl::learner {

void finish_learner_config(const LearnerProcessOptions& options, LearnerNodeConfig& config) {
  if (!options.hidden.empty()) {
    config.ddpg.actor_hidden = config.ddpg.critic_hidden = parse_hidden(options.hidden);
  }
  if (options.resume && config.checkpoint_dir.empty()) {
    throw cli::UsageError("option --resume needs --checkpoint-dir");
  }
}

bool names_one_bench_case(int argc, const char* const* argv) {
  bool one_case = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    one_case |= a.rfind("--hidden", 0) == 0 || a.rfind("--batch-size", 0) == 0;
  }
  return one_case;
}

int run_learner_bench(const LearnerNodeConfig& config, const LearnerProcessOptions& options,
                      std::ostream& out) {
  nn::set_num_threads(options.threads);
  const Algo algo = config.ddpg.algo;
  std::vector<BenchCase> cases;
  if (options.bench_one_case) {
    BenchCase c;
    c.algo = algo;
    if (!options.hidden.empty()) c.hidden = parse_hidden(options.hidden);
    if (config.ddpg.batch_size > 0) c.batch = config.ddpg.batch_size;
    cases.push_back(c);
  } else {
    cases = standard_bench_cases(algo);
  }
  for (auto& c : cases) {
    c.threads = options.threads;
    c.seconds = options.bench_seconds;
    c.smooth_temporal_weight = config.ddpg.smooth_temporal_weight;
    c.smooth_spatial_weight = config.ddpg.smooth_spatial_weight;
    print_bench_line(out, run_update_benchmark(c));
  }
  return 0;
}

void run_learner_process(const LearnerNodeConfig& config, const LearnerProcessOptions& options,
                         const transport::TransportConfig& transport_config, std::ostream& log) {
  nn::set_num_threads(options.threads);
  auto transport = transport::make_transport(transport_config);
  signals::install_stop_handlers();
  LearnerNode node(config, *transport, log);
  if (options.resume) node.resume();
  log << listening::kLearner << to_string(config.ddpg.algo) << ", actor "
      << node.algorithm().actor().spec().describe() << ", buffer " << config.ddpg.replay_capacity
      << ", " << transport::describe(transport_config) << "\n";
  bool announced_done = false;
  while (!signals::stop_requested()) {
    node.poll(50);
    if (node.training_done() && !announced_done) {
      announced_done = true;
      log << "auv_learner: training done after " << node.episodes() << " episodes, "
          << node.updates() << " updates\n";
      if (!options.keep_running) break;
    }
  }
  node.finish();
}

}  // namespace auvrl::learner
