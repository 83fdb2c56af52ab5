// Weights delivery: auv_learner (real process, default broadcast setting: after every update,
// at most every 50 ms) trains on synthetic experience (2,000 transitions/s from a feeder
// process, once the learner reads it and every subscriber has found the learner) while 4
// subscriber processes count the policy_weights_t they receive and their latency. Over LCM, DDS and
// DDS with DDS Security in the same run
// (--transport: lcm, dds, dds-secure; both = lcm and dds; dds-both = dds and dds-secure; all =
// the three, one after the other). Prints, per actor size and transport:
//   weights transport=lcm hidden=64-64 bytes=B published=N subscriber=k received=M delivery=M/N
//     p50_ms p99_ms
// Then the late joiner: once the learner has published (at least 100 versions) and gone quiet
// (no experience, so no broadcast), a new subscriber process that sends no request:
//   late_joiner transport=dds versions_published=N first_ms=X version=V newest=W count=C
// (first_ms: from its start, so its discovery and, secured, its authentication included; C: the
// weights that came in the second after the first).
// Run inside a private network namespace: scripts/netns.sh build/bin/bench_weights
//
// dds-secure needs --dds-security DIR, made by scripts/pki.sh with an identity for each
// process: learner, actor-K for subscriber K, launcher (this process, an observer: it reads the
// learner's statistics and the policy summaries), feeder and late-joiner (role actor: no role
// both publishes experience and reads the learner's statistics, so the feeder is a process of
// its own). For 4 subscribers (the default):
//   scripts/pki.sh --out DIR --actors 4 --participant actor:feeder --participant actor:late-joiner
//   scripts/netns.sh build/bin/bench_weights --transport dds-both --dds-security DIR
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/learner_stats_t.hpp>
#include <auvrl_lcm/policy_summary_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <thread>

#include "child_process.hpp"
#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/dds_security.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"
#include "synthetic_experience.hpp"
#include "transport_variants.hpp"

namespace {

using namespace auvrl;
using Clock = std::chrono::steady_clock;
// The learner's sizes for its default vehicle (Nessie VII, 6 thrusters) and the extended
// layout (--layout extended): 17 + 6 inputs.
constexpr int kStateDim = 23;
constexpr int kActionDim = 6;

/// The identities of a secured case besides the learner's and the subscribers' (actor-K).
constexpr const char* kMonitorIdentity = "launcher";  // this process: reads stats, summaries
constexpr const char* kFeederIdentity = "feeder";     // publishes the experience
constexpr const char* kLateJoinerIdentity = "late-joiner";

/// A subscriber process: counts weights messages until told to stop (by a file appearing).
/// Over DDS it reports (result_path.matched) once it has found the learner, started after every
/// subscriber is ready (result_path.ready), and, secured, authenticated it: the feeder waits for
/// that, so that the first weights count too. The learner's reader of weights requests stands
/// for the learner.
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
  transport->wait_for_readers(channels::kWeightsRequest, {"learner"}, std::chrono::seconds(20));
  std::ofstream(result_path + ".matched") << "matched\n";
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
/// weights arrived after it subscribed (waiting at most timeout_ms: discovery, and with DDS
/// Security the authentication, take their time), their version and how many came in the
/// window_ms after the first.
void late_joiner(const transport::TransportConfig& config, const std::string& result_path,
                 int timeout_ms, int window_ms) {
  const auto start = Clock::now();
  auto transport = transport::make_transport(config);
  Clock::time_point first;
  std::int64_t version = -1, count = 0;
  transport::subscribe<auvrl_lcm::policy_weights_t>(
      *transport, channels::kPolicyWeights,
      [&](const std::string&, const auvrl_lcm::policy_weights_t& w) {
        if (count++ == 0) {
          first = Clock::now();
          version = w.version;
        }
      });
  const auto deadline = start + std::chrono::milliseconds(timeout_ms);
  const auto listening = [&] {
    const auto now = Clock::now();
    return now < deadline && (count == 0 || now < first + std::chrono::milliseconds(window_ms));
  };
  while (listening()) transport->handle(5);
  const double first_ms =
      count == 0 ? -1.0 : std::chrono::duration<double, std::milli>(first - start).count();
  std::ofstream(result_path) << first_ms << " " << version << " " << count << "\n";
}

/// Waits until every subscriber K has written DIR/subK`suffix` (at most a minute).
void wait_for_subscribers(const std::string& dir, const std::string& suffix, int subscribers) {
  const auto end = Clock::now() + std::chrono::seconds(60);
  for (int k = 0; k < subscribers; ++k) {
    while (access((dir + "/sub" + std::to_string(k) + suffix).c_str(), F_OK) != 0 &&
           Clock::now() < end) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }
}

/// Forks `subscribers` subscriber processes (results in DIR/subK) and waits until each is ready.
std::vector<pid_t> start_subscribers(const transport::TransportConfig& config,
                                     const std::string& dir, const std::string& stop_path,
                                     int subscribers) {
  std::vector<pid_t> children;
  for (int k = 0; k < subscribers; ++k) {
    const pid_t pid = fork();
    if (pid == 0) {
      subscriber(bench::as_participant(config, "actor-" + std::to_string(k)),
                 dir + "/sub" + std::to_string(k), stop_path);
      _exit(0);
    }
    children.push_back(pid);
  }
  wait_for_subscribers(dir, ".ready", subscribers);
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
  for (const std::string& a :
       transport::transport_arguments(bench::as_participant(config, "learner"))) {
    learner_argv.push_back(a);
  }
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

/// The feeder, a process of its own (no DDS Security role both publishes experience and reads
/// the learner's statistics): waits until the learner reads experience (DDS discovery, and
/// authentication when secured), then feeds it for `seconds`.
void feeder(const transport::TransportConfig& config, double seconds) {
  auto transport = transport::make_transport(config);
  const std::vector<std::string> missing =
      transport->wait_for_readers(channels::kExperience, {"learner"}, std::chrono::seconds(20));
  if (!missing.empty()) std::cerr << "feeder: no learner reads experience; feeding anyway\n";
  feed_experience(*transport, seconds);
}

/// This program's command line in an internal mode (`mode` `value`, a fresh process: exec, not
/// fork, since the caller's transport has threads) over v, as participant `identity` when
/// secured.
std::vector<std::string> self_arguments(const bench::TransportVariant& v, const std::string& mode,
                                        const std::string& value, const std::string& identity) {
  std::vector<std::string> argv = {"/proc/self/exe", mode, value, "--transport",
                                   transport::to_string(v.config.kind)};
  if (!v.config.dds.security_dir.empty()) {
    const auto dir = std::filesystem::path(v.config.dds.security_dir) / identity;
    argv.insert(argv.end(), {"--dds-security", dir.string()});
  }
  return argv;
}

/// The feeder process for `seconds`; handles this process' messages until it has finished.
void run_feeder(transport::Transport& transport, const bench::TransportVariant& v, double seconds,
                const std::string& dir) {
  test_support::ChildProcess feed(
      self_arguments(v, "--feeder", std::to_string(seconds), kFeederIdentity), dir + "/feeder.log");
  while (feed.running()) transport.handle(20);
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

/// The late joiner: a fresh process that subscribes while the learner is quiet; prints what it
/// got.
void run_late_joiner(transport::Transport& transport, const bench::TransportVariant& v,
                     const std::string& hidden, const std::string& dir,
                     std::int64_t published_before, const std::int64_t& newest_version) {
  const std::string late_path = dir + "/late";
  test_support::ChildProcess late(
      self_arguments(v, "--late-joiner", late_path, kLateJoinerIdentity), dir + "/late.log");
  while (late.running()) transport.handle(10);
  std::ifstream in(late_path);
  double first_ms = -1;
  long long version = -1, count = 0;
  in >> first_ms >> version >> count;
  std::printf(
      "late_joiner transport=%s hidden=%s versions_published=%lld first_ms=%.2f version=%lld "
      "newest=%lld count=%lld\n",
      v.name.c_str(), hidden.c_str(), static_cast<long long>(published_before), first_ms, version,
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
void run_case(const bench::TransportVariant& v, const std::string& hidden, double seconds,
              int subscribers) {
  const std::string dir = test_support::make_temp_dir("auvrl_bench_weights_");
  const std::string stop_path = dir + "/stop";
  const std::vector<pid_t> children = start_subscribers(v.config, dir, stop_path, subscribers);
  test_support::ChildProcess learner(learner_arguments(v.config, hidden), dir + "/learner.log");
  auto transport = transport::make_transport(bench::as_participant(v.config, kMonitorIdentity));
  transport::Latest<auvrl_lcm::learner_stats_t> stats(*transport, channels::kLearnerStats);
  std::int64_t newest_version = -1;
  transport::subscribe<auvrl_lcm::policy_summary_t>(
      *transport, channels::kPolicySummary,
      [&](const std::string&, const auvrl_lcm::policy_summary_t& s) {
        newest_version = std::max(newest_version, s.version);
      });
  wait_for_subscribers(dir, ".matched", subscribers);
  run_feeder(*transport, v, seconds, dir);
  // The late joiner: with the learner quiet (no experience, no broadcast), a new subscriber.
  wait_until_quiet(*transport, newest_version);
  std::int64_t published_before = -1;
  if (auto s = stats.take()) published_before = s->weights_published;
  run_late_joiner(*transport, v, hidden, dir, published_before, newest_version);

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
  print_subscribers(v.name, hidden, dir, subscribers, last);
}

/// The participants a secured run needs besides the learner's and the subscribers' (actor-K).
std::vector<std::string> participants(int subscribers) {
  std::vector<std::string> names = {"learner", kMonitorIdentity, kFeederIdentity,
                                    kLateJoinerIdentity};
  for (int k = 0; k < subscribers; ++k) names.push_back("actor-" + std::to_string(k));
  return names;
}

/// The internal modes: the late joiner (writes to late_joiner_path) or the feeder (for
/// feeder_seconds), over --transport lcm|dds with --dds-security a participant's directory.
int run_internal(const std::string& which, const std::string& security_dir,
                 const std::string& late_joiner_path, double feeder_seconds) {
  transport::TransportConfig config;
  config.kind = transport::parse_transport_kind(which);
  config.dds.security_dir = security_dir;
  if (!late_joiner_path.empty()) {
    // LCM has no discovery (and no history): what comes at all comes within a second.
    const bool dds = config.kind == transport::TransportKind::kDds;
    late_joiner(config, late_joiner_path, dds ? 10000 : 1000, 1000);
  } else {
    feeder(config, feeder_seconds);
  }
  return 0;
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
  std::string security_dir;
  bench::add_variant_options(cmd, &which, &security_dir,
                             "learner, launcher, feeder, late-joiner and actor-K per subscriber "
                             "(see bench_weights.cpp)");
  std::string late_joiner_path;
  cmd.option("late-joiner", &late_joiner_path,
             "(internal) be the late joiner over --transport, write the result here");
  double feeder_seconds = -1.0;
  cmd.option("feeder", &feeder_seconds,
             "(internal) be the feeder over --transport, for this many seconds");
  try {
    if (!cmd.parse(argc, argv)) return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  if (!late_joiner_path.empty() || feeder_seconds >= 0) {
    return run_internal(which, security_dir, late_joiner_path, feeder_seconds);
  }
  std::vector<bench::TransportVariant> variants;
  try {
    variants = bench::select_variants(which, security_dir, participants(subscribers));
  } catch (const transport::TransportError& e) {
    std::cerr << e.what() << "\n(make the PKI: scripts/pki.sh --out DIR --actors " << subscribers
              << " --participant actor:feeder --participant actor:late-joiner)\n";
    return 2;
  }
  std::size_t start = 0;
  while (start <= hidden_list.size()) {
    const auto comma = std::min(hidden_list.find(',', start), hidden_list.size());
    for (const bench::TransportVariant& v : variants) {
      run_case(v, hidden_list.substr(start, comma - start), seconds, subscribers);
    }
    start = comma + 1;
  }
  return 0;
}
