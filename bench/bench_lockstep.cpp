// Lockstep control steps per second over each transport (LCM, DDS reliable, DDS best effort;
// --transport picks one): auv_sim as a real process, one client, then two client processes at
// once, each driving its own vehicle; first with the processes placed by the scheduler, then
// with all of them pinned to one CPU. Prints one line per client:
//   lockstep transport=lcm placement=any clients=1 client=0 steps=N steps_per_s=X p50_us=..
// Pinning matters on virtual machines: a wake-up on another CPU costs an inter-processor
// interrupt, and a lockstep round trip is four wake-ups (LCM hands every datagram from its
// receive thread to the handling thread).
// Run it inside a private network namespace: scripts/netns.sh build/bin/bench_lockstep
#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include "child_process.hpp"
#include "common/cli.hpp"
#include "common/sim_client.hpp"
#include "common/transport_options.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;

struct ClientResult {
  double steps_per_s = 0;
  double p50_us = 0;
  double p99_us = 0;
  int failures = 0;
};

/// A transport to measure: its name in the output and its configuration.
struct Variant {
  std::string name;
  transport::TransportConfig config;
};

ClientResult run_client(const transport::TransportConfig& config, int vehicle_id, int steps) {
  auto transport = transport::make_transport(config);
  SimClient client(*transport, vehicle_id);
  auvrl_lcm::vehicle_reset_t reset{};
  reset.position_ned_m[2] = 5.0;
  ClientResult result;
  // auv_sim may still be starting: retry the reset for a few seconds.
  bool ready = false;
  for (int i = 0; i < 50 && !ready; ++i) ready = client.reset(reset).has_value();
  if (!ready) {
    result.failures = steps;
    return result;
  }
  std::vector<double> command(6, 5.0);
  std::vector<double> latency_us;
  latency_us.reserve(static_cast<std::size_t>(steps));
  const auto start = Clock::now();
  for (int k = 0; k < steps; ++k) {
    command[0] = (k % 100) * 0.3;
    const auto t0 = Clock::now();
    if (!client.step(command)) ++result.failures;
    latency_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::sort(latency_us.begin(), latency_us.end());
  result.steps_per_s = steps / seconds;
  result.p50_us = latency_us[latency_us.size() / 2];
  result.p99_us = latency_us[latency_us.size() * 99 / 100];
  return result;
}

void print(const std::string& variant, const char* placement, int clients, int index, int steps,
           const ClientResult& r) {
  std::printf(
      "lockstep transport=%s placement=%s clients=%d client=%d steps=%d steps_per_s=%.0f "
      "p50_us=%.1f p99_us=%.1f failures=%d\n",
      variant.c_str(), placement, clients, index, steps, r.steps_per_s, r.p50_us, r.p99_us,
      r.failures);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  int steps = 20000;
  std::string vehicle = std::string(AUVRL_CONFIG_DIR) + "/vehicles/nessie7.yaml";
  std::string which = "all";
  cli::CommandLine cmd("bench_lockstep",
                       "Lockstep steps/s with one and two clients, per transport.");
  cmd.option("steps", &steps, "steps per client");
  cmd.option("vehicle", &vehicle, "vehicle file");
  cmd.option("transport", &which,
             "lcm, dds (reliable), dds-best-effort, or all (one after the other, same run)");
  cmd.choices("transport", {"lcm", "dds", "dds-best-effort", "all"});
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  std::vector<Variant> variants;
  {
    Variant lcm{"lcm", {}}, dds{"dds", {}}, best_effort{"dds-best-effort", {}};
    dds.config.kind = best_effort.config.kind = transport::TransportKind::kDds;
    best_effort.config.dds.lockstep_reliable = false;
    for (const Variant& v : {lcm, dds, best_effort}) {
      if (which == "all" || which == v.name) variants.push_back(v);
    }
  }
  cpu_set_t all;
  sched_getaffinity(0, sizeof all, &all);
  for (const char* placement : {"any", "cpu0"}) {
    if (std::string(placement) == "cpu0") {
      cpu_set_t one;
      CPU_ZERO(&one);
      CPU_SET(0, &one);
      sched_setaffinity(0, sizeof one, &one);  // inherited by auv_sim and the clients
    }
    for (const Variant& v : variants) {
      std::vector<std::string> sim_argv = {test_support::bin_path("auv_sim"), "--vehicle", vehicle,
                                           "--vehicles", "2"};
      for (const std::string& a : transport::transport_arguments(v.config)) sim_argv.push_back(a);
      test_support::ChildProcess sim(sim_argv);
      print(v.name, placement, 1, 0, steps, run_client(v.config, 0, steps));

      // Two client processes at once, each on its own vehicle; each prints its own line.
      std::vector<pid_t> children;
      for (int id = 0; id < 2; ++id) {
        const pid_t pid = fork();
        if (pid == 0) {
          print(v.name, placement, 2, id, steps, run_client(v.config, id, steps));
          _exit(0);
        }
        children.push_back(pid);
      }
      for (pid_t pid : children) waitpid(pid, nullptr, 0);
    }
  }
  sched_setaffinity(0, sizeof all, &all);
  return 0;
}
