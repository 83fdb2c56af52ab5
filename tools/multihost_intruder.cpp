// An intruder for scripts/multihost.sh --security: a participant that should not be let in
// (no certificate, one from another authority, permissions that do not allow the topics, or
// permissions it granted itself) tries, until SIGTERM/SIGINT, to inject what would hurt a
// training system or a vehicle, and to read what the system sends. Every kInjectPeriod it
// publishes:
//   EXPERIENCE      a batch of actor kIntruderActorId (the learner would train on it)
//   EPISODE         a report of that actor
//   POLICY_WEIGHTS  weights of version kIntruderVersion (every actor would act with them)
//   SIM_CMD_0       a thruster command for vehicle 0
// The probes count what reaches them by these marks; this program prints what it managed:
//   intruder=LABEL attempts=N published=P refused=R received=M first_refusal="..."
// (published: handed to the transport without error; refused: the transport refused it, e.g.
// DDS Security's local access control; received: any message of the system that reached it).
//   multihost_intruder --label LABEL [transport flags] [--out FILE]
#include <auvrl_lcm/episode_report_t.hpp>
#include <auvrl_lcm/experience_batch_t.hpp>
#include <auvrl_lcm/policy_weights_t.hpp>
#include <auvrl_lcm/thruster_cmd_t.hpp>
#include <chrono>
#include <fstream>
#include <functional>
#include <iostream>

#include "common/channels.hpp"
#include "common/cli.hpp"
#include "common/signals.hpp"
#include "common/transport.hpp"
#include "common/transport_options.hpp"

namespace {

using namespace auvrl;

constexpr std::chrono::milliseconds kInjectPeriod{50};
/// The marks the probes look for (tools/multihost_probe.cpp).
constexpr int kIntruderActorId = 99;
constexpr std::int64_t kIntruderVersion = 999999999;

/// What the intruder managed.
struct Tally {
  std::int64_t attempts = 0;
  std::int64_t published = 0;
  std::int64_t refused = 0;
  std::int64_t received = 0;
  std::string first_refusal;
  std::string subscribe_refusal;
};

void attempt(Tally& tally, const std::function<void()>& publish) {
  ++tally.attempts;
  try {
    publish();
    ++tally.published;
  } catch (const std::exception& e) {
    ++tally.refused;
    if (tally.first_refusal.empty()) tally.first_refusal = e.what();
  }
}

void inject_once(transport::Transport& t, Tally& tally) {
  auvrl_lcm::experience_batch_t batch{};
  batch.actor_id = kIntruderActorId;
  batch.batch_seq = tally.attempts + 1;
  attempt(tally, [&] { transport::publish(t, channels::kExperience, batch); });
  auvrl_lcm::episode_report_t episode{};
  episode.actor_id = kIntruderActorId;
  attempt(tally, [&] { transport::publish(t, channels::kEpisode, episode); });
  auvrl_lcm::policy_weights_t weights{};
  weights.version = kIntruderVersion;
  attempt(tally, [&] { transport::publish(t, channels::kPolicyWeights, weights); });
  auvrl_lcm::thruster_cmd_t command{};
  command.vehicle_id = 0;
  attempt(tally, [&] { transport::publish(t, channels::sim_command(0), command); });
}

/// Counts the system's messages that reach the intruder (its own, marked, are not counted);
/// a subscription the transport refuses is noted.
void subscribe_to_system(transport::Transport& t, Tally& tally) {
  const auto guarded = [&tally](const std::function<void()>& subscribe) {
    try {
      subscribe();
    } catch (const std::exception& e) {
      if (tally.subscribe_refusal.empty()) tally.subscribe_refusal = e.what();
    }
  };
  constexpr int kQueue = 100000;
  guarded([&] {
    transport::subscribe<auvrl_lcm::experience_batch_t>(
        t, channels::kExperience,
        [&tally](const std::string&, const auvrl_lcm::experience_batch_t& b) {
          if (b.actor_id != kIntruderActorId) ++tally.received;
        },
        nullptr, kQueue);
  });
  guarded([&] {
    transport::subscribe<auvrl_lcm::episode_report_t>(
        t, channels::kEpisode,
        [&tally](const std::string&, const auvrl_lcm::episode_report_t& r) {
          if (r.actor_id != kIntruderActorId) ++tally.received;
        },
        nullptr, kQueue);
  });
  guarded([&] {
    transport::subscribe<auvrl_lcm::policy_weights_t>(
        t, channels::kPolicyWeights,
        [&tally](const std::string&, const auvrl_lcm::policy_weights_t& w) {
          if (w.version != kIntruderVersion) ++tally.received;
        },
        nullptr, kQueue);
  });
  guarded([&] {
    t.subscribe(
        "POLICY_SUMMARY|WEIGHTS_REQUEST|LEARNER_STATS|SIM_HEARTBEAT|LOGGER_HEARTBEAT",
        [&tally](const transport::RawMessage&) { ++tally.received; }, kQueue);
  });
}

}  // namespace

int main(int argc, char** argv) {
  try {
    cli::CommandLine cmd("multihost_intruder",
                         "Tries to inject experience, weights and thruster commands into a "
                         "training system and to read its traffic, until SIGTERM; then prints "
                         "what it managed (scripts/multihost.sh --security).");
    std::string label = "intruder", out_path;
    transport::TransportConfig config;
    cmd.option("label", &label, "name printed on the line");
    cmd.option("out", &out_path, "write the line here instead of stdout");
    transport::add_transport_options(cmd, config);
    config.dds.role = "intruder";
    if (!cmd.parse(argc, argv)) return 0;
    signals::install_stop_handlers();
    auto t = transport::make_transport(config);
    Tally tally;
    subscribe_to_system(*t, tally);
    std::cerr << "multihost_intruder " << label << ": injecting" << std::endl;
    auto next = std::chrono::steady_clock::now();
    while (!signals::stop_requested()) {
      if (std::chrono::steady_clock::now() >= next) {
        inject_once(*t, tally);
        next += kInjectPeriod;
      }
      t->handle(10);
    }
    std::ofstream file;
    if (!out_path.empty()) file.open(out_path);
    std::ostream& out = out_path.empty() ? std::cout : file;
    out << "intruder=" << label << " attempts=" << tally.attempts
        << " published=" << tally.published << " refused=" << tally.refused
        << " received=" << tally.received << " first_refusal=\"" << tally.first_refusal
        << "\" subscribe_refusal=\"" << tally.subscribe_refusal << "\"\n";
    return 0;
  } catch (const cli::UsageError& e) {
    std::cerr << "multihost_intruder: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "multihost_intruder: " << e.what() << "\n";
    return 1;
  }
}
