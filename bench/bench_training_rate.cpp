// Environment steps per second of the training system (auv_learner, N auv_actor processes and
// their simulators), measured from auv_sim's heartbeats over a window after a warm-up (2 s, and
// until every simulator's heartbeat and the learner's statistics have come), in two
// placements: "shared" (one auv_sim for all, everything on one bus, nothing pinned) and
// "pinned" (what auvrl train does: one auv_sim per actor pinned to the actor's CPU, a private
// lockstep bus per pair: an LCM port, or a DDS domain, of its own). The learner updates at the
// given ratio, without flow control. Over LCM, DDS and DDS with DDS Security in the same run
// (--transport: lcm, dds, dds-secure; both = lcm and dds; dds-both = dds and dds-secure; all =
// the three, one after the other).
// Prints: training transport=T placement=P actors=N seconds=S env_steps_per_s=X updates_per_s=Y
// Run inside a private network namespace: scripts/netns.sh build/bin/bench_training_rate
//
// dds-secure needs --dds-security DIR, made by scripts/pki.sh, with an identity for each process
// as auvrl train names them: learner, actor-I, sim-I (pinned: one per actor; shared: sim-0 for
// all), launcher (this process, an observer: it reads heartbeats and the learner's statistics).
// scripts/pki.sh's default (--actors 2) has them all:
//   scripts/pki.sh --out DIR
//   scripts/netns.sh build/bin/bench_training_rate --transport dds-both --dds-security DIR
#include <unistd.h>

#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/sim_heartbeat_t.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/dds_security.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "transport_variants.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;
constexpr int kMaxActors = 2;  // the cases: 1 and 2 actors

/// The private lockstep bus of pair i (as auvrl train makes it).
std::vector<std::string> lockstep_bus_args(const transport::TransportConfig& config, int i) {
  if (config.kind == transport::TransportKind::kDds) {
    return {"--lockstep-dds-domain", std::to_string(config.dds.domain_id + 1 + i)};
  }
  return {"--lockstep-lcm-url",
          "udpm://239.255.76.67:" + std::to_string(7668 + i) + "?ttl=0&recv_buf_size=1048576"};
}

/// The command line of auv_sim number i (participant sim-i): pinned, one vehicle on pair i's
/// bus; shared, all.
std::vector<std::string> sim_arguments(const transport::TransportConfig& config, int i, int actors,
                                       bool pinned, int cpus) {
  std::vector<std::string> argv = {test_support::bin_path("auv_sim"), "--heartbeat-period", "0.25"};
  if (pinned) {
    argv.insert(argv.begin(), {"/usr/bin/taskset", "-c", std::to_string(i % cpus)});
    argv.insert(argv.end(), {"--first-vehicle-id", std::to_string(i)});
    const auto b = lockstep_bus_args(config, i);
    argv.insert(argv.end(), b.begin(), b.end());
  } else {
    argv.insert(argv.end(), {"--vehicles", std::to_string(actors)});
  }
  const std::vector<std::string> transport_args =
      bench::participant_arguments(config, "sim-" + std::to_string(i));
  argv.insert(argv.end(), transport_args.begin(), transport_args.end());
  return argv;
}

/// auv_learner's command line: TD3, 64-64, at the given update ratio.
std::vector<std::string> learner_arguments(const transport::TransportConfig& config,
                                           const std::string& learner_ratio) {
  std::vector<std::string> learner_argv = {test_support::bin_path("auv_learner"),
                                           "--algo",
                                           "td3",
                                           "--hidden",
                                           "64-64",
                                           "--batch-size",
                                           "256",
                                           "--layout",
                                           "extended",
                                           "--updates-per-transition",
                                           learner_ratio,
                                           "--warmup-transitions",
                                           "5000",
                                           "--replay-capacity",
                                           "200000"};
  const std::vector<std::string> transport_args = bench::participant_arguments(config, "learner");
  learner_argv.insert(learner_argv.end(), transport_args.begin(), transport_args.end());
  return learner_argv;
}

/// The command line of auv_actor `id` (pinned: on its CPU and pair id's bus).
std::vector<std::string> actor_arguments(const transport::TransportConfig& config, int id,
                                         bool pinned, int cpus) {
  std::vector<std::string> argv = {test_support::bin_path("auv_actor"),
                                   "--actor-id",
                                   std::to_string(id),
                                   "--seed",
                                   std::to_string(id + 1),
                                   "--reward",
                                   "shaped",
                                   "--noise",
                                   "gaussian",
                                   "--layout",
                                   "extended"};
  if (pinned) {
    argv.insert(argv.end(), {"--pin-cpu", std::to_string(id % cpus)});
    const auto b = lockstep_bus_args(config, id);
    argv.insert(argv.end(), b.begin(), b.end());
  }
  const std::vector<std::string> transport_args =
      bench::participant_arguments(config, "actor-" + std::to_string(id));
  argv.insert(argv.end(), transport_args.begin(), transport_args.end());
  return argv;
}

/// Rates over the measuring window.
struct Rates {
  double seconds = 0.0;
  double steps_per_s = 0.0;
  double updates_per_s = 0.0;
};

/// A 2 s warm-up (longer until a heartbeat of each of the `sims` simulators and the learner's
/// statistics have come: DDS discovery, and authentication when secured, take their time), then
/// environment steps (the simulators' heartbeats) and learner updates over `seconds`.
Rates measure(transport::Transport& monitor,
              const std::map<int, auvrl_lcm::sim_heartbeat_t>& heartbeats, std::size_t sims,
              transport::Latest<auvrl_lcm::learner_stats_t>& stats, double seconds) {
  const auto total_steps = [&] {
    std::int64_t n = 0;
    for (const auto& [pid, h] : heartbeats) n += h.steps_total;
    return n;
  };
  const auto pump = [&](double for_s) {
    const auto end = Clock::now() + std::chrono::duration<double>(for_s);
    while (Clock::now() < end) monitor.handle(50);
  };
  pump(2.0);  // warm-up: processes start, the learner starts updating
  const auto give_up = Clock::now() + std::chrono::seconds(20);
  while ((heartbeats.size() < sims || !stats.has_value()) && Clock::now() < give_up) {
    monitor.handle(50);
  }
  const std::int64_t first = total_steps();
  std::optional<auvrl_lcm::learner_stats_t> first_stats = stats.take();
  const auto t0 = Clock::now();
  pump(seconds);
  Rates r;
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::optional<auvrl_lcm::learner_stats_t> last_stats = stats.take();
  r.steps_per_s = static_cast<double>(total_steps() - first) / r.seconds;
  r.updates_per_s =
      first_stats && last_stats
          ? static_cast<double>(last_stats->updates - first_stats->updates) / r.seconds
          : 0.0;
  return r;
}

/// One case: the simulators, auv_learner and `actors` actors in the given placement; prints the
/// rates measured.
void run_case(const bench::TransportVariant& v, int actors, double seconds,
              const std::string& learner_ratio, bool pinned) {
  const transport::TransportConfig& config = v.config;
  const std::string dir = test_support::make_temp_dir("auvrl_bench_training_");
  auto monitor = transport::make_transport(bench::as_participant(config, "launcher"));
  std::map<int, auvrl_lcm::sim_heartbeat_t> heartbeats;  // by sim pid
  transport::subscribe<auvrl_lcm::sim_heartbeat_t>(
      *monitor, channels::kSimHeartbeat,
      [&](const std::string&, const auvrl_lcm::sim_heartbeat_t& h) { heartbeats[h.pid] = h; });
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*monitor, channels::kLearnerStats);
  std::vector<std::unique_ptr<test_support::ChildProcess>> procs;
  const int cpus = std::max(1, static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN)));
  for (int i = 0; i < (pinned ? actors : 1); ++i) {
    procs.push_back(std::make_unique<test_support::ChildProcess>(
        sim_arguments(config, i, actors, pinned, cpus), dir + "/sim" + std::to_string(i) + ".log"));
  }
  test_support::ChildProcess learner(learner_arguments(config, learner_ratio),
                                     dir + "/learner.log");
  for (int id = 0; id < actors; ++id) {
    procs.push_back(std::make_unique<test_support::ChildProcess>(
        actor_arguments(config, id, pinned, cpus), dir + "/actor" + std::to_string(id) + ".log"));
  }
  const std::size_t sims = pinned ? static_cast<std::size_t>(actors) : 1;
  const Rates r = measure(*monitor, heartbeats, sims, stats, seconds);
  std::printf(
      "training transport=%s placement=%s actors=%d seconds=%.1f env_steps_per_s=%.0f "
      "updates_per_s=%.0f updates_per_transition=%s\n",
      v.name.c_str(), pinned ? "pinned" : "shared", actors, r.seconds, r.steps_per_s,
      r.updates_per_s, learner_ratio.c_str());
  std::fflush(stdout);
}

/// The participants a secured run needs: the learner, this process, each actor and simulator.
std::vector<std::string> participants() {
  std::vector<std::string> names = {"learner", "launcher"};
  for (int i = 0; i < kMaxActors; ++i) {
    names.push_back("actor-" + std::to_string(i));
    names.push_back("sim-" + std::to_string(i));
  }
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  std::string ratio = "0.25";
  cli::CommandLine cmd("bench_training_rate",
                       "Environment steps/s with 1 and 2 actors (one sim, one learner).");
  cmd.option("seconds", &seconds, "measuring window per case");
  cmd.option("updates-per-transition", &ratio, "the learner's update ratio");
  std::string which = "both";
  std::string security_dir;
  bench::add_variant_options(cmd, &which, &security_dir,
                             "learner, launcher, actor-0, actor-1, sim-0 and sim-1 "
                             "(scripts/pki.sh --out DIR)");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  std::vector<bench::TransportVariant> variants;
  try {
    variants = bench::select_variants(which, security_dir, participants());
  } catch (const transport::TransportError& e) {
    std::cerr << e.what() << "\n(make the PKI: scripts/pki.sh --out DIR)\n";
    return 2;
  }
  for (bool pinned : {false, true}) {
    for (const bench::TransportVariant& v : variants) {
      for (int actors = 1; actors <= kMaxActors; ++actors) {
        run_case(v, actors, seconds, ratio, pinned);
      }
    }
  }
  return 0;
}
