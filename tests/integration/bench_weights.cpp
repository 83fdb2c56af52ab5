// Weights delivery: auv_learner (real process, default broadcast setting: after every update,
// at most every 50 ms) trains on synthetic experience while 4 subscriber processes count the
// policy_weights_t they receive and their latency. Prints, per actor size:
//   weights hidden=64-64 bytes=B published=N subscriber=k received=M delivery=M/N p50_ms p99_ms
// Run inside a private network namespace: scripts/netns.sh build/bin/bench_weights
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/transport.hpp"
#include "synthetic_experience.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;
constexpr int kStateDim = 23;
constexpr int kActionDim = 6;

/// A subscriber process: counts weights messages until told to stop (by a file appearing).
void subscriber(const std::string& result_path, const std::string& stop_path) {
  auto transport = transport::make_transport({});
  std::vector<double> latency_ms;
  std::int64_t bytes = 0;
  transport::subscribe<auvrl_lcm::policy_weights_t>(
      *transport, channels::kPolicyWeights,
      [&](const std::string&, const auvrl_lcm::policy_weights_t& w) {
        latency_ms.push_back(static_cast<double>(transport::now_utime() - w.utime) / 1000.0);
        bytes = w.num_bytes;
      });
  std::ofstream(result_path + ".ready") << "ready\n";
  while (access(stop_path.c_str(), F_OK) != 0) transport->handle(20);
  std::sort(latency_ms.begin(), latency_ms.end());
  std::ofstream out(result_path);
  const auto pct = [&](double p) {
    return latency_ms.empty() ? 0.0
                              : latency_ms[static_cast<std::size_t>(p * (latency_ms.size() - 1))];
  };
  out << latency_ms.size() << " " << bytes << " " << pct(0.5) << " " << pct(0.99) << "\n";
}

void run_case(const std::string& hidden, double seconds, int subscribers) {
  const std::string dir = test_support::make_temp_dir("auvrl_bench_weights_");
  const std::string stop_path = dir + "/stop";
  std::vector<pid_t> children;
  for (int k = 0; k < subscribers; ++k) {
    const pid_t pid = fork();
    if (pid == 0) {
      subscriber(dir + "/sub" + std::to_string(k), stop_path);
      _exit(0);
    }
    children.push_back(pid);
  }
  for (int k = 0; k < subscribers; ++k) {
    while (access((dir + "/sub" + std::to_string(k) + ".ready").c_str(), F_OK) != 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  test_support::ChildProcess learner(
      {test_support::bin_path("auv_learner"), "--state-dim", std::to_string(kStateDim),
       "--action-dim", std::to_string(kActionDim), "--hidden", hidden, "--batch", "64", "--replay",
       "100000"},
      dir + "/learner.log");
  auto transport = transport::make_transport({});
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*transport, channels::kLearnerStats);
  std::int64_t seq = 0;
  // Experience at 2,000 transitions/s, in batches of 20 (an actor's rate on this machine).
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  auto next = Clock::now();
  while (Clock::now() < end) {
    transport::publish(
        *transport, channels::kExperience,
        test_support::synthetic_experience_batch(0, ++seq, 20, kStateDim, kActionDim));
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
    transport->drain();
  }
  // Stop the learner first so no weights are in flight, then read its final figures.
  learner.terminate();
  std::optional<auvrl_lcm::learner_stats_t> last;
  for (int i = 0; i < 20; ++i) {
    transport->handle(20);
    if (auto s = stats.take()) last = s;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::ofstream(stop_path) << "stop\n";
  for (pid_t pid : children) waitpid(pid, nullptr, 0);
  const std::int64_t published = last ? last->weights_published : -1;
  for (int k = 0; k < subscribers; ++k) {
    std::ifstream in(dir + "/sub" + std::to_string(k));
    long received = 0, bytes = 0;
    double p50 = 0, p99 = 0;
    in >> received >> bytes >> p50 >> p99;
    std::printf(
        "weights hidden=%s bytes=%ld published=%lld subscriber=%d received=%ld "
        "delivery=%.4f p50_ms=%.2f p99_ms=%.2f updates=%lld\n",
        hidden.c_str(), bytes, static_cast<long long>(published), k, received,
        published > 0 ? static_cast<double>(received) / static_cast<double>(published) : 0.0, p50,
        p99, static_cast<long long>(last ? last->updates : -1));
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  int subscribers = 4;
  std::string hidden_list = "64-64,400-300";
  cli::CommandLine cmd("bench_weights", "Weights delivery rate and latency to subscribers.");
  cmd.option("seconds", &seconds, "training time per case");
  cmd.option("subscribers", &subscribers, "subscriber processes");
  cmd.option("hidden", &hidden_list, "comma-separated actor sizes");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  std::size_t start = 0;
  while (start <= hidden_list.size()) {
    const auto comma = std::min(hidden_list.find(',', start), hidden_list.size());
    run_case(hidden_list.substr(start, comma - start), seconds, subscribers);
    start = comma + 1;
  }
  return 0;
}
