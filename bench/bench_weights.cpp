// Weights delivery: auv_learner (real process, default broadcast setting: after every update,
// at most every 50 ms) trains on synthetic experience while 4 subscriber processes count the
// policy_weights_t they receive and their latency; over LCM and over DDS in the same run
// (--transport picks one). Prints, per transport and actor size:
//   weights transport=lcm hidden=64-64 bytes=B published=N subscriber=k received=M delivery=M/N
//     p50_ms p99_ms
// Then the late joiner: once the learner has published (at least 100 versions) and gone quiet
// (no experience, so no broadcast), a new subscriber process that sends no request:
//   late_joiner transport=dds versions_published=N first_ms=X version=V newest=W count=C
// Run inside a private network namespace: scripts/netns.sh build/bin/bench_weights
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_summary_t.hpp>
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
#include "common/transport_options.hpp"
#include "synthetic_experience.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;
// The learner's sizes for its default vehicle (Nessie VII, 6 thrusters) and the extended
// layout (--layout extended): 17 + 6 inputs.
constexpr int kStateDim = 23;
constexpr int kActionDim = 6;

/// A subscriber process: counts weights messages until told to stop (by a file appearing).
void subscriber(const transport::TransportConfig& config, const std::string& result_path,
                const std::string& stop_path) {
  auto transport = transport::make_transport(config);
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

/// The late joiner: a process that subscribes (and asks nothing) and writes when the first
/// weights arrived after it subscribed, their version and how many came in timeout_ms.
void late_joiner(const transport::TransportConfig& config, const std::string& result_path,
                 int timeout_ms) {
  const auto start = Clock::now();
  auto transport = transport::make_transport(config);
  double first_ms = -1;
  std::int64_t version = -1, count = 0;
  transport::subscribe<auvrl_lcm::policy_weights_t>(
      *transport, channels::kPolicyWeights,
      [&](const std::string&, const auvrl_lcm::policy_weights_t& w) {
        if (count++ == 0) {
          first_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
          version = w.version;
        }
      });
  const auto end = start + std::chrono::milliseconds(timeout_ms);
  while (Clock::now() < end) transport->handle(5);
  std::ofstream(result_path) << first_ms << " " << version << " " << count << "\n";
}

/// Forks `subscribers` subscriber processes (results in DIR/subK) and waits until each is ready.
std::vector<pid_t> start_subscribers(const transport::TransportConfig& config,
                                     const std::string& dir, const std::string& stop_path,
                                     int subscribers) {
  std::vector<pid_t> children;
  for (int k = 0; k < subscribers; ++k) {
    const pid_t pid = fork();
    if (pid == 0) {
      subscriber(config, dir + "/sub" + std::to_string(k), stop_path);
      _exit(0);
    }
    children.push_back(pid);
  }
  for (int k = 0; k < subscribers; ++k) {
    while (access((dir + "/sub" + std::to_string(k) + ".ready").c_str(), F_OK) != 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
  return children;
}

/// auv_learner's command line for an actor of `hidden` on `config`.
std::vector<std::string> learner_arguments(const transport::TransportConfig& config,
                                           const std::string& hidden) {
  std::vector<std::string> learner_argv = {test_support::bin_path("auv_learner"),
                                           "--layout",
                                           "extended",
                                           "--hidden",
                                           hidden,
                                           "--batch-size",
                                           "64",
                                           "--replay-capacity",
                                           "100000"};
  for (const std::string& a : transport::transport_arguments(config)) learner_argv.push_back(a);
  return learner_argv;
}

/// Experience at 2,000 transitions/s, in batches of 20 (an actor's rate on this machine), for
/// `seconds`.
void feed_experience(transport::Transport& transport, double seconds) {
  std::int64_t seq = 0;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  auto next = Clock::now();
  while (Clock::now() < end) {
    transport::publish(
        transport, channels::kExperience,
        test_support::synthetic_experience_batch(0, ++seq, 20, kStateDim, kActionDim));
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
    transport.drain();
  }
}

/// Handles messages until no new policy version (`newest_version`, updated by a subscription)
/// has appeared for a second.
void wait_until_quiet(transport::Transport& transport, const std::int64_t& newest_version) {
  auto quiet_since = Clock::now();
  std::int64_t seen = newest_version;
  while (Clock::now() - quiet_since < std::chrono::milliseconds(1000)) {
    transport.handle(20);
    if (newest_version != seen) {
      seen = newest_version;
      quiet_since = Clock::now();
    }
  }
}

/// The late joiner: a fresh process (exec, not fork: this one's transport has threads) that
/// subscribes while the learner is quiet; prints what it got.
void run_late_joiner(transport::Transport& transport, const std::string& name,
                     const std::string& hidden, const std::string& dir,
                     std::int64_t published_before, const std::int64_t& newest_version) {
  const std::string late_path = dir + "/late";
  test_support::ChildProcess late(
      {"/proc/self/exe", "--late-joiner", late_path, "--transport", name}, dir + "/late.log");
  while (late.running()) transport.handle(10);
  std::ifstream in(late_path);
  double first_ms = -1;
  long long version = -1, count = 0;
  in >> first_ms >> version >> count;
  std::printf(
      "late_joiner transport=%s hidden=%s versions_published=%lld first_ms=%.2f version=%lld "
      "newest=%lld count=%lld\n",
      name.c_str(), hidden.c_str(), static_cast<long long>(published_before), first_ms, version,
      static_cast<long long>(newest_version), count);
}

/// One line per subscriber: what it received of what the learner published, and the latency.
void print_subscribers(const std::string& name, const std::string& hidden, const std::string& dir,
                       int subscribers, const std::optional<auvrl_lcm::learner_stats_t>& last) {
  const std::int64_t published = last ? last->weights_published : -1;
  for (int k = 0; k < subscribers; ++k) {
    std::ifstream in(dir + "/sub" + std::to_string(k));
    long received = 0, bytes = 0;
    double p50 = 0, p99 = 0;
    in >> received >> bytes >> p50 >> p99;
    std::printf(
        "weights transport=%s hidden=%s bytes=%ld published=%lld subscriber=%d received=%ld "
        "delivery=%.4f p50_ms=%.2f p99_ms=%.2f updates=%lld\n",
        name.c_str(), hidden.c_str(), bytes, static_cast<long long>(published), k, received,
        published > 0 ? static_cast<double>(received) / static_cast<double>(published) : 0.0, p50,
        p99, static_cast<long long>(last ? last->updates : -1));
  }
  std::fflush(stdout);
}

/// One case: subscribers, auv_learner training on synthetic experience for `seconds`, the late
/// joiner, then one line per subscriber.
void run_case(const std::string& name, const transport::TransportConfig& config,
              const std::string& hidden, double seconds, int subscribers) {
  const std::string dir = test_support::make_temp_dir("auvrl_bench_weights_");
  const std::string stop_path = dir + "/stop";
  const std::vector<pid_t> children = start_subscribers(config, dir, stop_path, subscribers);
  test_support::ChildProcess learner(learner_arguments(config, hidden), dir + "/learner.log");
  auto transport = transport::make_transport(config);
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*transport, channels::kLearnerStats);
  std::int64_t newest_version = -1;
  transport::subscribe<auvrl_lcm::policy_summary_t>(
      *transport, channels::kPolicySummary,
      [&](const std::string&, const auvrl_lcm::policy_summary_t& s) {
        newest_version = std::max(newest_version, s.version);
      });
  feed_experience(*transport, seconds);
  // The late joiner: with the learner quiet (no experience, no broadcast), a new subscriber.
  wait_until_quiet(*transport, newest_version);
  std::int64_t published_before = -1;
  if (auto s = stats.take()) published_before = s->weights_published;
  run_late_joiner(*transport, name, hidden, dir, published_before, newest_version);

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
  print_subscribers(name, hidden, dir, subscribers, last);
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
  std::string which = "both";
  cmd.option("transport", &which, "lcm, dds or both (one after the other, same run)");
  cmd.choices("transport", {"lcm", "dds", "both"});
  std::string late_joiner_path;
  cmd.option("late-joiner", &late_joiner_path,
             "(internal) be the late joiner over --transport, write the result here");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  if (!late_joiner_path.empty()) {
    transport::TransportConfig config;
    config.kind = transport::parse_transport_kind(which);
    late_joiner(config, late_joiner_path, 1000);
    return 0;
  }
  std::size_t start = 0;
  while (start <= hidden_list.size()) {
    const auto comma = std::min(hidden_list.find(',', start), hidden_list.size());
    for (const std::string name : {"lcm", "dds"}) {
      if (which != "both" && which != name) continue;
      transport::TransportConfig config;
      config.kind = transport::parse_transport_kind(name);
      run_case(name, config, hidden_list.substr(start, comma - start), seconds, subscribers);
    }
    start = comma + 1;
  }
  return 0;
}
