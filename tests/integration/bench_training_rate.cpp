// Environment steps per second of the training system (one auv_sim, one auv_learner, N
// auv_actor processes), measured from auv_sim's heartbeat over a window after a warm-up.
// Prints: training actors=N seconds=S env_steps_per_s=X updates_per_s=Y
// Run inside a private network namespace: scripts/netns.sh build/bin/bench_training_rate
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <chrono>
#include <cstdio>
#include <iostream>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/transport.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;

void run_case(int actors, double seconds, const std::string& learner_ratio) {
  const std::string dir = test_support::make_temp_dir("auvrl_bench_training_");
  auto monitor = transport::make_transport({});
  transport::Latest<auvrl_lcm::sim_heartbeat_t> heartbeat(*monitor, channels::kSimHeartbeat);
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*monitor, channels::kLearnerStats);
  test_support::ChildProcess sim(
      {test_support::bin_path("auv_sim"), "--vehicles", std::to_string(actors),
       "--heartbeat-period", "0.25"},
      dir + "/sim.log");
  test_support::ChildProcess learner(
      {test_support::bin_path("auv_learner"), "--algo", "td3", "--hidden", "64-64", "--batch",
       "256", "--state-dim", "23", "--updates-per-transition", learner_ratio, "--warmup", "5000",
       "--replay", "200000"},
      dir + "/learner.log");
  std::vector<std::unique_ptr<test_support::ChildProcess>> procs;
  for (int id = 0; id < actors; ++id) {
    procs.push_back(std::make_unique<test_support::ChildProcess>(
        std::vector<std::string>{test_support::bin_path("auv_actor"), "--actor-id",
                                 std::to_string(id), "--seed", std::to_string(id + 1),
                                 "--reward", "shaped", "--noise", "gaussian"},
        dir + "/actor" + std::to_string(id) + ".log"));
  }
  const auto wait_heartbeat = [&](double for_s) {
    std::optional<auvrl_lcm::sim_heartbeat_t> hb;
    const auto end = Clock::now() + std::chrono::duration<double>(for_s);
    while (Clock::now() < end) {
      monitor->handle(50);
      if (auto h = heartbeat.take()) hb = h;
    }
    return hb;
  };
  wait_heartbeat(2.0);  // warm-up: processes start, the learner starts updating
  auto first = wait_heartbeat(0.3);
  std::optional<auvrl_lcm::learner_stats_t> first_stats = stats.take();
  const auto t0 = Clock::now();
  auto last = wait_heartbeat(seconds);
  const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
  std::optional<auvrl_lcm::learner_stats_t> last_stats = stats.take();
  if (!first || !last) {
    std::printf("training actors=%d error=no_heartbeat\n", actors);
    return;
  }
  const double steps_per_s = static_cast<double>(last->steps_total - first->steps_total) / dt;
  const double updates_per_s =
      first_stats && last_stats ? static_cast<double>(last_stats->updates - first_stats->updates) / dt
                                : 0.0;
  std::printf("training actors=%d seconds=%.1f env_steps_per_s=%.0f updates_per_s=%.0f "
              "updates_per_transition=%s\n",
              actors, dt, steps_per_s, updates_per_s, learner_ratio.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  std::string ratio = "0.25";
  cli::CommandLine cmd("bench_training_rate",
                       "Environment steps/s with 1 and 2 actors (one sim, one learner).");
  cmd.option("seconds", &seconds, "measuring window per case");
  cmd.option("updates-per-transition", &ratio, "the learner's update ratio");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  run_case(1, seconds, ratio);
  run_case(2, seconds, ratio);
  return 0;
}
