// Control steps per second of step() (Google Benchmark; run by hand in a Release build):
//   build/bin/bench_sim_step
// items_per_second is control steps (0.1 s of simulated time each) per second on one core.
#include <benchmark/benchmark.h>

#include <string>

#include "sim/dynamics.hpp"
#include "sim/vehicle_model.hpp"

namespace {

using auvrl::sim::ThrusterVector;
using auvrl::sim::VehicleModel;
using auvrl::sim::VehicleState;

const VehicleModel& model(const std::string& file) {
  static const VehicleModel nessie =
      auvrl::sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml");
  static const VehicleModel munk =
      auvrl::sim::load_vehicle_file(std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7_munk.yaml");
  return file == "munk" ? munk : nessie;
}

/// A moving vehicle (commands alternate so nothing settles into a trivial state).
void run(benchmark::State& bench, const VehicleModel& m, bool ideal) {
  auvrl::sim::ResetSettings reset;
  reset.eta << 0, 0, 5, 0, 0, 0;
  reset.current.constant_velocity_ned_mps << 0.1, 0.05, 0.0;
  VehicleState state = auvrl::sim::make_state(m, reset);
  const VehicleState initial = state;
  ThrusterVector forward(6), turn(6);
  forward << 30, 30, 5, -5, 10, 10;
  turn << 20, -20, 10, 10, -10, 10;
  long k = 0;
  for (auto _ : bench) {
    const ThrusterVector& command = (k++ / 50) % 2 == 0 ? forward : turn;
    if (ideal) {
      auvrl::sim::step_ideal_thrusters(m, state, command);
    } else {
      auvrl::sim::step(m, state, command);
    }
    if (k % 700 == 0) state = initial;  // episodes of 70 s
    benchmark::DoNotOptimize(state.eta);
  }
  bench.SetItemsProcessed(bench.iterations());
  bench.counters["substeps"] = m.substeps;
}

void BM_StepNessieRk4(benchmark::State& bench) { run(bench, model("nessie"), false); }
void BM_StepNessieRk4IdealThrusters(benchmark::State& bench) { run(bench, model("nessie"), true); }
void BM_StepNessieMunkRk4(benchmark::State& bench) { run(bench, model("munk"), false); }
void BM_StepNessieSemiImplicitEuler(benchmark::State& bench) {
  static VehicleModel euler = [] {
    VehicleModel m = model("nessie");
    m.integrator = auvrl::sim::Integrator::kSemiImplicitEuler;
    return m;
  }();
  run(bench, euler, false);
}

BENCHMARK(BM_StepNessieRk4);
BENCHMARK(BM_StepNessieRk4IdealThrusters);
BENCHMARK(BM_StepNessieMunkRk4);
BENCHMARK(BM_StepNessieSemiImplicitEuler);

}  // namespace

BENCHMARK_MAIN();
