// The learner's update rates (Google Benchmark; run by hand in a Release build):
//   build/bin/bench_updates [--benchmark_filter=td3] [--benchmark_min_time=...]
// Each case runs the update loop of learner/bench.hpp for kSecondsPerCase and reports
// updates_per_s (the manual time is the loop's wall-clock time): the three standard cases
// (AUV dims 23/6, one thread) for DDPG and TD3 and the same with pendulum dims (state 3,
// action 1), RLtools' published cases (batch 100 at 256-256 and 400-400), and the fast preset's
// learner without and with the PID imitation term alternated three times (the machine is
// shared), with the ratio of their rates, and the same for the smoothness terms (CAPS, both on).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "learner/bench.hpp"

namespace {

using auvrl::learner::Algo;
using auvrl::learner::BenchCase;
using auvrl::learner::BenchResult;

constexpr double kSecondsPerCase = 2.0;

/// Runs one case once and reports it as a single manually timed iteration.
void run_case(benchmark::State& state, BenchCase c) {
  c.seconds = kSecondsPerCase;
  for (auto _ : state) {
    const BenchResult r = auvrl::learner::run_update_benchmark(c);
    state.SetIterationTime(r.seconds);
    state.counters["updates_per_s"] = r.updates_per_s;
    state.counters["cpu_share"] = r.seconds > 0 ? r.cpu_seconds / r.seconds : 0.0;
  }
}

/// A term's cost: the case without and with it, interleaved so that both see the same load;
/// the ratio of the sums is what to compare across machines.
void term_ratio(benchmark::State& state, BenchCase without, BenchCase with) {
  for (auto _ : state) {
    double plain_updates = 0, plain_s = 0, term_updates = 0, term_s = 0;
    for (int round = 0; round < 3; ++round) {
      for (bool on : {false, true}) {
        BenchCase c = on ? with : without;
        c.seconds = kSecondsPerCase;
        const BenchResult r = auvrl::learner::run_update_benchmark(c);
        (on ? term_updates : plain_updates) += static_cast<double>(r.updates);
        (on ? term_s : plain_s) += r.seconds;
      }
    }
    state.SetIterationTime(plain_s + term_s);
    state.counters["without_updates_per_s"] = plain_updates / plain_s;
    state.counters["with_updates_per_s"] = term_updates / term_s;
    state.counters["ratio"] = (term_updates / term_s) / (plain_updates / plain_s);
  }
}

/// The imitation term's cost in the fast preset's learner.
void imitation_ratio(benchmark::State& state) {
  term_ratio(state, auvrl::learner::fast_preset_bench_case(0.0f),
             auvrl::learner::fast_preset_bench_case(0.4f));
}

/// The smoothness terms' cost (temporal and spatial) in the fast preset's learner (imitation on).
void smoothness_ratio(benchmark::State& state) {
  BenchCase with = auvrl::learner::fast_preset_bench_case(0.4f);
  with.smooth_temporal_weight = with.smooth_spatial_weight = 0.1f;
  term_ratio(state, auvrl::learner::fast_preset_bench_case(0.4f), with);
}

std::string case_name(const BenchCase& c) {
  std::string hidden;
  for (int h : c.hidden) hidden += (hidden.empty() ? "" : "-") + std::to_string(h);
  return std::string(c.algo == Algo::kTd3 ? "td3" : "ddpg") + "/" + hidden + "/batch" +
         std::to_string(c.batch) + "/dims" + std::to_string(c.state_dim) + "x" +
         std::to_string(c.action_dim);
}

void register_case(const BenchCase& c) {
  benchmark::RegisterBenchmark(case_name(c).c_str(), run_case, c)
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kSecond);
}

void register_all() {
  for (Algo algo : {Algo::kDdpg, Algo::kTd3}) {
    for (BenchCase c : auvrl::learner::standard_bench_cases(algo)) {
      register_case(c);
      c.state_dim = 3;
      c.action_dim = 1;
      register_case(c);
    }
    for (const std::vector<int>& hidden :
         {std::vector<int>{256, 256}, std::vector<int>{400, 400}}) {
      for (int dims : {0, 1}) {
        BenchCase c;
        c.algo = algo;
        c.hidden = hidden;
        c.batch = 100;
        if (dims == 1) {
          c.state_dim = 3;
          c.action_dim = 1;
        }
        register_case(c);
      }
    }
  }
  benchmark::RegisterBenchmark("fast_preset/imitation_ratio", imitation_ratio)
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kSecond);
  benchmark::RegisterBenchmark("fast_preset/smoothness_ratio", smoothness_ratio)
      ->Iterations(1)
      ->UseManualTime()
      ->Unit(benchmark::kSecond);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
