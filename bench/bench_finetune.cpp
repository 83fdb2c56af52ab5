// The fine-tuning search's unit of work: one sample's objective, the fast preset's 42 way-points
// driven by the committed policy (Google Benchmark; run by hand in a Release build):
//   build/bin/bench_finetune
// OneAtATime runs the way-points one after another (arrival_objective, a network pass per step
// and way-point); Batched drives them in lockstep through one batched pass per step
// (BatchedObjective), as the search does. Both give the same objective to the bit; compare
// their items_per_second (samples per second on one core) within one run.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "agent/controller.hpp"
#include "common/nn/file_io.hpp"
#include "common/nn/serialize.hpp"
#include "launcher/run_config.hpp"
#include "sim/vehicle_model.hpp"
#include "tuning/policy_finetune.hpp"

namespace {

using namespace auvrl;

/// The fast preset's model, task, fine-tuning and way-points, and the committed policy.
struct Setup {
  launcher::RunConfig config =
      launcher::read_run_config(std::string(AUVRL_CONFIG_DIR) + "/presets/fast.yaml");
  sim::VehicleModel model = sim::load_vehicle_file(config.vehicle_path);
  task::TaskConfig task = applied(config.task, model);
  nn::Mlp policy =
      nn::network_from_bytes(nn::read_file(std::string(AUVRL_CONFIG_DIR) + "/policies/fast.nn"), 1);
  std::vector<tuning::FinetuneEpisode> episodes =
      tuning::objective_episodes(model, task, config.finetune, 1);

  static task::TaskConfig applied(task::TaskConfig task, const sim::VehicleModel& model) {
    task::apply_vehicle(model.facts(), task);
    return task;
  }
};

const Setup& setup() {
  static const Setup s;
  return s;
}

void OneAtATime(benchmark::State& bench) {
  const Setup& s = setup();
  agent::PolicyController controller(s.policy, tuning::finetune_driving_task(s.task));
  for (auto _ : bench) {
    double sum = 0.0;
    for (const tuning::FinetuneEpisode& e : s.episodes) {
      sum += tuning::arrival_objective(s.model, s.task, controller, e, s.config.finetune);
    }
    benchmark::DoNotOptimize(sum);
  }
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK(OneAtATime)->Unit(benchmark::kMillisecond);

void Batched(benchmark::State& bench) {
  const Setup& s = setup();
  tuning::BatchedObjective objective(s.model, s.task, s.policy, s.config.finetune,
                                     s.episodes.size());
  for (auto _ : bench) {
    double sum = 0.0;
    for (const double v : objective(s.episodes)) sum += v;
    benchmark::DoNotOptimize(sum);
  }
  bench.SetItemsProcessed(bench.iterations());
}
BENCHMARK(Batched)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
