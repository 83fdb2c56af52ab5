// Prints the learner's update rates: the three standard cases (AUV dims 23/6, one thread), for
// DDPG and TD3, and the same with pendulum dims (state 3, action 1), as RLtools reports them;
// then the fast preset's learner without and with the PID imitation term, alternated three
// times (the machine is shared), and the ratio of their rates.
// Usage: bench_updates [SECONDS per case]. Not a CTest test.
#include <iostream>

#include "common/cli.hpp"
#include "learner/bench.hpp"

int main(int argc, char** argv) {
  using namespace auvrl::learner;
  double seconds = 2.0;
  auvrl::cli::CommandLine cmd("bench_updates", "The learner's update rates, per case.");
  cmd.positional("SECONDS", &seconds, "measuring time per case", /*required=*/false);
  cmd.check("SECONDS", auvrl::cli::positive());
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const auvrl::cli::UsageError& e) {
    std::cerr << "bench_updates: " << e.what() << "\n";
    return 2;
  }
  for (Algo algo : {Algo::kDdpg, Algo::kTd3}) {
    for (BenchCase c : standard_bench_cases(algo)) {
      c.seconds = seconds;
      print_bench_line(std::cout, run_update_benchmark(c));
      c.state_dim = 3;
      c.action_dim = 1;
      print_bench_line(std::cout, run_update_benchmark(c));
    }
    // RLtools' published cases: batch 100 at 256-256 and 400-400.
    for (auto hidden : {std::vector<int>{256, 256}, std::vector<int>{400, 400}}) {
      for (int dims : {0, 1}) {
        BenchCase c;
        c.algo = algo;
        c.hidden = hidden;
        c.batch = 100;
        c.seconds = seconds;
        if (dims == 1) {
          c.state_dim = 3;
          c.action_dim = 1;
        }
        print_bench_line(std::cout, run_update_benchmark(c));
      }
    }
  }
  // The imitation term's cost: the same case without and with it, interleaved so that both see
  // the same load; the ratio of the sums is what to compare across machines.
  double plain_updates = 0, plain_s = 0, imitation_updates = 0, imitation_s = 0;
  for (int round = 0; round < 3; ++round) {
    for (float weight : {0.0f, 0.4f}) {
      BenchCase c = fast_preset_bench_case(weight);
      c.seconds = seconds;
      const BenchResult r = run_update_benchmark(c);
      print_bench_line(std::cout, r);
      (weight > 0.0f ? imitation_updates : plain_updates) += static_cast<double>(r.updates);
      (weight > 0.0f ? imitation_s : plain_s) += r.seconds;
    }
  }
  std::cout << "fast preset: updates/s with imitation / without = "
            << (imitation_updates / imitation_s) / (plain_updates / plain_s) << '\n';
  return 0;
}
